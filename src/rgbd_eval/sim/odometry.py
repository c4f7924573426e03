"""Wheel odometry with drift: integrate noisy increments of the true motion.

Each step's true motion in the robot frame (forward, lateral, yaw) is scaled
by ``1 + scale_error`` and perturbed by Gaussian noise whose variance grows
linearly with the distance (and angle) travelled, so the error is a random
walk. A standing robot accumulates no error. Odometry starts at the true pose:
``odom`` coincides with the world frame at t = 0.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from rgbd_eval import exact
from rgbd_eval.sim.scenario import Odometry

F64 = NDArray[np.float64]


def relative_motion(p0: F64, p1: F64) -> tuple[float, float, float]:
    """(forward, lateral, dyaw) of pose p1 seen from pose p0, poses as (x, y, yaw)."""
    dx, dy = p1[0] - p0[0], p1[1] - p0[1]
    c, s = exact.cos(p0[2]), exact.sin(p0[2])
    dyaw = (p1[2] - p0[2] + math.pi) % (2.0 * math.pi) - math.pi
    return (c * dx + s * dy, -s * dx + c * dy, dyaw)


def integrate_odometry(true_poses: F64, model: Odometry, rng: np.random.Generator) -> F64:
    """Odometry poses (N, 3) for true poses (N, 3) of base_link, each (x, y, yaw)."""
    poses = np.asarray(true_poses, dtype=np.float64)
    if poses.ndim != 2 or poses.shape[1] != 3:
        raise ValueError(f"true_poses must have shape (N, 3), got {poses.shape}")
    n = len(poses)
    out = np.empty_like(poses)
    if n == 0:
        return out
    out[0] = poses[0]
    noise = exact.standard_normal(rng, (n, 3))
    rot_sigma = math.radians(model.rotation_noise_deg)
    for i in range(1, n):
        fwd, lat, dyaw = relative_motion(poses[i - 1], poses[i])
        dist = exact.hypot(fwd, lat)
        fwd *= 1.0 + model.scale_error
        lat *= 1.0 + model.scale_error
        fwd += noise[i, 0] * model.translation_noise * math.sqrt(dist)
        lat += noise[i, 1] * model.translation_noise * math.sqrt(dist)
        dyaw += noise[i, 2] * rot_sigma * math.sqrt(dist + abs(dyaw))
        x, y, yaw = out[i - 1]
        c, s = exact.cos(yaw), exact.sin(yaw)
        out[i] = (x + c * fwd - s * lat, y + s * fwd + c * lat, yaw + dyaw)
    return out
