"""Verdicts on a paper's claims: held, failed, or inconclusive over several runs (issue 31).

A claim judged on one run says as much about that run's people, paths and noise as about
the method. Judged on several runs (scenario seeds that draw other people and noise), a
claim is *held* when it holds on every run, *failed* when it fails on every run, and
*inconclusive* when the runs disagree: a verdict that flips with the seed is never held.
A single run gives held or failed, and says that it is one run.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any


class Verdict(enum.Enum):
    """What ``reproduce`` says of one claim."""

    HELD = "held"
    FAILED = "failed"
    INCONCLUSIVE = "inconclusive"

    @staticmethod
    def of(held: bool) -> Verdict:
        """The verdict of one run."""
        return Verdict.HELD if held else Verdict.FAILED


def over_runs(held: Sequence[bool]) -> Verdict:
    """Held on every run, failed on every run, else inconclusive (ValueError: no run)."""
    if not held:
        raise ValueError("a verdict needs at least one run")
    if all(held):
        return Verdict.HELD
    if not any(held):
        return Verdict.FAILED
    return Verdict.INCONCLUSIVE


@dataclass(frozen=True)
class Spread:
    """A measured value over runs: mean, least and greatest (NaN runs left out)."""

    mean: float
    low: float
    high: float
    runs: int

    @staticmethod
    def of(values: Sequence[float]) -> Spread:
        """The spread of ``values`` (all NaN or none: NaN throughout, ``runs`` 0)."""
        kept = [float(v) for v in values if not math.isnan(v)]
        if not kept:
            return Spread(math.nan, math.nan, math.nan, 0)
        return Spread(math.fsum(kept) / len(kept), min(kept), max(kept), len(kept))

    def text(self, fmt: str = ".3g", unit: str = "") -> str:
        """``mean [low, high] unit over n runs``; one run: the value alone."""
        if self.runs == 0:
            return "-"
        if self.runs == 1:
            return f"{self.mean:{fmt}}{unit} (one run)"
        return (
            f"{self.mean:{fmt}}{unit} [{self.low:{fmt}}, {self.high:{fmt}}] over {self.runs} runs"
        )


def over_seeds(
    seeds: Sequence[Any],
    held: Mapping[Any, bool | None],
    measured: Mapping[Any, Mapping[str, float]],
) -> tuple[Verdict, dict[str, Spread]]:
    """One claim over ``seeds``: its verdict and the spread of each value it measured.

    ``held`` and ``measured`` are by seed. A seed on which the claim was not judged
    (absent from ``held``, or None: a row or a variant missing there) makes it
    inconclusive: a claim is held or failed only when judged the same way on every seed.
    """
    if not seeds:
        raise ValueError("a verdict needs at least one seed")
    judged = [held.get(s) for s in seeds]
    verdict = (
        Verdict.INCONCLUSIVE
        if any(h is None for h in judged)
        else over_runs([bool(h) for h in judged])
    )
    names = dict.fromkeys(n for s in seeds for n in measured.get(s, {}))
    spreads = {n: Spread.of([measured.get(s, {}).get(n, math.nan) for s in seeds]) for n in names}
    return verdict, spreads


def spreads_json(
    spreads: Mapping[str, Spread], per_run: Mapping[Any, Mapping[str, float]]
) -> dict[str, dict[str, Any]]:
    """A claim's measured values for a report's JSON: per name its mean, least and greatest
    over the runs and each run's value (None where a run did not measure it)."""
    return {
        name: {
            "mean": sp.mean,
            "min": sp.low,
            "max": sp.high,
            "per_seed": {str(run): values.get(name) for run, values in per_run.items()},
        }
        for name, sp in spreads.items()
    }


def tally(verdicts: Sequence[Verdict]) -> str:
    """``2 held, 1 failed, 1 inconclusive of 4``."""
    n = {v: sum(1 for x in verdicts if x is v) for v in Verdict}
    return (
        f"{n[Verdict.HELD]} held, {n[Verdict.FAILED]} failed, "
        f"{n[Verdict.INCONCLUSIVE]} inconclusive of {len(verdicts)}"
    )
