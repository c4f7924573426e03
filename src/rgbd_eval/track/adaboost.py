"""Discrete AdaBoost with decision stumps (Freund and Schapire 1997; seed 004 ref. [1]).

Seed 004, section 5 builds its occlusion classifier with "the AdaBoost algorithm [1]" from
thermal and colour features. This is the discrete version as Viola and Jones use it for
feature selection: each round picks the one stump (feature, threshold, polarity) with the
lowest weighted error ``e``, gives it the vote ``alpha = 1/2 ln((1 - e) / e)``, and
re-weights the samples by ``exp(-alpha y h(x))``. The strong classifier is the sign of
``sum alpha h(x)``. A stump says ``+1`` when ``polarity * (x[feature] - threshold) > 0``.

The stump search sorts each feature once; for every split between two distinct sorted
values the weighted error of "``+1`` above" is ``W+ below + W- above`` (cumulative sums),
and of "``+1`` below" its complement, so a round costs ``O(n d)``. Ties in error are broken
by the lowest feature index, then the lowest threshold (numpy's ``argmin``), so training is
a pure function of the data. scikit-learn is not a dependency of this project and its
``AdaBoostClassifier`` (SAMME) would add a large package for ~60 lines of numpy.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from rgbd_eval import exact

F64 = NDArray[np.float64]

#: Errors are clamped to [_EPS, 1 - _EPS] so a perfect stump gets a finite vote.
_EPS = 1e-10


@dataclass(frozen=True)
class Stump:
    """``h(x) = +1 if polarity * (x[feature] - threshold) > 0 else -1``, with vote ``alpha``."""

    feature: int
    threshold: float
    polarity: int
    alpha: float


@dataclass(frozen=True)
class BoostedStumps:
    """A strong classifier: the sign of the alpha-weighted stump votes."""

    feature_names: tuple[str, ...]
    stumps: tuple[Stump, ...]

    def __post_init__(self) -> None:
        for s in self.stumps:
            if not 0 <= s.feature < len(self.feature_names):
                raise ValueError(
                    f"stump feature {s.feature} must index one of "
                    f"{len(self.feature_names)} features"
                )
            if s.polarity not in (-1, 1):
                raise ValueError(f"stump polarity {s.polarity} must be -1 or +1")

    def score(self, x: F64) -> F64:
        """``sum alpha h(x)`` per row of ``x`` (``(n, d)``), or of one ``(d,)`` vector."""
        x2 = np.atleast_2d(np.asarray(x, dtype=np.float64))
        if x2.shape[1] != len(self.feature_names):
            raise ValueError(
                f"features have {x2.shape[1]} columns, the classifier {len(self.feature_names)}"
            )
        total = np.zeros(x2.shape[0])
        for s in self.stumps:
            total += s.alpha * np.where(s.polarity * (x2[:, s.feature] - s.threshold) > 0, 1, -1)
        return total

    def predict(self, x: F64) -> NDArray[np.int64]:
        """``+1`` / ``-1`` per row (a zero score counts as ``-1``)."""
        return np.where(self.score(x) > 0, 1, -1).astype(np.int64)

    def to_dict(self) -> dict[str, Any]:
        return {
            "feature_names": list(self.feature_names),
            "stumps": [
                {
                    "feature": self.feature_names[s.feature],
                    "threshold": s.threshold,
                    "polarity": s.polarity,
                    "alpha": s.alpha,
                }
                for s in self.stumps
            ],
        }

    @staticmethod
    def from_dict(data: Mapping[str, Any]) -> BoostedStumps:
        """Inverse of :meth:`to_dict`; ``KeyError``/``ValueError``/``TypeError`` on bad data."""
        names = tuple(str(n) for n in data["feature_names"])
        index = {n: i for i, n in enumerate(names)}
        stumps = []
        for s in data["stumps"]:
            name = str(s["feature"])
            if name not in index:
                raise ValueError(f"stump feature {name!r} is not one of {list(names)}")
            stumps.append(
                Stump(index[name], float(s["threshold"]), int(s["polarity"]), float(s["alpha"]))
            )
        return BoostedStumps(names, tuple(stumps))


def best_stump(
    x: F64, y: NDArray[np.int64], w: F64, order: NDArray[np.int64], features: Sequence[int]
) -> tuple[int, float, int, float]:
    """The stump of least weighted error over ``features``: (feature, threshold, polarity, error).

    ``order`` is ``argsort(x, axis=0)`` (computed once). Thresholds are midpoints between
    distinct neighbouring values, plus one below the smallest (a constant stump).
    """
    best: tuple[int, float, int, float] | None = None
    wp = np.where(y > 0, w, 0.0)
    wn = np.where(y > 0, 0.0, w)
    total_p, total_n = float(wp.sum()), float(wn.sum())
    for j in features:
        idx = order[:, j]
        v = x[idx, j]
        # split k: samples idx[:k] below, idx[k:] above (k = 0 .. n)
        below_p = np.concatenate([[0.0], np.cumsum(wp[idx])])
        below_n = np.concatenate([[0.0], np.cumsum(wn[idx])])
        err_up = below_p + (total_n - below_n)  # +1 above the threshold
        err_down = (total_p + total_n) - err_up  # +1 below
        valid = np.ones(len(v) + 1, dtype=bool)
        valid[1:-1] = v[1:] > v[:-1]  # only between distinct values
        valid[-1] = False  # "all below" equals "all above" with the other polarity
        e_up = np.where(valid, err_up, np.inf)
        e_down = np.where(valid, err_down, np.inf)
        k_up, k_down = int(np.argmin(e_up)), int(np.argmin(e_down))
        for k, err, pol in ((k_up, e_up[k_up], 1), (k_down, e_down[k_down], -1)):
            if best is not None and err >= best[3]:
                continue
            thr = float(v[0] - 1.0) if k == 0 else float((v[k - 1] + v[k]) / 2.0)
            best = (int(j), thr, pol, float(err))
    if best is None:
        raise ValueError("no feature to choose a stump from")
    return best


def train(
    x: F64,
    y: NDArray[np.int64],
    feature_names: Sequence[str],
    rounds: int,
    features: Sequence[int] | None = None,
) -> BoostedStumps:
    """Discrete AdaBoost for ``rounds`` rounds on ``x`` (``(n, d)``) and labels ``y`` in {-1, +1}.

    ``features`` restricts the stumps to those columns (a feature group). Starts from equal
    weights per class (Viola and Jones: ``1/2m`` and ``1/2l``). Stops early when the best
    stump is no better than chance (``e >= 1/2``).
    """
    x = np.asarray(x, dtype=np.float64)
    y = np.asarray(y, dtype=np.int64)
    if x.ndim != 2 or x.shape[0] != y.shape[0] or x.shape[1] != len(feature_names):
        raise ValueError(
            f"x {x.shape}, y {y.shape} and {len(feature_names)} feature names do not agree"
        )
    if not np.all(np.isin(y, (-1, 1))):
        raise ValueError("labels must be -1 or +1")
    n_pos, n_neg = int((y > 0).sum()), int((y < 0).sum())
    if n_pos == 0 or n_neg == 0:
        raise ValueError(f"need both classes, got {n_pos} positive and {n_neg} negative samples")
    if rounds < 1:
        raise ValueError(f"rounds={rounds} must be at least 1")
    if not np.all(np.isfinite(x)):
        raise ValueError("features must be finite")
    cols = list(range(x.shape[1])) if features is None else sorted(set(features))
    w = np.where(y > 0, 0.5 / n_pos, 0.5 / n_neg)
    order = np.argsort(x, axis=0, kind="stable").astype(np.int64)
    stumps: list[Stump] = []
    for _ in range(rounds):
        j, thr, pol, err = best_stump(x, y, w, order, cols)
        if err >= 0.5:
            break
        e = min(max(err, _EPS), 1.0 - _EPS)
        alpha = 0.5 * exact.log((1.0 - e) / e)
        h = np.where(pol * (x[:, j] - thr) > 0, 1, -1)
        w = w * exact.exp(np.asarray(-alpha * y * h, dtype=np.float64))
        w = w / w.sum()
        stumps.append(Stump(j, thr, pol, alpha))
    return BoostedStumps(tuple(feature_names), tuple(stumps))
