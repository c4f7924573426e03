"""Re-expressing pinto2022's appearance thresholds in an embedder's own units.

The seed's thresholds (T_lower 300, T_upper 700, T_recover 400; seed 001, eqs. 17-18) are
Euclidean distances between TriNet embeddings. Another embedder has another scale, so each
threshold is re-defined by the role Algorithm 1 and 2 give it, and read off the embedder's
distance distributions of same-person and different-person pairs:

- ``T_lower``: below it an association is admitted however far apart (Algorithm 1, line 9),
  so different people should almost never fall below it: the ``lower_quantile`` (1 %)
  quantile of different-person distances;
- ``T_upper``: at or above it an association is refused however close (line 11), so the
  same person should almost never reach it: the ``upper_quantile`` (99 %) quantile of
  same-person distances;
- ``T_recover``: an old ID is recovered below it (Algorithm 2), one decision between two
  populations: the distance with the fewest wrong decisions (same-person pairs at or above
  it + different-person pairs below it), the middle of the widest such interval
  (:func:`rgbd_eval.tuning.fewest_errors`, the project's rule for a value chosen on tuning
  data). The equal-error threshold (:func:`equal_error_threshold`) is printed beside it.

Distances are computed in a fixed order from exact operations (:mod:`rgbd_eval.exact`), so
the same embeddings give the same thresholds, bit for bit, on every CPU.

Where the distributions overlap (as TriNet's do, in the seed's values), this gives the
seed's ordering ``T_lower < T_recover < T_upper``. Where they are separated, the 1 % of
different-person distances lies above the 99 % of same-person ones and the rule gives
``T_lower > T_upper``: appearance alone decides, and both collapse to ``T_recover`` (no
distance band is left where the spatial test decides).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rgbd_eval import exact
from rgbd_eval.tuning import fewest_errors

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class Thresholds:
    """Appearance thresholds in an embedder's units."""

    t_lower: float
    t_upper: float
    t_recover: float


def pair_distances(
    embeddings: NDArray[np.floating],
    ids: NDArray[np.integer],
    frames: NDArray[np.integer],
    min_frame_gap: int,
) -> tuple[FloatArray, FloatArray]:
    """Euclidean distances of same-person pairs ``min_frame_gap`` or more frames apart, and of
    different-person pairs (any frames); summed in index order (no BLAS)."""
    e = np.asarray(embeddings, dtype=np.float64)
    sq = exact.dot(e, e)
    d2 = sq[:, None] + sq[None, :] - 2.0 * exact.matmul(e, np.ascontiguousarray(e.T))
    d = np.sqrt(np.clip(d2, 0.0, None))
    i, j = np.triu_indices(len(e), k=1)
    same = ids[i] == ids[j]
    apart = np.abs(frames[i] - frames[j]) >= min_frame_gap
    return d[i, j][same & apart], d[i, j][~same]


def equal_error_threshold(same: FloatArray, different: FloatArray) -> float:
    """The distance where P(same >= t) = P(different < t) (the smaller such t, interpolated)."""
    if same.size == 0 or different.size == 0:
        raise ValueError("need same-person and different-person distances")
    candidates = np.unique(np.concatenate([same, different]))
    miss = np.array([(same >= t).mean() for t in candidates])  # falls with t
    false_accept = np.array([(different < t).mean() for t in candidates])  # rises with t
    gap = miss - false_accept
    k = int(np.argmax(gap <= 0)) if (gap <= 0).any() else len(candidates) - 1
    if k == 0 or gap[k] == 0:
        return float(candidates[k])
    t0, t1, g0, g1 = candidates[k - 1], candidates[k], gap[k - 1], gap[k]
    return float(t0 + (t1 - t0) * g0 / (g0 - g1))


def roc_auc(same: FloatArray, different: FloatArray) -> float:
    """P(a different-person distance > a same-person distance), ties counted half."""
    both = np.concatenate([same, different])
    ranks = np.empty(both.size)
    order = np.argsort(both, kind="stable")
    ranks[order] = np.arange(1, both.size + 1)
    for value in np.unique(both):  # average ranks of ties
        tie = both == value
        ranks[tie] = ranks[tie].mean()
    r_diff = ranks[same.size :].sum()
    n_s, n_d = same.size, different.size
    return float((r_diff - n_d * (n_d + 1) / 2) / (n_s * n_d))


def calibrate(
    same: FloatArray,
    different: FloatArray,
    lower_quantile: float = 0.01,
    upper_quantile: float = 0.99,
) -> Thresholds:
    """Thresholds by the rules of the module docstring."""
    if same.size == 0 or different.size == 0:
        raise ValueError("need same-person and different-person distances")
    t_recover = fewest_errors(same.tolist(), different.tolist(), keep="below").value
    t_lower = float(np.quantile(different, lower_quantile))
    t_upper = float(np.quantile(same, upper_quantile))
    if t_lower > t_upper:
        t_lower = t_upper = t_recover
    t_lower = min(t_lower, t_recover)
    t_upper = max(t_upper, t_recover)
    return Thresholds(t_lower, t_upper, t_recover)
