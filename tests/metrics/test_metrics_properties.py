"""Property tests: ``evaluate_sequence`` against a direct use of motmetrics.

The reference builds its own distance matrices pair by pair, feeds a fresh
``MOTAccumulator`` and reads ``motmetrics.metrics.create().compute``; our counts
must agree on random sequences with overlapping people, switching ids and
unscored tracks.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from typing import Any

import motmetrics as mm
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from metrics_builders import gt, track

from rgbd_eval.config import Convention, EvaluationConfig, Gating
from rgbd_eval.metrics import Counts, evaluate_sequence
from rgbd_eval.types import GroundTruthObject, TrackOutput, TrackStatus, Visibility

REFERENCE_METRICS = [
    "num_frames",
    "num_objects",
    "num_predictions",
    "num_matches",
    "num_switches",
    "num_false_positives",
    "num_misses",
    "num_fragmentations",
    "num_unique_objects",
    "mostly_tracked",
    "partially_tracked",
    "mostly_lost",
    "idtp",
    "idfp",
    "idfn",
    "motp",
    "mota",
    "idf1",
]


def _scored(t: TrackOutput) -> bool:
    """The spec, restated: validated tracks that are visible or occluded are scored."""
    return t.status is TrackStatus.VALIDATED and t.visibility is not Visibility.NOT_VISIBLE


Frames = tuple[list[list[GroundTruthObject]], list[list[TrackOutput]]]


@st.composite
def sequences(draw: st.DrawFn, with_ignored: bool = False) -> Frames:
    """A few frames of up to 3 people and 4 track ids crowded into a small area.

    Boxes have integer coordinates and positions lie on a 0.25 m grid, so the
    reference's distances equal ours bit for bit (ties break the same way).
    """
    n_frames = draw(st.integers(1, 12))
    coord = st.integers(0, 30)
    size = st.integers(6, 20)
    grid = st.integers(0, 12).map(lambda v: v * 0.25)
    gts: list[list[GroundTruthObject]] = []
    tracks: list[list[TrackOutput]] = []
    for _ in range(n_frames):
        people = draw(st.lists(st.integers(1, 3), unique=True, max_size=3))
        frame_gt = [
            gt(
                p,
                (draw(coord), draw(coord), draw(size), draw(size)),
                (draw(grid), draw(grid)),
                ignore=with_ignored and draw(st.booleans()),
            )
            for p in people
        ]
        ids = draw(st.lists(st.integers(10, 13), unique=True, max_size=4))
        frame_tracks = []
        for i in ids:
            # Mostly near a person (jittered), so that matches and id switches are common.
            near = draw(st.sampled_from([None, *frame_gt, *frame_gt])) if frame_gt else None
            if near is not None and near.box2d is not None and near.world_xyz is not None:
                dx, dy = draw(st.integers(-4, 4)), draw(st.integers(-4, 4))
                b = near.box2d
                box = (b.left + dx, b.top + dy, b.width, b.height)
                xy = (near.world_xyz[0] + dx * 0.25, near.world_xyz[1] + dy * 0.25)
            else:
                box = (draw(coord), draw(coord), draw(size), draw(size))
                xy = (draw(grid), draw(grid))
            visibility = draw(st.sampled_from(list(Visibility)))
            status = draw(st.sampled_from([TrackStatus.VALIDATED] * 3 + [TrackStatus.NEW]))
            frame_tracks.append(track(i, box, xy, visibility=visibility, status=status))
        gts.append(frame_gt)
        tracks.append(frame_tracks)
    return gts, tracks


def _reference_distance(gating: Gating, g: GroundTruthObject, t: TrackOutput, thr: float) -> float:
    if gating is Gating.IOU:
        a, b = g.box2d, t.box2d
        assert a is not None and b is not None
        w = max(0.0, min(a.right, b.right) - max(a.left, b.left))
        h = max(0.0, min(a.bottom, b.bottom) - max(a.top, b.top))
        inter = w * h
        iou = inter / (a.width * a.height + b.width * b.height - inter)
        return 1.0 - iou if iou >= thr else math.nan
    assert g.world_xyz is not None
    d = float(np.hypot(g.world_xyz[0] - t.x, g.world_xyz[1] - t.y))
    return d if d <= thr else math.nan


def _reference(
    gts: Sequence[Sequence[GroundTruthObject]],
    tracks: Sequence[Sequence[TrackOutput]],
    gating: Gating,
    threshold: float,
) -> dict[str, Any]:
    acc = mm.MOTAccumulator(auto_id=True)
    for frame_gt, frame_tracks in zip(gts, tracks, strict=True):
        scored = [t for t in frame_tracks if _scored(t)]
        d = [[_reference_distance(gating, g, t, threshold) for t in scored] for g in frame_gt]
        acc.update(
            [g.object_id for g in frame_gt],
            [t.track_id for t in scored],
            np.array(d, dtype=float).reshape(len(frame_gt), len(scored)),
        )
    result: dict[str, Any] = mm.metrics.create().compute(
        acc, metrics=REFERENCE_METRICS, return_dataframe=False
    )
    return result


def _close(ours: float | int | None, reference: float) -> bool:
    if ours is None:
        return math.isnan(reference)
    return math.isclose(ours, reference, rel_tol=1e-9, abs_tol=1e-12)


@pytest.mark.parametrize("gating", list(Gating))
@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=sequences())
def test_counts_equal_motmetrics(gating: Gating, data: Frames) -> None:
    gts, tracks = data
    config = EvaluationConfig(gating=gating, convention=Convention.MOTMETRICS)
    threshold = config.effective_threshold()
    scores = evaluate_sequence(gts, tracks, config)
    c, s = scores.counts, scores.summary()
    ref = _reference(gts, tracks, gating, threshold)
    assert c.num_frames == ref["num_frames"]
    assert c.num_gt == ref["num_objects"]
    assert c.num_tracks == ref["num_predictions"]
    assert c.num_matches == ref["num_matches"] + ref["num_switches"]
    assert c.id_switches == ref["num_switches"]
    assert c.fp == ref["num_false_positives"]
    assert c.fn == ref["num_misses"]
    assert c.fragmentations == ref["num_fragmentations"]
    assert c.num_gt_tracks == ref["num_unique_objects"]
    assert (c.mostly_tracked, c.partly_tracked, c.mostly_lost) == (
        ref["mostly_tracked"],
        ref["partially_tracked"],
        ref["mostly_lost"],
    )
    assert (c.idtp, c.idfp, c.idfn) == (ref["idtp"], ref["idfp"], ref["idfn"])
    assert _close(s["mota"], ref["mota"]) or (c.num_gt == 0)
    assert _close(s["idf1"], ref["idf1"])
    # motmetrics' MOTP is the mean distance; ours is mean IoU = 1 - mean(1 - IoU) for IoU.
    if c.num_matches:
        expected_motp = 1.0 - ref["motp"] if gating is Gating.IOU else ref["motp"]
        assert s["motp"] == pytest.approx(expected_motp, rel=1e-9)
    else:
        assert s["motp"] is None
    # The counts survive a JSON round trip.
    assert Counts.from_dict(json.loads(json.dumps(c.to_dict()))) == c
    # Per-frame events add up to the counts.
    assert sum(len(f.matches) for f in scores.frames) == c.num_matches
    assert sum(len(f.misses) for f in scores.frames) == c.fn
    assert sum(len(f.false_positives) for f in scores.frames) == c.fp
    assert sum(m.id_switch for f in scores.frames for m in f.matches) == c.id_switches
    # MOTA never exceeds 1; Main Tr. never exceeds All Tr.
    if c.num_gt:
        assert s["mota"] is not None and s["mota"] <= 1.0
        assert s["main_tr"] <= s["all_tr"]  # type: ignore[operator]


@pytest.mark.parametrize("gating", list(Gating))
@settings(max_examples=40, deadline=None)
@given(
    presence=st.lists(st.lists(st.booleans(), min_size=3, max_size=3), min_size=1, max_size=12),
    offsets=st.lists(st.integers(0, 20), min_size=3, max_size=3),
)
def test_a_perfect_tracker_scores_mota_one(
    gating: Gating, presence: list[list[bool]], offsets: list[int]
) -> None:
    # People stand 100 px / 10 m apart (never confusable); the tracker outputs exactly
    # the ground truth with its own ids (100 + person).
    gts = [
        [
            gt(p, (100.0 * p + offsets[p], 5.0, 30.0, 60.0), (10.0 * p, offsets[p] * 0.1))
            for p in range(3)
            if here[p]
        ]
        for here in presence
    ]
    tracks = [
        [
            track(100 + g.object_id, g.box2d.as_tuple() if g.box2d else None, g.world_xyz[:2])
            for g in frame
            if g.world_xyz is not None
        ]
        for frame in gts
    ]
    s = evaluate_sequence(
        gts, tracks, EvaluationConfig(gating=gating, convention=Convention.MOTMETRICS)
    ).summary()
    if s["num_gt"] == 0:
        assert s["mota"] is None
        return
    assert (s["fp"], s["fn"], s["id_switches"], s["fragmentations"]) == (0, 0, 0, 0)
    assert s["mota"] == 1.0
    assert s["main_tr"] == 1.0 and s["all_tr"] == 1.0 and s["idf1"] == 1.0
    assert s["motp"] == (1.0 if gating is Gating.IOU else 0.0)


@pytest.mark.parametrize("gating", list(Gating))
@settings(max_examples=40, deadline=None)
@given(data=sequences(with_ignored=True))
def test_ignored_ground_truth_is_neither_scored_nor_missed(gating: Gating, data: Frames) -> None:
    gts, tracks = data
    scores = evaluate_sequence(
        gts, tracks, EvaluationConfig(gating=gating, convention=Convention.MOTMETRICS)
    )
    c = scores.counts
    ignored = sum(g.ignore for frame in gts for g in frame)
    scored_tracks = sum(_scored(t) for frame in tracks for t in frame)
    assert c.ignored_gt == ignored
    assert c.num_gt == sum(len(frame) for frame in gts) - ignored
    assert c.num_tracks + c.ignored_tracks == scored_tracks
    for frame_gt, events in zip(gts, scores.frames, strict=True):
        ignored_ids = {g.object_id for g in frame_gt if g.ignore}
        assert set(events.ignored_gt) == ignored_ids
        assert len(events.ignored_tracks) <= len(ignored_ids)
        assert not ignored_ids & set(events.misses)
        assert not ignored_ids & {m.gt_id for m in events.matches}
        assert not set(events.ignored_tracks) & set(events.false_positives)
