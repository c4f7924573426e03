"""Linear Kalman filter maths as pure functions (filterpy names), batched like :mod:`.ukf`."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]


def predict(x: Array, P: Array, F: Array, Q: Array) -> tuple[Array, Array]:
    """Prior ``x = F x``, ``P = F P F^T + Q``."""
    x_prior = np.einsum("...ij,...j->...i", F, x)
    P_prior = F @ P @ np.swapaxes(F, -1, -2) + Q
    return x_prior, P_prior


def update(x: Array, P: Array, z: Array, H: Array, R: Array) -> tuple[Array, Array]:
    """Posterior after measurement ``z = H x + v``, ``v ~ N(0, R)`` (Joseph form)."""
    Ht = np.swapaxes(H, -1, -2)
    S = H @ P @ Ht + R
    K = np.swapaxes(np.linalg.solve(S, np.swapaxes(P @ Ht, -1, -2)), -1, -2)
    y = z - np.einsum("...ij,...j->...i", H, x)
    x_post = x + np.einsum("...ij,...j->...i", K, y)
    I_KH = np.eye(P.shape[-1]) - K @ H
    P_post = I_KH @ P @ np.swapaxes(I_KH, -1, -2) + K @ R @ np.swapaxes(K, -1, -2)
    return x_post, P_post
