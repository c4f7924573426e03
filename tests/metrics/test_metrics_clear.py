"""Hand-computed CLEAR MOT micro-scenarios for ``evaluate_sequence``.

Boxes are 10x10 pixels unless said otherwise; people stand 100 px apart so that
only the intended pairs overlap.
"""

from __future__ import annotations

import pytest
from metrics_builders import gt, track

from rgbd_eval.config import Convention, EvaluationConfig, Gating
from rgbd_eval.errors import RgbdEvalError, ScoringError
from rgbd_eval.metrics import Counts, evaluate_sequence, summarize, total
from rgbd_eval.types import TrackStatus, Visibility

# The hand-computed counts below follow motmetrics 1.4; test_metrics_conventions.py
# covers where the motchallenge convention differs.
MM = Convention.MOTMETRICS
IOU = EvaluationConfig(gating=Gating.IOU, convention=MM)
METRIC = EvaluationConfig(gating=Gating.METRIC, convention=MM)
A = (0.0, 0.0, 10.0, 10.0)  # person A's box
B = (100.0, 0.0, 10.0, 10.0)  # person B's box
FAR = (500.0, 500.0, 10.0, 10.0)  # nobody there


def test_perfect_tracking() -> None:
    # 3 frames x 2 people, tracks exactly on them: 6 GT, 6 matches of IoU 1.
    gts = [[gt(1, A), gt(2, B)]] * 3
    tracks = [[track(7, A), track(8, B)]] * 3
    scores = evaluate_sequence(gts, tracks, IOU)
    c = scores.counts
    assert (c.num_frames, c.num_gt, c.num_matches, c.fp, c.fn, c.id_switches) == (3, 6, 6, 0, 0, 0)
    s = scores.summary()
    assert s["mota"] == 1.0  # 1 - 0 / 6
    assert s["motp"] == 1.0  # 6 x IoU 1 / 6
    assert (s["main_tr"], s["all_tr"], s["idf1"]) == (1.0, 1.0, 1.0)
    assert (s["mt"], s["pt"], s["ml"]) == (2, 0, 0)


def test_one_miss() -> None:
    # GT 1 in 4 frames, the track is missing in frame 2.
    gts = [[gt(1, A)]] * 4
    tracks = [[track(7, A)], [track(7, A)], [], [track(7, A)]]
    c = evaluate_sequence(gts, tracks, IOU).counts
    assert (c.num_gt, c.num_matches, c.fn, c.fp) == (4, 3, 1, 0)
    s = summarize(c)
    assert s["mota"] == pytest.approx(0.75)  # 1 - 1 / 4
    assert s["fn_rate"] == pytest.approx(0.25)
    assert s["all_tr"] == pytest.approx(0.75)  # 3 / 4
    assert c.fragmentations == 1  # tracked, tracked, lost, tracked
    assert (c.mostly_tracked, c.partly_tracked) == (0, 1)  # 3/4 = 0.75 < 0.8


def test_one_false_positive() -> None:
    # GT 1 in 2 frames, matched; frame 1 has an extra track far away.
    gts = [[gt(1, A)]] * 2
    tracks = [[track(7, A)], [track(7, A), track(9, FAR)]]
    c = evaluate_sequence(gts, tracks, IOU).counts
    assert (c.num_gt, c.num_tracks, c.num_matches, c.fp, c.fn) == (2, 3, 2, 1, 0)
    s = summarize(c)
    assert s["mota"] == pytest.approx(0.5)  # 1 - 1 / 2
    assert s["fp_rate"] == pytest.approx(0.5)
    assert s["precision"] == pytest.approx(2 / 3)
    # IDF1: GT 1 <-> track 7 for 2 frames; track 9's frame is an IDFP: 4 / (4 + 1 + 0)
    assert s["idf1"] == pytest.approx(0.8)


