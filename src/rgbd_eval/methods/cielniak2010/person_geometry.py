"""People stand on the floor: the height in metres that an image silhouette implies.

Our addition to seed 004 (its snippets give no size prior; its robot's camera sat at a
fixed height). The camera's pose in the world (z up, floor at z = 0) is known from the
tf chain, so the ray through a silhouette's feet meets the floor at a point ``P``, and the
ray through its top passes over ``P`` at the height the silhouette implies. A part of a
person (its legs, its upper body) fitted as a whole person implies an implausible height
or no floor point at all; :func:`height_log_prior` turns the implied height into a
log-likelihood term, zero inside the range of standing adults and falling as a Gaussian
outside it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rgbd_eval.types import CameraModel, Pose

F64 = NDArray[np.float64]


@dataclass(frozen=True)
class HeightPrior:
    """Standing heights ``[min_m, max_m]``; outside them the log-prior falls as
    ``-((excess / sigma_m)^2) / 2``; ``no_floor`` is the log-prior of a silhouette whose
    feet do not look down at the floor."""

    min_m: float = 1.4
    max_m: float = 2.05
    sigma_m: float = 0.1
    no_floor: float = -50.0

    def __post_init__(self) -> None:
        if not 0.0 < self.min_m < self.max_m:
            raise ValueError(f"heights [{self.min_m}, {self.max_m}] must be increasing and > 0")
        if self.sigma_m <= 0.0:
            raise ValueError(f"sigma_m={self.sigma_m} must be positive")


def _rays(camera: CameraModel, rotation: F64, u: F64, v: F64) -> F64:
    """World directions (N, 3) of the rays through pixels (u, v)."""
    out: F64 = camera.rays_at(u, v) @ rotation.T
    return out


def implied_heights(camera: CameraModel, pose: Pose, states: F64) -> F64:
    """Height (m) of a person standing where each state's box ``(u, v, h, ...)`` has its feet
    (``v + h/2``) and its top (``v - h/2``); NaN where the feet ray does not meet the floor."""
    R = pose.rotation_matrix()
    o = np.asarray(pose.translation, dtype=np.float64)
    u = states[:, 0]
    half = states[:, 2] / 2.0
    feet = _rays(camera, R, u, states[:, 1] + half)
    down = feet[:, 2] < -1e-9
    t = np.where(down, -o[2] / np.where(down, feet[:, 2], -1.0), np.nan)
    floor_xy = o[:2] + t[:, None] * feet[:, :2]
    top = _rays(camera, R, u, states[:, 1] - half)
    horizontal = (top[:, :2] ** 2).sum(axis=1)
    s = ((floor_xy - o[:2]) * top[:, :2]).sum(axis=1) / np.maximum(horizontal, 1e-12)
    out: F64 = o[2] + s * top[:, 2]
    return out


def height_log_prior(prior: HeightPrior, heights: F64) -> F64:
    """Log-prior of implied heights (0 inside the range; ``no_floor`` for NaN)."""
    excess = np.maximum(np.maximum(prior.min_m - heights, heights - prior.max_m), 0.0)
    out: F64 = np.where(np.isnan(heights), prior.no_floor, -0.5 * (excess / prior.sigma_m) ** 2)
    return out
