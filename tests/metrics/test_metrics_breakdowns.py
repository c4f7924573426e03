"""Breakdowns on hand-computed micro-scenarios (the arithmetic in comments)."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from metrics_builders import gt, track

from rgbd_eval.config import Convention, EvaluationConfig, Gating
from rgbd_eval.io.tracks import align, read_mot_gt, read_mot_tracks
from rgbd_eval.metrics import breakdowns as bd
from rgbd_eval.metrics import evaluate_sequence
from rgbd_eval.types import Pose

METRIC = EvaluationConfig(gating=Gating.METRIC, threshold=1.0)
SETTINGS = bd.Settings()
STEP_NS = 100_000_000  # 10 Hz


def _camera(
    n: int, headings: list[float] | None = None, xs: list[float] | None = None
) -> bd.CameraPath:
    """A level camera (optical frame: z forward) at (xs[i], 0) looking along heading[i]."""
    poses = []
    for i in range(n):
        h = 0.0 if headings is None else headings[i]
        # world_T_optical: optical z (forward) = (cos h, sin h, 0), x (right) = (sin h, -cos h, 0),
        # y (down) = (0, 0, -1); as a quaternion via the rotation matrix.
        r = np.array(
            [[math.sin(h), 0.0, math.cos(h)], [-math.cos(h), 0.0, math.sin(h)], [0.0, -1.0, 0.0]]
        )
        t = np.eye(4)
        t[:3, :3] = r
        t[0, 3] = 0.0 if xs is None else xs[i]
        poses.append(Pose.from_matrix(t))
    return bd.CameraPath.from_poses([i * STEP_NS for i in range(n)], poses, "test")


def _scenario() -> tuple[list[list], list[list]]:
    """Two people seen from a camera at the origin, 7 frames, metric gating at 1 m.

    Person 1 at (1, 0): 1 m away, fully visible, absent in frame 5.
    Person 2 at (5, 0): 5 m away, 30 % visible.
    f0, f1: track 10 on p1, track 20 on p2.
    f2: track 10 on p1; p2 missed (FN); track 30 at (3, 0), 2 m from p2: a FP, 3 m away.
    f3: p1 missed (FN); track 21 on p2: an id switch (p2's last track was 20).
    f4: track 10 on p1 (back after a 1-frame gap, same id), track 21 on p2.
    f5: p1 absent; track 21 on p2.
    f6: track 11 on p1: an id switch after a 1-frame gap in which p1 was unseen; 21 on p2.
    """
    p1 = lambda f: gt(1, None, (1.0, 0.0), frame=f)  # noqa: E731
    p2 = lambda f: gt(2, None, (5.0, 0.0), frame=f, visibility=0.3)  # noqa: E731
    gts = [[p1(f), p2(f)] if f != 5 else [p2(f)] for f in range(7)]
    on1 = lambda tid: track(tid, None, (1.0, 0.0))  # noqa: E731
    on2 = lambda tid: track(tid, None, (5.0, 0.0))  # noqa: E731
    tracks = [
        [on1(10), on2(20)],
        [on1(10), on2(20)],
        [on1(10), track(30, None, (3.0, 0.0))],
        [on2(21)],
        [on1(10), on2(21)],
        [on2(21)],
        [on1(11), on2(21)],
    ]
    return gts, tracks


def _breakdowns(convention: Convention = Convention.MOTCHALLENGE) -> tuple:
    gts, tracks = _scenario()
    config = METRIC.model_copy(update={"convention": convention})
    scores = evaluate_sequence(gts, tracks, config)
    b = bd.breakdowns(scores.table, gts, tracks, _camera(7), SETTINGS, convention)
    return scores, b


def _band(b: bd.Breakdown, label: str) -> bd.BandCounts:
    return next(x.counts for x in b.bands if x.label == label)


def test_the_scenario_counts() -> None:
    scores, _ = _breakdowns()
    c = scores.counts
    # GT: p1 6 frames + p2 7 = 13; matches 5 + 6 = 11; FN 2; FP 1 (track 30); 2 switches.
    assert (c.num_gt, c.num_matches, c.fn, c.fp, c.id_switches) == (13, 11, 2, 1, 2)
    # p1 resumes at f4 and f6 (f5 is scored: p2 and tracks), p2 at f3: 3 fragmentations.
    assert c.fragmentations == 3


def test_distance_bands_take_fps_by_the_tracks_own_position() -> None:
    _, b = _breakdowns()
    d = b.distance
    assert [x.label for x in d.bands] == ["0-2 m", "2-4 m", "4-6 m", "6+ m"]
    # 0-2 m: p1's 6 instances, 5 matched, FN 1 (f3), switch 1 (f6): MOTA = 1 - 2/6.
    near = _band(d, "0-2 m")
    assert (near.frames, near.num_gt, near.fn, near.fp, near.id_switches) == (6, 6, 1, 0, 1)
    assert near.summary()["mota"] == pytest.approx(1 - 2 / 6)
    # 2-4 m: no ground truth, the FP of track 30 (3 m away) in frame 2: MOTA undefined.
    mid = _band(d, "2-4 m")
    assert (mid.frames, mid.num_gt, mid.fp) == (1, 0, 1)
    assert mid.summary()["mota"] is None and mid.summary()["errors_per_frame"] == 1.0
    # 4-6 m: p2's 7 instances, FN 1 (f2), switch 1 (f3): MOTA = 1 - 2/7.
    far = _band(d, "4-6 m")
    assert (far.num_gt, far.fn, far.fp, far.id_switches) == (7, 1, 0, 1)
    assert far.summary()["mota"] == pytest.approx(5 / 7)
    assert _band(d, "6+ m") == bd.BandCounts()
    # The bands add up to the sequence's counts.
    total = sum((x.counts for x in d.bands), bd.BandCounts())
    assert (total.num_gt, total.fn, total.fp, total.id_switches) == (13, 2, 1, 2)


def test_visibility_bands_are_fp_free() -> None:
    _, b = _breakdowns()
    v = b.visibility
    assert not v.with_fp
    # p1 (100 % visible) in 75-100 %: 6 GT, FN 1, switch 1: MOTA = 1 - 2/6, no FP counted.
    full = _band(v, "75-100 %")
    assert (full.num_gt, full.fn, full.id_switches) == (6, 1, 1)
    assert full.summary(with_fp=False)["mota"] == pytest.approx(4 / 6)
    assert full.summary(with_fp=False)["fp_rate"] is None
    # p2 (30 %) in 25-50 %: 7 GT, FN 1, switch 1: MOTA 5/7; track 30's FP is in no band.
    part = _band(v, "25-50 %")
    assert (part.num_gt, part.fn, part.id_switches, part.fp) == (7, 1, 1, 0)
    assert part.summary(with_fp=False)["mota"] == pytest.approx(5 / 7)
    assert _band(v, "0-25 %").num_gt == 0 and _band(v, "50-75 %").num_gt == 0


def test_a_visibility_on_an_edge_goes_to_the_band_above() -> None:
    gts = [[gt(1, (0, 0, 10, 10), visibility=0.25), gt(2, (50, 0, 10, 10), visibility=1.0)]]
    tracks = [[track(1, (0, 0, 10, 10))]]
    scores = evaluate_sequence(gts, tracks, EvaluationConfig())
    v = bd.breakdowns(scores.table, gts, tracks, None, SETTINGS, Convention.MOTCHALLENGE).visibility
    # 0.25 -> "25-50 %" (matched), 1.0 -> "75-100 %" (missed).
    assert _band(v, "25-50 %").num_matches == 1 and _band(v, "75-100 %").fn == 1


def test_motion_of_a_standing_camera_takes_every_error_of_its_frames() -> None:
    _, b = _breakdowns()
    m = b.motion
    standing = _band(m, "standing")
    # Every frame: 13 GT, FN 2 + FP 1 + IDSW 2 = 5 errors over 7 frames: MOTA = 1 - 5/13.
    assert (standing.frames, standing.num_gt, standing.fp) == (7, 13, 1)
    assert standing.summary()["mota"] == pytest.approx(8 / 13)
    assert standing.summary()["errors_per_frame"] == pytest.approx(5 / 7)
    assert _band(m, "turning") == bd.BandCounts() and _band(m, "driving") == bd.BandCounts()


def test_motion_states_from_the_camera_path() -> None:
    # 10 Hz, 30 frames: 10 standing, 10 turning at 1 rad/s in place, 10 driving at 1 m/s.
    # Speed and turn rate are measured between the frames 0.25 s (2 frames) before and after.
    headings = [0.0] * 10 + [0.1 * k for k in range(1, 11)] + [1.0] * 10
    xs = [0.0] * 20 + [0.1 * k for k in range(1, 11)]
    states = bd.motion_states(_camera(30, headings, xs), SETTINGS)
    # Frame 7: frames 5..9 all at rest -> standing. Frame 8: frames 6..10, heading 0 -> 0.1
    # over 0.4 s = 0.25 rad/s > 0.2 -> turning already (the window's reach).
    assert states[:8] == ["standing"] * 8
    # Heading 0.1 at frame 10 ... 1.0 at frame 19. Frame 20: frames 18..22, 0.9 -> 1.0 in
    # 0.4 s -> turning; frame 21: frames 19..23, heading constant, x 0 -> 0.3 m in 0.4 s =
    # 0.75 m/s > 0.1 -> driving.
    assert states[8:21] == ["turning"] * 13
    assert states[21:] == ["driving"] * 9
    # A higher turning threshold sees the turn as standing (no translation).
    calm = bd.Settings(turning_rate=2.0)
    assert bd.motion_states(_camera(30, headings, xs), calm)[12] == "standing"


def test_distance_follows_a_moving_camera() -> None:
    # The camera drives along x at 1 m/s; person 1 stands at (6.5, 0): 6.5, 6.4, ..., 5.6 m.
    n = 10
    gts = [[gt(1, None, (6.5, 0.0), frame=f)] for f in range(n)]
    tracks = [[track(1, None, (6.5, 0.0))] for _ in range(n)]
    scores = evaluate_sequence(gts, tracks, METRIC)
    camera = _camera(n, xs=[0.1 * f for f in range(n)])
    b = bd.breakdowns(scores.table, gts, tracks, camera, SETTINGS, Convention.MOTCHALLENGE)
    # Frames 0-5 at 6.5..6.0 m (6.0 is on the edge: the band above), 6-9 at 5.9..5.6 m.
    assert _band(b.distance, "6+ m").num_gt == 6 and _band(b.distance, "4-6 m").num_gt == 4
    assert _band(b.motion, "driving").frames == n


def test_a_false_positive_without_a_position_is_in_no_distance_band() -> None:
    # IoU gating: tracks of MOTChallenge text have no world position.
    gts = [[gt(1, (0, 0, 10, 10), (1.0, 0.0))]]
    nowhere = (math.nan, math.nan)
    tracks = [[track(1, (0, 0, 10, 10), nowhere), track(2, (50, 50, 10, 10), nowhere)]]
    scores = evaluate_sequence(gts, tracks, EvaluationConfig())
    d = bd.breakdowns(scores.table, gts, tracks, _camera(1), SETTINGS, Convention.MOTCHALLENGE)
    assert d.distance.unassigned_fp == 1 and _band(d.distance, "0-2 m").num_matches == 1
    assert sum(x.counts.fp for x in d.distance.bands) == 0


def test_breakdowns_without_a_camera_or_positions_say_why() -> None:
    gts, tracks = _scenario()
    scores = evaluate_sequence(gts, tracks, METRIC)
    b = bd.breakdowns(scores.table, gts, tracks, None, SETTINGS, Convention.MOTCHALLENGE)
    assert not b.distance.available and "camera" in b.distance.reason
    assert not b.motion.available
    boxes = [[gt(1, (0, 0, 10, 10))]]
    scores = evaluate_sequence(boxes, [[track(1)]], EvaluationConfig())
    b = bd.breakdowns(
        scores.table, boxes, [[track(1)]], _camera(1), SETTINGS, Convention.MOTCHALLENGE
    )
    assert not b.distance.available and "world positions" in b.distance.reason
    # Every instance 100 % visible: no visibility was annotated (MOT15).
    assert not b.visibility.available


def test_per_person_switches_and_the_gap_before_them() -> None:
    _, b = _breakdowns()
    p1, p2 = b.persons
    # p1: 6 frames, matched in 5; tracks 10 then 11; the switch at f6 comes 1 frame after its
    # last match (f4), a frame (f5) in which p1 was not annotated: unseen 1.
    assert (p1.gt_id, p1.frames, p1.matched, p1.track_ids) == (1, 6, 5, (10, 11))
    assert p1.coverage == pytest.approx(5 / 6)
    assert p1.switches == (bd.Switch(frame=6, from_track=10, to_track=11, gap=1, unseen=1),)
    assert p1.fragmentations == 2
    # p2: switch at f3, 1 frame after its last match (f1); it was annotated (missed) in f2.
    assert p2.switches == (bd.Switch(frame=3, from_track=20, to_track=21, gap=1, unseen=0),)
    assert p2.fragmentations == 1


def test_per_gap_recovery() -> None:
    _, b = _breakdowns()
    one = next(g for g in b.gaps if g.label == "1")
    # Gaps of 1 frame: p1 f2->f4 (10 again: recovered), p1 f4->f6 (10 -> 11), p2 f1->f3
    # (20 -> 21): 3 gaps, 1 recovered.
    assert (one.gaps, one.recovered) == (3, 1) and one.rate == pytest.approx(1 / 3)
    assert sum(g.gaps for g in b.gaps) == 3
    assert [g.label for g in b.gaps] == ["1", "2-4", "5-9", "10-29", "30-89", "90+"]


TUD = Path(pytest.importorskip("motmetrics").__file__).parent / "data"


@pytest.mark.parametrize("convention", list(Convention))
@pytest.mark.parametrize("name", ["TUD-Campus", "TUD-Stadtmitte"])
def test_per_person_counts_add_up_to_the_sequence(name: str, convention: Convention) -> None:
    aligned = align(read_mot_gt(TUD / name / "gt.txt"), read_mot_tracks(TUD / name / "test.txt"), 0)
    config = EvaluationConfig(convention=convention)
    scores = evaluate_sequence(aligned.gt, aligned.tracks, config)
    b = bd.breakdowns(scores.table, aligned.gt, aligned.tracks, None, SETTINGS, convention)
    c = scores.counts
    assert sum(p.fragmentations for p in b.persons) == c.fragmentations
    assert sum(p.id_switches for p in b.persons) == c.id_switches
    assert sum(p.matched for p in b.persons) == c.num_matches
    assert sum(p.frames for p in b.persons) == c.num_gt
    # Every gap ends in a match that either keeps the id or is a switch.
    not_recovered = sum(g.gaps - g.recovered for g in b.gaps)
    switches_after_a_gap = sum(1 for p in b.persons for s in p.switches if s.gap > 0)
    assert not_recovered == switches_after_a_gap


def test_bands_of_several_sequences_add_up() -> None:
    _, b = _breakdowns()
    twice = b.distance + b.distance
    near = _band(twice, "0-2 m")
    assert (near.num_gt, near.fn, near.id_switches) == (12, 2, 2)
    assert near.summary()["mota"] == pytest.approx(1 - 4 / 12)


def test_a_run_is_analysed_on_its_annotated_span_only() -> None:
    """``run`` scores frames 2..5 of 8 (the annotated span): the breakdowns, intervals and curve
    take those frames only, and a switch's frame is the recording's.

    GT: person 1 at (1, 0) in frames 2..5. Tracks: 10 on it in frames 2, 3, 11 in 4, 5 (a
    switch at frame 4); track 9 at (4, 0), 3 m from it, in every frame: FPs, 4 of them in the
    span. The camera drives along x at 1 m/s (10 Hz): every frame is 'driving'.
    """
    from types import SimpleNamespace

    from rgbd_eval.config import RunConfig
    from rgbd_eval.pipeline import GroundTruthMatch, score_sequence
    from rgbd_eval.report.analysis import analyse, inputs_of_run

    n, span = 8, (2, 5)
    gts = [[gt(1, None, (1.0, 0.0), frame=f)] if 2 <= f <= 5 else [] for f in range(n)]
    fp = replace(track(9, None, (4.0, 0.0)), confidence=0.2)
    tracks = tuple(
        (
            *(
                (replace(track(10 if f < 4 else 11, None, (1.0, 0.0)), confidence=0.9),)
                if 2 <= f <= 5
                else ()
            ),
            fp,
        )
        for f in range(n)
    )
    config = RunConfig(evaluation=METRIC)
    match = GroundTruthMatch("gt.csv", gts, 4, 0, span)
    scores = score_sequence(match, tracks, config)
    assert (scores.counts.num_gt, scores.counts.fp, scores.counts.id_switches) == (4, 4, 1)
    poses = []
    for f in range(n):
        t = np.eye(4)
        t[:3, :3] = [[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]]  # optical, looking +x
        t[0, 3] = 0.1 * f
        poses.append(Pose.from_matrix(t))
    result = SimpleNamespace(
        name="part",
        scores=scores,
        ground_truth=match,
        tracks=tracks,
        detections=SimpleNamespace(
            stamps_ns=tuple(f * STEP_NS for f in range(n)), camera_poses=tuple(poses)
        ),
        info=SimpleNamespace(world_frame="odom", has_odometry=True),
    )
    analysis = analyse(inputs_of_run([result]), METRIC, curve_points=5)  # type: ignore[list-item]
    (part,) = analysis.sequences
    assert part.frames == 4
    motion = next(b for b in part.breakdowns if b.kind == bd.MOTION)
    driving = _band(motion, "driving")
    assert (driving.frames, driving.num_gt, driving.fp, driving.id_switches) == (4, 4, 4, 1)
    distance = next(b for b in part.breakdowns if b.kind == bd.DISTANCE)
    # FPs by the track's own distance: 9 is 4 - 0.1 f m away, 3.8..3.5 m in frames 2..5.
    assert _band(distance, "2-4 m").fp == 4
    (person,) = part.persons
    assert person.frames == 4 and [s.frame for s in person.switches] == [4]
    # The curve scores what was scored: at the lowest threshold, the sequence's counts.
    assert analysis.curve is not None
    lowest = analysis.curve.points[0]
    assert lowest.threshold == 0.2 and lowest.overall.fp == scores.counts.fp
    assert analysis.curve.points[-1].overall.fp == 0
