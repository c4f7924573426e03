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
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Generic, Protocol, TypeVar


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


class Judged(Protocol):
    """One seed's judgement of a claim: held (None: not judged there), and the values it
    compared, by name."""

    @property
    def held(self) -> bool | None: ...

    @property
    def measured(self) -> Mapping[str, float]: ...


J = TypeVar("J", bound=Judged)


@dataclass(frozen=True)
class ClaimOverSeeds(Generic[J]):
    """One claim over the seeds: its verdict, each seed's judgement, the measured spreads."""

    key: str
    verdict: Verdict
    per_seed: dict[Any, J]
    spreads: dict[str, Spread]

    @property
    def judged(self) -> J:
        """The first seed's judgement (the claim's sentence and source are every seed's)."""
        return next(iter(self.per_seed.values()))


def claims_over_seeds(
    per_seed: Mapping[Any, Sequence[J]], key: Callable[[J], str]
) -> list[ClaimOverSeeds[J]]:
    """Each claim, told apart by ``key``, over the seeds (in the order they first appear):
    :func:`over_seeds`, so a claim judged on only some seeds is inconclusive."""
    if not per_seed:
        raise ValueError("a verdict needs at least one seed")
    seeds = list(per_seed)
    by_key: dict[str, dict[Any, J]] = {}
    for seed, judgements in per_seed.items():
        for j in judgements:
            by_key.setdefault(key(j), {})[seed] = j
    out = []
    for k, judged in by_key.items():
        verdict, spreads = over_seeds(
            seeds,
            {s: j.held for s, j in judged.items()},
            {s: j.measured for s, j in judged.items()},
        )
        out.append(ClaimOverSeeds(k, verdict, judged, spreads))
    return out


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
