"""Verdicts over runs (issue 31): a claim that flips with the seed is never held."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from rgbd_eval.plugins import ReproduceResult
from rgbd_eval.verdicts import Spread, Verdict, over_runs, spreads_json, tally


def test_held_only_when_every_run_holds() -> None:
    assert over_runs([True] * 5) is Verdict.HELD
    assert over_runs([False] * 5) is Verdict.FAILED
    # cielniak2010's colour claim held on tracker seeds 0-2 and failed on 3-7
    assert over_runs([True, True, True, False, False, False, False, False]) is (
        Verdict.INCONCLUSIVE
    )
    assert over_runs([True]) is Verdict.HELD
    with pytest.raises(ValueError, match="at least one run"):
        over_runs([])


@given(st.lists(st.booleans(), min_size=1, max_size=12))
def test_a_verdict_is_held_exactly_when_no_run_fails(runs: list[bool]) -> None:
    v = over_runs(runs)
    assert (v is Verdict.HELD) == all(runs)
    assert (v is Verdict.FAILED) == (not any(runs))
    # one run that disagrees with another makes any claim inconclusive
    assert over_runs([*runs, not runs[0]]) is Verdict.INCONCLUSIVE


def test_spread_mean_min_max_and_text() -> None:
    # (5.7 + 8.4 + 7.3) / 3 = 7.133...
    s = Spread.of([5.7, 8.4, 7.3, math.nan])
    assert s.runs == 3 and s.low == 5.7 and s.high == 8.4
    assert s.mean == pytest.approx(7.1333333)
    assert s.text(".2f") == "7.13 [5.70, 8.40] over 3 runs"
    assert Spread.of([2.0]).text(".1f", " %") == "2.0 % (one run)"
    assert Spread.of([]).text() == "-" and Spread.of([math.nan]).runs == 0


def test_tally_and_a_plugins_bool_claims_read_as_one_run() -> None:
    r = ReproduceResult(
        "", {}, (("a", True), ("b", False), ("c", Verdict.INCONCLUSIVE), ("d", Verdict.HELD))
    )
    verdicts = [v for _, v in r.verdicts()]
    assert verdicts == [Verdict.HELD, Verdict.FAILED, Verdict.INCONCLUSIVE, Verdict.HELD]
    assert tally(verdicts) == "2 held, 1 failed, 1 inconclusive of 4"


def test_spreads_json_gives_mean_least_greatest_and_each_run() -> None:
    spreads = {"mota": Spread.of([0.8, 0.9]), "gap": Spread.of([0.1])}
    per_run = {1: {"mota": 0.8, "gap": 0.1}, 2: {"mota": 0.9}}
    out = spreads_json(spreads, per_run)
    assert out["mota"]["min"] == 0.8 and out["mota"]["max"] == 0.9
    assert out["mota"]["mean"] == pytest.approx(0.85)
    assert out["mota"]["per_seed"] == {"1": 0.8, "2": 0.9}
    assert out["gap"]["per_seed"] == {"1": 0.1, "2": None}  # seed 2 did not measure it


def test_over_seeds_judges_a_claim_on_every_seed_or_calls_it_inconclusive() -> None:
    from rgbd_eval.verdicts import over_seeds

    # Held on seeds 1 and 2, with gains of 3 and 5 points: held, mean 4 [3, 5].
    verdict, spreads = over_seeds([1, 2], {1: True, 2: True}, {1: {"gain": 3.0}, 2: {"gain": 5.0}})
    assert verdict is Verdict.HELD
    assert (spreads["gain"].mean, spreads["gain"].low, spreads["gain"].high) == (4.0, 3.0, 5.0)
    # Failed on both: failed.
    assert over_seeds([1, 2], {1: False, 2: False}, {})[0] is Verdict.FAILED
    # Held on 1, not judged on 2 (its row missing, or None): inconclusive, not held; the
    # spread is over the one seed that measured it.
    verdict, spreads = over_seeds([1, 2], {1: True}, {1: {"gain": 3.0}})
    assert verdict is Verdict.INCONCLUSIVE and spreads["gain"].runs == 1
    assert over_seeds([1, 2], {1: True, 2: None}, {})[0] is Verdict.INCONCLUSIVE
    # Flips: inconclusive.
    assert over_seeds([1, 2], {1: True, 2: False}, {})[0] is Verdict.INCONCLUSIVE


def test_claims_over_seeds_groups_each_claim_by_key_in_first_seen_order() -> None:
    from dataclasses import dataclass, field

    from rgbd_eval.verdicts import claims_over_seeds

    @dataclass(frozen=True)
    class J:
        key: str
        held: bool | None
        measured: dict[str, float] = field(default_factory=dict)

    per_seed = {
        1: [J("a", True, {"gain": 2.0}), J("b", False)],
        # seed 2 lists them the other way round and judges "c" too
        2: [J("b", False), J("a", True, {"gain": 4.0}), J("c", True)],
        3: [J("a", False, {"gain": -1.0}), J("b", False), J("c", None)],
    }
    got = claims_over_seeds(per_seed, lambda j: j.key)
    assert [c.key for c in got] == ["a", "b", "c"]
    a, b, c = got
    # a: held on 1 and 2, failed on 3 -> inconclusive; gain mean (2 + 4 - 1) / 3 = 5/3
    assert a.verdict is Verdict.INCONCLUSIVE and a.spreads["gain"].mean == pytest.approx(5 / 3)
    assert a.judged is per_seed[1][0] and list(a.per_seed) == [1, 2, 3]
    assert b.verdict is Verdict.FAILED  # failed on every seed
    # c: absent on seed 1, not judged on 3: inconclusive, never held
    assert c.verdict is Verdict.INCONCLUSIVE and list(c.per_seed) == [2, 3]
    with pytest.raises(ValueError, match="at least one seed"):
        claims_over_seeds({}, lambda j: "x")
