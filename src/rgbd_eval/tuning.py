"""Choosing a threshold on tuning data by the project's rule (issue 31).

The rule, fixed before looking at any data: the threshold with the fewest errors, and where
a range of thresholds ties, the middle of the widest interval of thresholds with that count.
Used by the tools that choose a method's value on a tuning scene (dmtbs's smallest blob,
satake2009's colour test, pinto2022's recovery distance).

A threshold ``t`` splits measured values into kept and dropped. With ``keep="at_or_above"``
a value ``v`` is kept when ``v >= t``; with ``keep="below"``, when ``v < t``. The errors of
``t`` are the *positives* (values that should be kept) dropped plus the *negatives* (values
that should be dropped) kept. Either way the errors change only at the measured values: every
``t`` in ``(v[i-1], v[i]]`` behaves as ``v[i]``, so each candidate interval runs from the
value below (exclusive) to a measured value (inclusive); below the smallest value the
interval starts at ``floor``, and one more interval ``(v[-1], v[-1] + 1]`` stands for every
threshold above all values.
"""

from __future__ import annotations

import bisect
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

Keep = Literal["at_or_above", "below"]


@dataclass(frozen=True)
class Choice:
    """A chosen threshold: the middle of ``(low, high]``, where ``errors`` is least."""

    value: float
    low: float
    high: float
    errors: int


def errors_at(positives: Sequence[float], negatives: Sequence[float], t: float, keep: Keep) -> int:
    """Positives dropped + negatives kept at threshold ``t``."""
    if keep == "at_or_above":
        return sum(v < t for v in positives) + sum(v >= t for v in negatives)
    return sum(v >= t for v in positives) + sum(v < t for v in negatives)


def fewest_errors(
    positives: Sequence[float],
    negatives: Sequence[float],
    keep: Keep = "at_or_above",
    floor: float = 0.0,
) -> Choice:
    """The threshold with the fewest errors, the middle of the widest interval of such
    thresholds (the first of equally wide ones); ValueError without values or with a value
    below ``floor``."""
    if keep not in ("at_or_above", "below"):
        raise ValueError(f"keep={keep!r} must be 'at_or_above' or 'below'")
    values = sorted({*map(float, positives), *map(float, negatives)})
    if not values:
        raise ValueError("need at least one measured value")
    if values[0] < floor:
        raise ValueError(f"value {values[0]} lies below floor={floor}")
    cuts = [*values, values[-1] + 1.0]
    # counts by bisection on sorted values: the same integers as errors_at, in O(log n)
    pos, neg = sorted(map(float, positives)), sorted(map(float, negatives))
    errors = []
    for t in cuts:
        pos_below, neg_below = bisect.bisect_left(pos, t), bisect.bisect_left(neg, t)
        if keep == "at_or_above":
            errors.append(pos_below + len(neg) - neg_below)
        else:
            errors.append(len(pos) - pos_below + neg_below)
    best = min(errors)
    widest: tuple[float, float] | None = None
    i = 0
    while i < len(cuts):
        if errors[i] != best:
            i += 1
            continue
        j = i
        while j + 1 < len(cuts) and errors[j + 1] == best:
            j += 1
        low = cuts[i - 1] if i > 0 else floor
        if widest is None or cuts[j] - low > widest[1] - widest[0]:
            widest = (low, cuts[j])
        i = j + 1
    if widest is None:  # not reached: some cut has the least count
        raise ValueError("no interval")
    low, high = widest
    return Choice((low + high) / 2.0, low, high, best)
