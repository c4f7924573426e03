"""Hand-computed scenarios where the two conventions differ, and the devkit's ignored ground truth.

Boxes are 10x10 pixels unless said otherwise.
"""

from __future__ import annotations

from metrics_builders import gt, track

from rgbd_eval.config import Convention, EvaluationConfig, Gating
from rgbd_eval.metrics import evaluate_sequence
from rgbd_eval.types import Box2D, GroundTruthObject

MC = EvaluationConfig(gating=Gating.IOU, convention=Convention.MOTCHALLENGE)
MM = EvaluationConfig(gating=Gating.IOU, convention=Convention.MOTMETRICS)
A = (0.0, 0.0, 10.0, 10.0)
FAR = (500.0, 500.0, 10.0, 10.0)


def test_previous_match_kept_only_from_the_previous_frame() -> None:
    # GT 1 at A in 7 frames; track 8 sits exactly on A, track 7 is 1 px off (IoU 90 / 110
    # = 0.82). Frames 0-4 give the same matches in both conventions: 7, 8 (switch), 8,
    # 7 (switch), 7. Frame 5 has both tracks far away: GT 1 is missed. Frame 6 has both
    # on A: motchallenge has no previous-frame match to keep and takes the better IoU
    # (8, a switch); motmetrics gives GT 1 back its last track, 7 (no switch).
    shifted = (1.0, 0.0, 10.0, 10.0)
    gts = [[gt(1, A)]] * 7
    tracks = [
        [track(7, A)],
        [track(8, A)],
        [track(7, shifted), track(8, A)],
        [track(7, shifted)],
        [track(7, shifted), track(8, A)],
        [track(7, FAR), track(8, FAR)],
        [track(7, shifted), track(8, A)],
    ]
    mc = evaluate_sequence(gts, tracks, MC)
    mm = evaluate_sequence(gts, tracks, MM)
    assert [[(m.track_id, m.id_switch) for m in f.matches] for f in mc.frames][-1] == [(8, True)]
    assert [[(m.track_id, m.id_switch) for m in f.matches] for f in mm.frames][-1] == [(7, False)]
    # Switches: frames 1, 3 in both; frame 6 only under motchallenge.
    assert (mc.counts.id_switches, mm.counts.id_switches) == (3, 2)


def test_mostly_tracked_at_exactly_80_percent() -> None:
    # GT 1 in 5 frames, matched in 4: ratio 0.8 exactly. The devkit wants > 80 %.
    gts = [[gt(1, A)]] * 5
    tracks = [[track(7, A)]] * 4 + [[track(7, FAR)]]
    assert evaluate_sequence(gts, tracks, MC).counts.mostly_tracked == 0
    assert evaluate_sequence(gts, tracks, MC).counts.partly_tracked == 1
    assert evaluate_sequence(gts, tracks, MM).counts.mostly_tracked == 1


def test_fragmentation_at_a_frame_without_tracks() -> None:
    # GT 1 in 4 frames; frame 2 has no track at all, frame 2' (second scenario) has one
    # far away. TrackEval leaves its previous-frame memory untouched on a frame without
    # tracks, so only the second scenario fragments under motchallenge; motmetrics
    # counts both (tracked, tracked, missed, tracked).
    gts = [[gt(1, A)]] * 4
    empty = [[track(7, A)], [track(7, A)], [], [track(7, A)]]
    far = [[track(7, A)], [track(7, A)], [track(9, FAR)], [track(7, A)]]
    assert evaluate_sequence(gts, empty, MC).counts.fragmentations == 0
    assert evaluate_sequence(gts, far, MC).counts.fragmentations == 1
    assert evaluate_sequence(gts, empty, MM).counts.fragmentations == 1
    assert evaluate_sequence(gts, far, MM).counts.fragmentations == 1


def _box_with_iou(iou: float) -> tuple[float, float, float, float]:
    # A 10x10 box shifted right by s overlaps A in 10 (10 - s): IoU = (10 - s) / (10 + s),
    # so s = 10 (1 - IoU) / (1 + IoU).
    s = 10.0 * (1.0 - iou) / (1.0 + iou)
    return (s, 0.0, 10.0, 10.0)


def test_track_on_a_person_and_a_distractor_is_a_match() -> None:
    # The case: the track has IoU 0.92 with the visible person and 0.53 with a
    # distractor. Matching both together (the devkit) pairs it with the person
    # (0.92 > 0.53): a match, nothing dropped. Matching the distractor first would
    # drop the track and miss the person.
    person = A
    track_box = _box_with_iou(0.92)  # shifted right by 0.4167 px
    # The distractor sits to the left of the track so that its IoU with it is 0.53.
    s = 10.0 * (1.0 - 0.53) / (1.0 + 0.53)
    distractor = (track_box[0] - s, 0.0, 10.0, 10.0)
    gts = [[gt(1, person), gt(2, distractor, ignore=True)]]
    for config in (MC, MM):
        scores = evaluate_sequence(gts, [[track(7, track_box)]], config)
        c = scores.counts
        assert (c.num_matches, c.fn, c.fp, c.ignored_tracks) == (1, 0, 0, 0)
        assert scores.frames[0].matches[0].similarity > 0.919


def test_a_track_on_a_distractor_alone_is_dropped() -> None:
    gts = [[gt(1, A), gt(2, FAR, ignore=True)]]
    c = evaluate_sequence(gts, [[track(7, A), track(8, FAR)]], MC).counts
    assert (c.num_matches, c.fp, c.ignored_tracks, c.ignored_gt) == (1, 0, 1, 1)


def test_non_distractor_ignored_object_keeps_its_track_as_false_positive() -> None:
    # MOT17: a pedestrian with consider flag 0 (or a car) is not scored, but a track on
    # it stays scored: a false positive.
    car = GroundTruthObject(0, 0, 2, Box2D(*FAR), None, ignore=True, distractor=False)
    c = evaluate_sequence([[gt(1, A), car]], [[track(7, A), track(8, FAR)]], MC).counts
    assert (c.num_matches, c.fp, c.ignored_tracks) == (1, 1, 0)
