"""Global nearest neighbour data association (seed 000, 6.3 and 6.5.2).

Step 1 gates squared Mahalanobis distances with a chi-square quantile and solves
the assignment minimising their sum with the Hungarian (Kuhn-Munkres) method.
Step 2 pairs the leftovers by classifier score above a threshold, maximising the
summed scores.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import linear_sum_assignment
from scipy.special import gammaincinv

Array = NDArray[np.float64]
Pairs = list[tuple[int, int]]


def chi_square_gate(probability: float, dof: int = 2) -> float:
    """Gate ``G`` with ``P(d^2 < G) = probability`` for ``d^2 ~ chi^2(dof)`` (6.5.2)."""
    if not 0.0 < probability < 1.0:
        raise ValueError(f"gate probability={probability} must be in (0, 1)")
    if dof < 1:
        raise ValueError(f"dof={dof} must be >= 1")
    # scipy.stats.chi2.ppf's own formula, without importing scipy.stats (0.4 s at start-up).
    return float(2.0 * gammaincinv(dof / 2.0, probability))


def mahalanobis_sq(z_pred: Array, Pzz: Array, z: Array, r: Array) -> Array:
    """Squared Mahalanobis distances ``(T, D)`` of (6.10) for 2D measurements.

    ``z_pred (T, 2)`` and ``Pzz (T, 2, 2)`` are each track's predicted measurement
    and its covariance before noise; ``z (D, 2)`` the detections and ``r (D,)`` their
    isotropic measurement variances, so ``S(i, j) = Pzz(i) + r(j) I`` (6.7).
    """
    y = z[None, :, :] - z_pred[:, None, :]
    a = Pzz[:, None, 0, 0] + r[None, :]
    b = Pzz[:, None, 0, 1]
    d = Pzz[:, None, 1, 1] + r[None, :]
    det = a * d - b * b
    y0, y1 = y[..., 0], y[..., 1]
    return np.asarray((d * y0 * y0 - 2.0 * b * y0 * y1 + a * y1 * y1) / det, dtype=np.float64)


def gnn_assign(d2: Array, gate: float) -> Pairs:
    """Pairs ``(track, detection)`` minimising summed ``d2`` among those below ``gate``.

    Gated-out entries get a cost larger than any sum of valid ones (6.5.2, step 2),
    so the solution first keeps as many valid pairs as possible.
    """
    if d2.size == 0:
        return []
    valid = d2 < gate
    if not valid.any():
        return []
    big = gate * (min(d2.shape) + 1) + 1.0
    cost = np.where(valid, d2, big)
    rows, cols = linear_sum_assignment(cost)
    return [(int(i), int(j)) for i, j in zip(rows, cols, strict=True) if valid[i, j]]


def score_assign(scores: Array, min_score: float) -> Pairs:
    """Pairs ``(track, detection)`` maximising summed ``scores`` among those above ``min_score``."""
    if scores.size == 0:
        return []
    valid = scores > min_score
    if not valid.any():
        return []
    top = float(np.abs(scores[valid]).max())
    penalty = -(top + 1.0) * (min(scores.shape) + 1)
    gain = np.where(valid, scores, penalty)
    rows, cols = linear_sum_assignment(gain, maximize=True)
    return [(int(i), int(j)) for i, j in zip(rows, cols, strict=True) if valid[i, j]]
