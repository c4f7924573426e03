"""Unscented Kalman filter maths as pure functions (seed 000, 6.5.2).

Every function accepts a batch: ``x`` is ``(..., n)`` and ``P`` is ``(..., n, n)``,
so all tracks of a frame are predicted or updated in one call. Sigma points use
the scaled unscented transform (Julier 2002; van der Merwe 2004) with parameters
``alpha, beta, kappa``; the default ``alpha=1, beta=0, kappa=3-n`` is Julier and
Uhlmann's original choice for Gaussian priors. Names follow filterpy.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]
#: A process or measurement function acting on sigma points ``(..., 2n+1, n)``.
SigmaFunction = Callable[[Array], Array]


@dataclass(frozen=True)
class SigmaWeights:
    """Weights of the ``2n+1`` sigma points and the spread factor ``n + lambda``."""

    n: int
    Wm: Array
    Wc: Array
    scale: float


def sigma_weights(
    n: int, alpha: float = 1.0, beta: float = 0.0, kappa: float | None = None
) -> SigmaWeights:
    """Weights of the scaled unscented transform for state dimension ``n``."""
    if n < 1:
        raise ValueError(f"state dimension n={n} must be >= 1")
    if not alpha > 0:
        raise ValueError(f"alpha={alpha} must be > 0")
    k = 3.0 - n if kappa is None else kappa
    lam = alpha * alpha * (n + k) - n
    scale = n + lam
    if not scale > 0:
        raise ValueError(f"n + lambda = {scale} must be > 0 (n={n}, alpha={alpha}, kappa={k})")
    Wm = np.full(2 * n + 1, 0.5 / scale)
    Wc = Wm.copy()
    Wm[0] = lam / scale
    Wc[0] = lam / scale + (1.0 - alpha * alpha + beta)
    return SigmaWeights(n, Wm, Wc, scale)


def sigma_points(x: Array, P: Array, w: SigmaWeights) -> Array:
    """The ``2n+1`` sigma points ``(..., 2n+1, n)`` of ``N(x, P)``."""
    L = np.linalg.cholesky(w.scale * P)  # lower: P*scale = L L^T, columns are the offsets
    offsets = np.swapaxes(L, -1, -2)
    xc = x[..., None, :]
    return np.concatenate([xc, xc + offsets, xc - offsets], axis=-2)


def unscented_transform(Y: Array, w: SigmaWeights) -> tuple[Array, Array]:
    """Mean ``(..., m)`` and covariance ``(..., m, m)`` of transformed sigma points ``Y``."""
    y = w.Wm @ Y
    dY = Y - y[..., None, :]
    return y, _weighted_outer(dY, dY, w.Wc)


def predict(
    x: Array, P: Array, fx: SigmaFunction, Q: Array, w: SigmaWeights
) -> tuple[Array, Array]:
    """Prior ``(x, P)`` after the process ``fx`` with additive noise ``Q``."""
    X = sigma_points(x, P, w)
    x_prior, P_prior = unscented_transform(fx(X), w)
    return x_prior, _symmetric(P_prior + Q)


def measurement_prediction(
    x: Array, P: Array, hx: SigmaFunction, w: SigmaWeights
) -> tuple[Array, Array, Array]:
    """Predicted measurement ``z_hat``, its covariance without noise ``Pzz`` and ``Pxz``."""
    X = sigma_points(x, P, w)
    Z = hx(X)
    z_hat, Pzz = unscented_transform(Z, w)
    dX = X - x[..., None, :]
    dZ = Z - z_hat[..., None, :]
    return z_hat, Pzz, _weighted_outer(dX, dZ, w.Wc)


def update(
    x: Array, P: Array, z: Array, hx: SigmaFunction, R: Array, w: SigmaWeights
) -> tuple[Array, Array]:
    """Posterior ``(x, P)`` given measurement ``z`` with additive noise ``R``."""
    z_hat, Pzz, Pxz = measurement_prediction(x, P, hx, w)
    return correct(x, P, z, z_hat, Pzz, Pxz, R)


def correct(
    x: Array, P: Array, z: Array, z_hat: Array, Pzz: Array, Pxz: Array, R: Array
) -> tuple[Array, Array]:
    """Posterior from a :func:`measurement_prediction` already made (``S = Pzz + R``)."""
    S = Pzz + R
    # K = Pxz S^-1, solved as S^T K^T = Pxz^T (S is symmetric)
    K = np.swapaxes(np.linalg.solve(S, np.swapaxes(Pxz, -1, -2)), -1, -2)
    y = z - z_hat
    x_post = x + np.einsum("...ij,...j->...i", K, y)
    P_post = P - K @ S @ np.swapaxes(K, -1, -2)
    return x_post, _symmetric(P_post)


def _weighted_outer(dA: Array, dB: Array, weights: Array) -> Array:
    """``sum_k weights[k] dA[..., k, :]^T dB[..., k, :]`` as one (batched) matrix product."""
    return np.asarray((np.swapaxes(dA, -1, -2) * weights) @ dB, dtype=np.float64)


def _symmetric(P: Array) -> Array:
    return 0.5 * (P + np.swapaxes(P, -1, -2))
