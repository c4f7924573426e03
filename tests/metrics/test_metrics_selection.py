"""Matching tracks to ignored ground truth, and which objects are scored."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from metrics_builders import gt, track

from rgbd_eval.config import Gating
from rgbd_eval.errors import ScoringError
from rgbd_eval.metrics.selection import (
    FrameSelection,
    _select_checking,
    _select_sequence,
    is_ignored,
    is_scored_track,
    select_frame,
    select_frames,
    tracks_on_ignored,
)
from rgbd_eval.types import GroundTruthObject, TrackOutput, TrackStatus, Visibility


def test_tracks_on_ignored_takes_the_most_pairs() -> None:
    # Ignored I1 = (0, 0, 10, 10), I2 = (3, 0, 10, 10). Tracks:
    #   T0 = (0, 0, 10, 10): IoU with I1 1, with I2 70 / 130 = 0.54
    #   T1 = (2, 0, 10, 10): IoU with I1 80 / 120 = 0.67, with I2 90 / 110 = 0.82
    #   T2 far away.
    # Distances 1 - IoU: I1-T0 0 + I2-T1 0.18 = 0.18 beats I1-T1 0.33 + I2-T0 0.46;
    # either way both T0 and T1 are dropped and T2 stays.
    ignored = np.array([(0, 0, 10, 10), (3, 0, 10, 10)], dtype=float)
    tracks = np.array([(0, 0, 10, 10), (2, 0, 10, 10), (500, 0, 10, 10)], dtype=float)
    assert tracks_on_ignored(ignored, tracks, Gating.IOU, 0.5) == [0, 1]


def test_tracks_on_ignored_pairs_as_many_as_possible() -> None:
    # On the ground: ignored I1 at 0 m, I2 at 1.8 m; tracks T0 at 0.9 m, T1 at 0.0 m.
    # Inside the 1 m gate: I1-T0 0.9, I1-T1 0.0, I2-T0 0.9 (I2-T1 is 1.8 m: out).
    # Two pairs exist only as I1-T1 + I2-T0 (0.0 + 0.9): both tracks are dropped.
    ignored = np.array([(0.0, 0.0), (1.8, 0.0)])
    tracks = np.array([(0.9, 0.0), (0.0, 0.0)])
    assert tracks_on_ignored(ignored, tracks, Gating.METRIC, 1.0) == [0, 1]
    # A gate of 0.5 m leaves only the exact pair.
    assert tracks_on_ignored(ignored, tracks, Gating.METRIC, 0.5) == [1]


def test_tracks_on_ignored_with_nothing() -> None:
    none = np.zeros((0, 2))
    assert tracks_on_ignored(none, np.array([(0.0, 0.0)]), Gating.METRIC, 1.0) == []
    far = np.array([(9.0, 9.0)])
    assert tracks_on_ignored(np.array([(0.0, 0.0)]), far, Gating.METRIC, 1.0) == []


def test_which_objects_are_scored() -> None:
    assert is_scored_track(track(1))
    assert is_scored_track(track(1, visibility=Visibility.OCCLUDED))
    assert not is_scored_track(track(1, visibility=Visibility.NOT_VISIBLE))
    assert not is_scored_track(track(1, status=TrackStatus.NEW))
    assert is_ignored(gt(1, ignore=True), 0.0)
    assert is_ignored(gt(1, visibility=0.3), 0.5)
    assert not is_ignored(gt(1, visibility=0.5), 0.5)  # exactly at the limit: kept


def _random_frame(
    rng: np.random.Generator, gating: Gating
) -> tuple[list[GroundTruthObject], list[TrackOutput]]:
    """Crowded frames: ignored objects (distractors or not, some without the gated field),
    dropped and unscored tracks, boxes on a coarse grid so that pairs conflict and tie."""
    objects = []
    for k in range(int(rng.integers(0, 8))):
        ignored = bool(rng.random() < 0.4)
        box = tuple(float(v) for v in rng.integers(0, 6, 4) * 5) if rng.random() < 0.9 else None
        xy = tuple(float(v) for v in rng.integers(0, 6, 2) * 0.5) if rng.random() < 0.9 else None
        if not ignored and (box if gating is Gating.IOU else xy) is None:
            box, xy = (0.0, 0.0, 10.0, 10.0), (0.0, 0.0)
        if box is None and xy is None:
            box = (0.0, 0.0, 10.0, 10.0)
        o = gt(k, box, xy, ignore=ignored, visibility=float(rng.choice([0.2, 1.0])))  # type: ignore[arg-type]
        objects.append(dataclasses.replace(o, distractor=bool(rng.random() < 0.5)))
    tracks = [
        track(
            100 + k,
            tuple(float(v) for v in rng.integers(0, 6, 4) * 5),  # type: ignore[arg-type]
            tuple(float(v) for v in rng.integers(0, 6, 2) * 0.5),  # type: ignore[arg-type]
            status=TrackStatus.VALIDATED if rng.random() < 0.9 else TrackStatus.NEW,
        )
        for k in range(int(rng.integers(0, 8)))
    ]
    return objects, tracks


def _same(a: FrameSelection, b: FrameSelection) -> bool:
    arrays = ("gt_values", "track_values", "measure")
    return all(
        np.array_equal(getattr(a, f.name), getattr(b, f.name))
        and getattr(a, f.name).shape == getattr(b, f.name).shape
        if f.name in arrays
        else getattr(a, f.name) == getattr(b, f.name)
        for f in dataclasses.fields(FrameSelection)
    )


def test_select_frame_agrees_with_the_step_by_step_selection() -> None:
    # select_frame checks a frame's values once, as arrays, and computes one measure matrix;
    # the step-by-step selection (which names each problem) must give the same split.
    rng = np.random.default_rng(5)
    for gating, threshold in ((Gating.IOU, 0.5), (Gating.METRIC, 1.0)):
        for frame in range(400):
            objects, tracks = _random_frame(rng, gating)
            fast = select_frame(frame, objects, tracks, gating, threshold, 0.5)
            slow = _select_checking(frame, objects, tracks, gating, threshold, 0.5)
            assert _same(fast, slow), (gating, frame)


def test_select_frame_names_the_problems_as_before() -> None:
    with pytest.raises(ScoringError, match=r"ground-truth id\(s\) \[1\] appear more than once"):
        select_frame(3, [gt(1), gt(1, ignore=True)], [track(5)], Gating.IOU, 0.5, 0.0)
    with pytest.raises(ScoringError, match="ground-truth id 2 has no 2D box"):
        select_frame(3, [gt(2, None, (0.0, 0.0))], [track(5)], Gating.IOU, 0.5, 0.0)
    with pytest.raises(ScoringError, match="track id 5 has an invalid box"):
        select_frame(3, [gt(2)], [track(5, (0.0, 0.0, -1.0, 2.0))], Gating.IOU, 0.5, 0.0)
    # An ignored object's bad box matters only when it takes part in the matching.
    bad = gt(4, (0.0, 0.0, float("nan"), 1.0), ignore=True)
    assert select_frame(3, [gt(2), bad], [], Gating.IOU, 0.5, 0.0).ignored_gt_ids == [4]
    with pytest.raises(ScoringError, match="ground-truth id 4 has an invalid box"):
        select_frame(3, [gt(2), bad], [track(5)], Gating.IOU, 0.5, 0.0)


def test_select_frames_agrees_with_select_frame() -> None:
    # The sequence's fields are read and checked once as arrays; the frames' selections must
    # be select_frame's, and a problem is named with its frame as select_frame names it.
    rng = np.random.default_rng(6)
    for gating, threshold in ((Gating.IOU, 0.5), (Gating.METRIC, 1.0)):
        frames = [_random_frame(rng, gating) for _ in range(300)]
        # Every object with the gated field: the selection of the whole sequence at once.
        field = "box2d" if gating is Gating.IOU else "world_xyz"
        frames = [([o for o in g if getattr(o, field) is not None], t) for g, t in frames]
        gts, tracks = [f[0] for f in frames], [f[1] for f in frames]
        together = _select_sequence(gts, tracks, gating, threshold, 0.5)
        assert together is not None
        assert sum(len(s.dropped_track_ids) > 0 for s in together) > 10
        for k, (objects, frame_tracks) in enumerate(frames):
            alone = select_frame(k, objects, frame_tracks, gating, threshold, 0.5)
            assert _same(together[k], alone), (gating, k)
    boxes = [[gt(1), gt(2)], [gt(1), gt(3)], [gt(4), gt(4, ignore=True)]]
    with pytest.raises(ScoringError, match=r"frame 2: ground-truth id\(s\) \[4\] appear"):
        select_frames(boxes, [[track(1)], [], [track(1)]], Gating.IOU, 0.5, 0.0)
    with pytest.raises(ScoringError, match=r"frame 1: track id\(s\) \[7\] appear"):
        select_frames([[], [], []], [[track(7)], [track(7), track(7)], []], Gating.IOU, 0.5, 0.0)
    with pytest.raises(ScoringError, match="frame 1: ground-truth id 3 has an invalid box"):
        select_frames([[], [gt(3, (0.0, 0.0, 1.0, -1.0))]], [[], []], Gating.IOU, 0.5, 0.0)
