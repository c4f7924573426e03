"""Threshold curves in one pass: the scores at several confidence thresholds, without re-running.

A tracker's output that carries a confidence per track and frame
(:attr:`rgbd_eval.types.TrackOutput.confidence`) is scored again at each threshold
``c``, keeping the track instances of confidence ``>= c`` (those without a confidence are
always kept), exactly as ``rgbd-eval score`` scores a file holding only those rows. The
thresholds are the confidences present in the scored tracks: all of them when there are
at most ``points`` (default :data:`DEFAULT_POINTS`, ``--curve-points``), else ``points``
quantiles of the instances' confidences (each a value present, the lowest always among
them, which keeps every track: the report's own scores). Per metric the best threshold is
the one of highest MOTA, HOTA and IDF1, of fewest FP and FN (the lowest threshold on ties),
over all sequences summed.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from rgbd_eval.config import EvaluationConfig
from rgbd_eval.metrics.clear import evaluate_sequence
from rgbd_eval.metrics.counts import Counts, Summary, summarize, total
from rgbd_eval.metrics.selection import is_scored_track
from rgbd_eval.types import GroundTruthObject, TrackOutput

#: Thresholds of a curve at most, by default.
DEFAULT_POINTS = 20
#: The metrics a curve shows, and whether higher is better.
CURVE_METRICS: tuple[tuple[str, bool], ...] = (
    ("mota", True),
    ("hota", True),
    ("idf1", True),
    ("fp", False),
    ("fn", False),
)

Frames = Sequence[Sequence[TrackOutput]]


def confidences(track_frames: Sequence[Frames]) -> list[float]:
    """The confidences of every scored track instance (those that have one), sorted."""
    values = [
        t.confidence
        for frames in track_frames
        for frame in frames
        for t in frame
        if t.confidence is not None and math.isfinite(t.confidence) and is_scored_track(t)
    ]
    return sorted(values)


def thresholds(values: Sequence[float], points: int = DEFAULT_POINTS) -> list[float]:
    """The thresholds to score at (see the module docstring); ``values`` sorted."""
    if points < 2:
        raise ValueError(f"points={points} must be at least 2")
    unique = sorted(set(values))
    if len(unique) <= points:
        return unique
    n = len(values)
    picked = [values[max(0, math.ceil(round(k / (points - 1) * n, 9)) - 1)] for k in range(points)]
    return sorted(set(picked))


def keep_above(frames: Frames, threshold: float) -> list[list[TrackOutput]]:
    """The track instances of confidence ``>= threshold`` (all those without a finite one)."""
    return [[t for t in frame if _kept(t.confidence, threshold)] for frame in frames]


def _kept(confidence: float | None, threshold: float) -> bool:
    return confidence is None or not math.isfinite(confidence) or confidence >= threshold


@dataclass(frozen=True)
class CurvePoint:
    """The scores at one threshold: per sequence and summed."""

    threshold: float
    sequences: tuple[Counts, ...]
    overall: Counts

    def summary(self) -> Summary:
        return summarize(self.overall)


@dataclass(frozen=True)
class Curve:
    """Scores against the confidence threshold (or why there is no curve)."""

    points: tuple[CurvePoint, ...]
    best: dict[str, float | None]
    reason: str = ""


def best_thresholds(points: Sequence[CurvePoint]) -> dict[str, float | None]:
    """Per :data:`CURVE_METRICS` metric, the threshold of its best value (lowest on ties)."""
    out: dict[str, float | None] = {}
    for metric, higher in CURVE_METRICS:
        best: tuple[float, float] | None = None
        for p in points:
            value = p.summary()[metric]
            if value is None:
                continue
            key = float(value) if higher else -float(value)
            if best is None or key > best[0]:
                best = (key, p.threshold)
        out[metric] = None if best is None else best[1]
    return out


def sweep(
    sequences: Sequence[tuple[Sequence[Sequence[GroundTruthObject]], Frames]],
    config: EvaluationConfig,
    points: int = DEFAULT_POINTS,
) -> Curve:
    """Score ``(ground truth, tracks)`` of every sequence at each threshold."""
    values = confidences([tracks for _, tracks in sequences])
    if not values:
        return Curve((), {}, "the tracker output carries no confidences")
    chosen = thresholds(values, points)
    if len(chosen) < 2:
        return Curve((), {}, f"every track has the same confidence ({chosen[0]:g})")
    out = []
    for c in chosen:
        counts = tuple(
            evaluate_sequence(gt, keep_above(tracks, c), config).counts for gt, tracks in sequences
        )
        out.append(CurvePoint(float(c), counts, total(counts)))
    return Curve(tuple(out), best_thresholds(out))
