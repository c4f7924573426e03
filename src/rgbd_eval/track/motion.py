"""The constant-velocity people motion model and the Kinect measurement noise (seed 000, 6.1).

State ``x = (x, y, vx, vy)`` in the world ground plane (6.1); measurement
``z = (x, y)`` of the detection's theoretical centroid (6.2).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]

#: Measurement matrix of (6.7): the position components of the state.
H = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]])


def transition_matrix(dt: float) -> Array:
    """``F`` of (6.4) for a time step ``dt`` in seconds."""
    return np.array(
        [[1.0, 0.0, dt, 0.0], [0.0, 1.0, 0.0, dt], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
    )


def process_noise(dt: float, acceleration_variance: float) -> Array:
    """``Q = G G^T sigma_a^2`` of (6.6): white acceleration, equal on both axes."""
    if acceleration_variance < 0:
        raise ValueError(f"acceleration_variance={acceleration_variance} must be >= 0")
    G = np.array([[dt * dt / 2, 0.0], [0.0, dt * dt / 2], [dt, 0.0], [0.0, dt]])
    return np.asarray((G @ G.T) * acceleration_variance, dtype=np.float64)


def measurement_variance(
    voxel_size: float, distance: Array | float, depth_noise_coefficient: float
) -> Array:
    """Per-axis variance ``sigma_v^2 + sigma_d^2`` of (6.7).

    ``sigma_v^2 = voxel^2 / 12`` is the voxel grid's uniform quantisation (6.8);
    ``sigma_d = k d^2`` is the Kinect depth error growing with the squared
    distance (Figure 6.1).
    """
    d = np.asarray(distance, dtype=np.float64)
    sigma_d = depth_noise_coefficient * d * d
    return np.asarray(voxel_size * voxel_size / 12.0 + sigma_d * sigma_d, dtype=np.float64)


def apply_transition(X: Array, dt: float) -> Array:
    """The process function on sigma points ``(..., n, 4)``: ``X F^T``."""
    out = X.copy()
    out[..., 0] += dt * X[..., 2]
    out[..., 1] += dt * X[..., 3]
    return out


def apply_measurement(X: Array) -> Array:
    """The measurement function on sigma points ``(..., n, 4)``: ``X H^T``."""
    return X[..., :2]