def test_an_id_switch() -> None:
    # GT 1 in 4 frames: track 7 in frames 0-1, track 8 in frames 2-3 (same place).
    gts = [[gt(1, A)]] * 4
    tracks = [[track(7, A)]] * 2 + [[track(8, A)]] * 2
    scores = evaluate_sequence(gts, tracks, IOU)
    c = scores.counts
    assert (c.num_matches, c.id_switches, c.fp, c.fn, c.recall_errors) == (4, 1, 0, 0, 0)
    s = summarize(c)
    assert s["mota"] == pytest.approx(0.75)  # 1 - 1 / 4
    assert s["main_tr"] == pytest.approx(0.5)  # id 7 (or 8) covers 2 of 4 frames
    assert s["all_tr"] == 1.0
    # IDF1: GT 1 <-> one of the ids for 2 frames: IDTP 2, IDFN 2, IDFP 2 -> 4 / 8
    assert s["idf1"] == pytest.approx(0.5)
    assert [m.id_switch for f in scores.frames for m in f.matches] == [False, False, True, False]


def test_a_swap_of_two_ids() -> None:
    # Frames 0-1: 7 on A, 8 on B; frames 2-3: 7 on B, 8 on A (both ids present throughout).
    gts = [[gt(1, A), gt(2, B)]] * 4
    tracks = [[track(7, A), track(8, B)]] * 2 + [[track(7, B), track(8, A)]] * 2
    c = evaluate_sequence(gts, tracks, IOU).counts
    # A: 7 -> 8 and B: 8 -> 7 at frame 2; both are switches, neither is a recall error
    # (the ids were never given up).
    assert (c.num_matches, c.id_switches, c.recall_errors) == (8, 2, 0)
    s = summarize(c)
    assert s["mota"] == pytest.approx(0.75)  # 1 - 2 / 8
    assert s["main_tr"] == pytest.approx(0.5)  # A: 2 (7 or 8), B: 2 -> 4 / 8


def test_recall_error_is_an_id_handed_back_to_another_person() -> None:
    # Frames 0-1: 7 on A, 8 on B. Frame 2: A has left, B is missed, no track.
    # Frames 3-4: the tracker re-initialises B with A's old id 7.
    gts = [[gt(1, A), gt(2, B)]] * 2 + [[gt(2, B)]] * 3
    tracks = [[track(7, A), track(8, B)]] * 2 + [[]] + [[track(7, B)]] * 2
    scores = evaluate_sequence(gts, tracks, IOU)
    c = scores.counts
    # GT: A 2 + B 5 = 7; matches 2 + 2 + 2 = 6; FN 1 (B, frame 2); switch B: 8 -> 7.
    assert (c.num_gt, c.num_matches, c.fn, c.id_switches, c.recall_errors) == (7, 6, 1, 1, 1)
    assert summarize(c)["mota"] == pytest.approx(5 / 7)  # 1 - (1 + 0 + 1) / 7
    assert summarize(c)["main_tr"] == pytest.approx(4 / 7)  # A: 2, B: 2 (8 or 7)
    frame3 = scores.frames[3].matches
    assert frame3[0].gt_id == 2 and frame3[0].track_id == 7
    assert frame3[0].id_switch and frame3[0].recall_error


def test_a_switch_onto_a_kept_id_is_not_a_recall_error() -> None:
    # As above, but id 7 is still output in frame 2 (far away, a false positive):
    # it was never given up, so the switch of B onto it is no recall error.
    gts = [[gt(1, A), gt(2, B)]] * 2 + [[gt(2, B)]] * 3
    tracks = [[track(7, A), track(8, B)]] * 2 + [[track(7, FAR)]] + [[track(7, B)]] * 2
    c = evaluate_sequence(gts, tracks, IOU).counts
    assert (c.id_switches, c.recall_errors, c.fp) == (1, 0, 1)


