"""reproduce satake2009: per-person records and claims on hand-made events (fast)."""

from __future__ import annotations

from typing import Any

import pytest

from rgbd_eval.methods.satake2009.experiments import (
    PersonRecord,
    RunJudgement,
    check_claims,
    paper_values,
    person_records,
    summarise,
)
from rgbd_eval.methods.satake2009.follow import FollowResult, FollowStep, FollowSummary
from rgbd_eval.metrics.clear import FrameEvents, Match
from rgbd_eval.types import Box2D, GroundTruthObject, TrackOutput, TrackStatus, Visibility
from rgbd_eval.verdicts import Verdict


def _step(frame: int, status: Any = "following", track: int | None = 5) -> FollowStep:
    return FollowStep(
        frame, frame, frame / 20, 0.0, 0.0, 0.0, 4.0, 0.0, 4.0, 0.0, track, 4.0, 0.0, 0.1,
        status, 0.5, 0.5,
    )  # fmt: skip


def _gt(frame: int, gid: int, x: float, box: tuple[float, ...], vis: float) -> GroundTruthObject:
    return GroundTruthObject(frame, frame, gid, Box2D(*box), (x, 0.0, 0.9), vis)


def test_person_records_count_matches_ids_switches_and_occluders() -> None:
    # Frame 0: A (1) matched by track 5, B (2) missed.
    # Frame 1: A missed, 30% visible, B nearer (2 m vs 4 m) with an overlapping box; B -> 6.
    # Frame 2: A matched by track 7 (an ID switch), B by 6.
    # A: scored 3 (2 matches + 1 miss), main id 5 or 7 with 1 match each -> Main Tr. 1/3,
    #    All Tr. 2/3, ids (5, 7), 1 switch, min visibility 0.3, behind B once.
    # B: scored 3, matched 2 (both by 6): Main Tr. = All Tr. = 2/3, never behind A
    #    (A is farther in frame 1).
    events = [
        FrameEvents(0, (Match(1, 5, 0.1, False, False),), (2,), (), (), ()),
        FrameEvents(1, (Match(2, 6, 0.1, False, False),), (1,), (), (), ()),
        FrameEvents(2, (Match(1, 7, 0.1, True, False), Match(2, 6, 0.1, False, False)), (), (), (), ()),
    ]  # fmt: skip
    a_box, b_box = (100.0, 50.0, 40.0, 100.0), (110.0, 40.0, 50.0, 120.0)
    truth = [
        [_gt(0, 1, 4.0, a_box, 1.0), _gt(0, 2, 2.0, (300.0, 40.0, 50.0, 120.0), 1.0)],
        [_gt(1, 1, 4.0, a_box, 0.3), _gt(1, 2, 2.0, b_box, 1.0)],
        [_gt(2, 1, 4.0, a_box, 0.9), _gt(2, 2, 2.0, (10.0, 40.0, 50.0, 120.0), 1.0)],
    ]
    steps = [_step(i) for i in range(3)]
    a, b = person_records(events, truth, steps, {"A": 1, "B": 2}, 0.5)
    assert (a.scored, a.matched, a.main_matches, a.ids, a.id_switches) == (3, 2, 1, (5, 7), 1)
    assert a.all_tr == pytest.approx(2 / 3) and a.main_tr == pytest.approx(1 / 3)
    assert a.min_visibility == 0.3 and a.occluded_by == {"B": 1}
    assert (b.scored, b.matched, b.main_matches, b.ids, b.id_switches) == (3, 2, 2, (6,), 0)
    assert b.occluded_by == {"A": 0}


def _result(locked: int | None, first: int, last_status: Any, kept: bool) -> FollowResult:
    track = TrackOutput(first, 4.0, 0.0, 1.7, None, Visibility.VISIBLE, TrackStatus.VALIDATED)
    steps = (_step(0, "searching", None), _step(1, last_status, locked))
    summary = FollowSummary(
        "s", 0, 1, 2, locked, 1, kept, int(kept), 0, int(not kept), None,
        2.5, 2.4, 2.6, 2.5, 1.0, 2.0, 0.1,
    )  # fmt: skip
    return FollowResult(steps, summary, ((), (track,)), ((), ()), {"detect": 0.1, "track": 0.01})


