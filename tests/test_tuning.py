"""The choice rule of the tuning tools (issue 31): fewest errors, middle of the widest best
interval; hand-computed."""

from __future__ import annotations

import pytest

from rgbd_eval.tuning import Choice, errors_at, fewest_errors


def test_fewest_errors_keeps_at_or_above_and_takes_the_widest_best_interval() -> None:
    people, objects = [3.0, 5.5, 6.0], [1.0, 2.0, 4.0]
    # kept when >= t; errors = people below t + objects at or above t, per cut:
    #   t=1: 0+3=3  t=2: 0+2=2  t=3: 0+1=1  t=4: 1+1=2  t=5.5: 1+0=1  t=6: 2  t=7: 3
    # best 1 on (2, 3] (width 1) and (4, 5.5] (width 1.5): the wider, middle 4.75.
    # (first-to-last would span (2, 5.5] through t=4's two errors: 3.75.)
    assert [errors_at(people, objects, t, "at_or_above") for t in (1, 2, 3, 4, 5.5, 6, 7)] == [
        3,
        2,
        1,
        2,
        1,
        2,
        3,
    ]
    assert fewest_errors(people, objects) == Choice(4.75, 4.0, 5.5, 1)


def test_fewest_errors_keeps_below_and_takes_the_first_of_equal_intervals() -> None:
    same, different = [1.0, 2.0, 5.0], [3.0, 6.0, 7.0]
    # kept when < t; errors = same at or above t + different below t, per cut:
    #   t=1: 3+0=3  t=2: 2+0=2  t=3: 1+0=1  t=5: 1+1=2  t=6: 0+1=1  t=7: 0+2=2  t=8: 0+3=3
    # best 1 on (2, 3] and (5, 6], both 1 wide: the first, middle 2.5.
    assert fewest_errors(same, different, keep="below") == Choice(2.5, 2.0, 3.0, 1)


def test_fewest_errors_starts_the_first_interval_at_the_floor() -> None:
    # every blob a person's: errors 0 for t in (0, 0.08]; above it people are lost
    assert fewest_errors([0.08, 0.1], []) == Choice(0.04, 0.0, 0.08, 0)
    # kept below t, all positives kept only above every value: (1, 1 + 1]
    assert fewest_errors([0.5, 1.0], [], keep="below") == Choice(1.5, 1.0, 2.0, 0)


def test_fewest_errors_refuses_no_values_and_values_below_the_floor() -> None:
    with pytest.raises(ValueError, match="at least one"):
        fewest_errors([], [])
    with pytest.raises(ValueError, match="below floor"):
        fewest_errors([-1.0], [2.0])