def test_ignored_ground_truth_with_a_track_on_it() -> None:
    # GT 1 normal with track 7; GT 2 ignored with track 8 on it; GT 3 ignored, no track;
    # a NOT_VISIBLE and a NEW track far away are not scored.
    gts = [[gt(1, A), gt(2, B, ignore=True), gt(3, (200, 0, 10, 10), ignore=True)]]
    tracks = [
        [
            track(7, A),
            track(8, B),
            track(9, FAR, visibility=Visibility.NOT_VISIBLE),
            track(10, FAR, status=TrackStatus.NEW),
        ]
    ]
    scores = evaluate_sequence(gts, tracks, IOU)
    c = scores.counts
    assert (c.num_gt, c.num_tracks, c.num_matches, c.fp, c.fn) == (1, 1, 1, 0, 0)
    assert (c.ignored_gt, c.ignored_tracks) == (2, 1)
    assert summarize(c)["mota"] == 1.0
    assert scores.frames[0].ignored_gt == (2, 3)
    assert scores.frames[0].ignored_tracks == (8,)
    # Control: without the ignore flag GT 3 is a miss and GT 2 a match.
    plain = [[gt(1, A), gt(2, B), gt(3, (200, 0, 10, 10))]]
    c = evaluate_sequence(plain, tracks, IOU).counts
    assert (c.num_gt, c.num_matches, c.fn, c.ignored_gt) == (3, 2, 1, 0)


def test_low_visibility_is_ignored() -> None:
    gts = [[gt(1, A), gt(2, B, visibility=0.2)]]
    tracks = [[track(7, A), track(8, B)]]
    c = evaluate_sequence(gts, tracks, EvaluationConfig(min_visibility=0.5, convention=MM)).counts
    assert (c.num_gt, c.num_matches, c.fp, c.ignored_gt, c.ignored_tracks) == (1, 1, 0, 1, 1)


def test_tracks_are_matched_to_ignored_ground_truth_first() -> None:
    # GT 2 (ignored) at (1, 0) overlaps GT 1 at (0, 0): IoU 90 / 110 = 0.82. Track 7 sits
    # exactly on GT 2, so it is dropped first and GT 1 counts as a miss.
    gts = [[gt(1, A), gt(2, (1, 0, 10, 10), ignore=True)]]
    c = evaluate_sequence(gts, [[track(7, (1, 0, 10, 10))]], IOU).counts
    assert (c.num_gt, c.num_matches, c.fn, c.fp, c.ignored_tracks) == (1, 0, 1, 0, 1)


def test_ignored_ground_truth_without_box_is_skipped() -> None:
    # A person out of the image has a world position but no box: ignored, drops no track.
    gts = [[gt(1, A), gt(2, None, (5.0, 0.0), ignore=True)]]
    c = evaluate_sequence(gts, [[track(7, A)]], IOU).counts
    assert (c.num_gt, c.num_matches, c.ignored_gt, c.ignored_tracks) == (1, 1, 1, 0)


def test_metric_and_iou_gating_match_differently() -> None:
    # GT 1: box A, at (0, 0) m. Track 7: box shifted 5 px -> IoU 50 / 150 = 0.33 (< 0.5),
    #   but 0.5 m from GT 1 (<= 1 m).
    # GT 2: box B, at (3, 0) m. Track 8: exactly on box B (IoU 1), but at (4.5, 0): 1.5 m.
    gts = [[gt(1, A, (0.0, 0.0)), gt(2, B, (3.0, 0.0))]]
    tracks = [[track(7, (5, 0, 10, 10), (0.5, 0.0)), track(8, B, (4.5, 0.0))]]
    by_iou = evaluate_sequence(gts, tracks, IOU)
    by_distance = evaluate_sequence(gts, tracks, METRIC)
    assert [(m.gt_id, m.track_id) for m in by_iou.frames[0].matches] == [(2, 8)]
    assert [(m.gt_id, m.track_id) for m in by_distance.frames[0].matches] == [(1, 7)]
    assert by_iou.summary()["motp"] == 1.0  # mean IoU
    assert by_distance.summary()["motp"] == pytest.approx(0.5)  # mean distance, metres
    for scores in (by_iou, by_distance):
        assert (scores.counts.fp, scores.counts.fn) == (1, 1)
    # A wider metric gate (2 m) matches both.
    wide = evaluate_sequence(
        gts, tracks, EvaluationConfig(gating=Gating.METRIC, threshold=2.0, convention=MM)
    )
    assert wide.counts.num_matches == 2
    assert wide.summary()["motp"] == pytest.approx(1.0)  # (0.5 + 1.5) / 2