def _record(
    name: str, gid: int, main: int, matched: int, switches: int, **occ: int
) -> PersonRecord:
    return PersonRecord(name, gid, 10, matched, main, (gid,), switches, 0.2, dict(occ))


def test_claims_follow_the_thresholds_of_the_paper_yaml() -> None:
    paper = paper_values()
    c = paper["claims"]
    assert c["a_correctly_tracked"]["main_tr_min"] == 1.0  # the issue: Main Tr. of A = 100 %
    assert paper["timing"]["ms_per_frame"] == 70  # seed 002 section 4
    good = [
        _record("A", 1, 10, 10, 0, B=3, C=2),
        _record("B", 2, 9, 9, 0, A=0, C=0),
        _record("C", 3, 8, 8, 0, A=0, B=0),
    ]
    held = {
        x.key: x.held for x in check_claims(paper, _result(4, 4, "following", True), good, good[0])
    }
    assert held == dict.fromkeys(
        ("follows_a_detected_first", "a_correctly_tracked", "all_tracked_through_occlusions"),
        True,
    )
    # A's Main Tr. 90% (< 100%), B All Tr. 70% (< 80%), followed track not the first
    bad = [
        _record("A", 1, 9, 10, 1, B=3, C=2),
        _record("B", 2, 7, 7, 0, A=0, C=0),
        _record("C", 3, 8, 8, 0, A=0, B=0),
    ]
    held = {
        x.key: x.held for x in check_claims(paper, _result(5, 4, "following", True), bad, bad[0])
    }
    assert not any(held.values())
    # nobody crossed in front of A: the claim about B and C passing cannot hold
    unseen = [_record("A", 1, 10, 10, 0, B=0, C=2), *good[1:]]
    held = {
        x.key: x.held
        for x in check_claims(paper, _result(4, 4, "following", True), unseen, unseen[0])
    }
    assert not held["a_correctly_tracked"] and held["all_tracked_through_occlusions"]


def _judged(records: list[PersonRecord], ms: float) -> RunJudgement:
    paper = paper_values()
    result = _result(4, 4, "following", True)
    claims = check_claims(paper, result, records, records[0])
    timing = {"ms_per_frame": ms, "detect_ms": ms - 1.0, "track_ms": 1.0, "render_ms": 300.0}
    return RunJudgement(result, records, records[0], {"mota": 0.9}, claims, timing)


def test_verdicts_over_seeds_and_timing_is_a_measurement() -> None:
    # seeds 2 and 3 hold everything; on seed 4 B's All Tr. is 70 % (< 80 %): the
    # all-tracked claim is inconclusive, the other two held. The paper has five seeds.
    paper = paper_values()
    assert len(paper["fig8"]["seeds"]) >= 5
    good = [
        _record("A", 1, 10, 10, 0, B=3, C=2),
        _record("B", 2, 9, 9, 0, A=0, C=0),
        _record("C", 3, 8, 8, 0, A=0, B=0),
    ]
    weak = [good[0], _record("B", 2, 7, 7, 0, A=0, C=0), good[2]]
    runs = {2: _judged(good, 40.0), 3: _judged(good, 50.0), 4: _judged(weak, 60.0)}
    res = summarise(paper, runs)
    verdicts = dict(res.verdicts())
    sentence = {c["key"]: c["sentence"] for c in _claim_specs(paper)}
    assert verdicts[sentence["all_tracked_through_occlusions"]] is Verdict.INCONCLUSIVE
    assert verdicts[sentence["a_correctly_tracked"]] is Verdict.HELD
    assert len(verdicts) == 3  # timing is not a claim
    # the timing is the mean (40 + 50 + 60) / 3 = 50 ms with its range, beside the paper's
    assert res.data["timing"]["ms_per_frame"] == pytest.approx(50.0)
    assert (res.data["timing"]["ms_per_frame_min"], res.data["timing"]["ms_per_frame_max"]) == (
        40.0,
        60.0,
    )
    assert "50.0 ms (40.0-60.0 over the seeds" in res.markdown
    # the same runs all failing B: failed, not inconclusive
    res = summarise(paper, {2: _judged(weak, 40.0), 3: _judged(weak, 40.0)})
    assert dict(res.verdicts())[sentence["all_tracked_through_occlusions"]] is Verdict.FAILED


def _claim_specs(paper: dict[str, Any]) -> list[dict[str, Any]]:
    return [{"key": k, **v} for k, v in paper["claims"].items()]