def test_main_and_all_tracked_when_the_id_changes_once() -> None:
    # GT 1 in 10 frames: id 7 in frames 0-5, nothing in frame 6, id 9 in frames 7-9.
    gts = [[gt(1, A)]] * 10
    tracks = [[track(7, A)]] * 6 + [[]] + [[track(9, A)]] * 3
    s = evaluate_sequence(gts, tracks, IOU).summary()
    assert s["main_tr"] == pytest.approx(0.6)  # id 7 covers 6 of 10 frames
    assert s["all_tr"] == pytest.approx(0.9)  # any id: 9 of 10 = 1 - FN% (0.1)
    assert s["id_switches"] == 1
    assert s["mota"] == pytest.approx(0.8)  # 1 - (1 FN + 0 FP + 1 IDSW) / 10


def test_mostly_tracked_partly_tracked_mostly_lost() -> None:
    # 4 people in 10 frames, matched in 8, 2, 1 and 0 frames:
    # 8/10 = 0.8 -> MT (>= 80 %), 2/10 = 0.2 -> PT (>= 20 %), 1/10 and 0/10 -> ML.
    boxes = {p: (100.0 * p, 0.0, 10.0, 10.0) for p in range(4)}
    matched = {0: 8, 1: 2, 2: 1, 3: 0}
    gts = [[gt(p, boxes[p]) for p in range(4)] for _ in range(10)]
    tracks = [[track(10 + p, boxes[p]) for p in range(4) if f < matched[p]] for f in range(10)]
    c = evaluate_sequence(gts, tracks, IOU).counts
    assert (c.num_gt_tracks, c.mostly_tracked, c.partly_tracked, c.mostly_lost) == (4, 1, 1, 2)
    assert c.num_matches == 11  # 8 + 2 + 1 + 0


def test_matching_keeps_a_previous_match_while_it_is_valid() -> None:
    # Frame 0: GT 1 with track 7 (IoU 1). Frame 1: track 7 moved 2 px (IoU 80 / 120 = 0.67),
    # track 8 sits exactly on GT 1 (IoU 1). motmetrics keeps 1-7 (still inside the gate):
    # no switch, track 8 is a FP. A plain Hungarian would pick 8 and count a switch.
    shifted = (2.0, 0.0, 10.0, 10.0)
    gts = [[gt(1, A)]] * 2
    tracks = [[track(7, A)], [track(7, shifted), track(8, A)]]
    scores = evaluate_sequence(gts, tracks, IOU)
    assert [(m.gt_id, m.track_id) for m in scores.frames[1].matches] == [(1, 7)]
    assert scores.frames[1].false_positives == (8,)
    assert (scores.counts.id_switches, scores.counts.fp) == (0, 1)
    assert scores.counts.similarity_sum == pytest.approx(1.0 + 2 / 3)


def test_previous_match_is_kept_across_a_gap() -> None:
    # Frame 1 has no track (GT 1 missed). In frame 2 motmetrics still prefers the old
    # partner 7 (IoU 0.67) over 8 (IoU 1); TrackEval, which favours only matches of the
    # previous frame, would pick 8 and count an id switch.
    shifted = (2.0, 0.0, 10.0, 10.0)
    gts = [[gt(1, A)]] * 3
    tracks = [[track(7, A)], [], [track(7, shifted), track(8, A)]]
    scores = evaluate_sequence(gts, tracks, IOU)
    assert [(m.gt_id, m.track_id) for m in scores.frames[2].matches] == [(1, 7)]
    assert (scores.counts.id_switches, scores.counts.fn, scores.counts.fp) == (0, 1, 1)


def test_empty_sequence() -> None:
    scores = evaluate_sequence([], [], IOU)
    assert scores.counts == Counts.empty(Gating.IOU, 0.5, MM)
    assert scores.frames == ()
    assert scores.summary()["mota"] is None


def test_frames_without_anything() -> None:
    s = evaluate_sequence([[], [], []], [[], [], []], METRIC).summary()
    assert s["num_frames"] == 3
    assert s["num_gt"] == 0
    assert s["mota"] is None and s["motp"] is None and s["idf1"] is None


def test_tracks_without_ground_truth() -> None:
    s = evaluate_sequence([[], []], [[track(7)], [track(7)]], IOU).summary()
    assert (s["fp"], s["num_gt"]) == (2, 0)
    assert s["mota"] is None and s["fp_rate"] is None
    assert s["precision"] == 0.0
    assert s["idf1"] == 0.0  # 0 / (0 + 2 + 0)


def test_ground_truth_without_tracks() -> None:
    s = evaluate_sequence([[gt(1)]] * 3, [[]] * 3, IOU).summary()
    assert (s["fn"], s["mota"], s["motp"], s["ml"]) == (3, 0.0, None, 1)  # 1 - 3 / 3


def test_overall_is_derived_from_summed_counts() -> None:
    # Sequence 1: 4 frames, perfect (MOTA 1). Sequence 2: 1 frame, one miss (MOTA 0).
    # Overall MOTA = 1 - 1 / 5 = 0.8, not the mean of ratios (0.5).
    first = evaluate_sequence([[gt(1, A)]] * 4, [[track(7, A)]] * 4, IOU).counts
    second = evaluate_sequence([[gt(1, A)]], [[]], IOU).counts
    overall = total([first, second])
    assert (overall.num_frames, overall.num_gt, overall.num_matches, overall.fn) == (5, 5, 4, 1)
    assert overall.num_gt_tracks == 2
    assert summarize(overall)["mota"] == pytest.approx(0.8)
    assert summarize(overall)["idf1"] == pytest.approx(8 / 9)  # 2*4 / (2*4 + 0 + 1)


def test_ground_truth_frame_field_does_not_matter() -> None:
    # Frames are index-aligned; GroundTruthObject.frame is informative only.
    c = evaluate_sequence([[gt(1, A, frame=42)]], [[track(7, A)]], IOU).counts
    assert c.num_matches == 1


@pytest.mark.parametrize(
    ("gts", "tracks", "config", "message"),
    [
        ([[]], [[], []], IOU, "ground truth has 1 frames but the tracker output has 2"),
        ([[], [gt(1)]], [[], [track(7, None)]], IOU, "frame 1: track id 7 has no 2D box"),
        ([[gt(3, None, (1.0, 0.0))]], [[]], IOU, "frame 0: ground-truth id 3 has no 2D box"),
        ([[gt(3, A)]], [[]], METRIC, "frame 0: ground-truth id 3 has no world position"),
        ([[gt(1), gt(1)]], [[]], IOU, r"frame 0: ground-truth id\(s\) \[1\] appear more"),
        ([[]], [[track(7), track(7)]], IOU, r"frame 0: track id\(s\) \[7\] appear more"),
        ([[gt(1, (0, 0, -1, 5))]], [[]], IOU, "frame 0: ground-truth id 1 has an invalid box"),
        ([[]], [[track(7, (0, float("nan"), 1, 1))]], IOU, "frame 0: track id 7 has an invalid"),
        ([[gt(1, None, (float("inf"), 0.0))]], [[]], METRIC, "ground-truth id 1 has an invalid"),
        ([[gt(2**60)]], [[]], IOU, "frame 0: ground-truth ids must be smaller than 2\\*\\*53"),
    ],
)
def test_bad_input_raises_scoring_error(
    gts: list[list[object]], tracks: list[list[object]], config: EvaluationConfig, message: str
) -> None:
    with pytest.raises(ScoringError, match=message) as info:
        evaluate_sequence(gts, tracks, config)  # type: ignore[arg-type]
    assert isinstance(info.value, RgbdEvalError)
    assert info.value.exit_code == 6


def test_unscored_tracks_need_no_box() -> None:
    # NOT_VISIBLE and NEW tracks are not scored, so a missing box is fine.
    tracks = [
        [
            track(7, None, visibility=Visibility.NOT_VISIBLE),
            track(8, None, status=TrackStatus.NEW),
        ]
    ]
    c = evaluate_sequence([[gt(1)]], tracks, IOU).counts
    assert (c.num_tracks, c.fn) == (0, 1)


def test_occluded_tracks_are_scored() -> None:
    c = evaluate_sequence([[gt(1)]], [[track(7, visibility=Visibility.OCCLUDED)]], IOU).counts
    assert c.num_matches == 1
