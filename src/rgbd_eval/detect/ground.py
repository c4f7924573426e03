"""The ground plane across frames (seed 000, 5.1, 5.4.1, 5.4.2).

The plane is initialised once (three floor points or pixels, a given plane, the
world frame's floor z = 0 seen from the first frame's camera pose, or
automatically by RANSAC over the lower part of the cloud, keeping the plane
whose normal agrees with gravity), then refined every frame by a least-squares
fit to the points within one voxel of it, and kept unchanged when too few floor
points are seen. Planes live in the depth camera's optical frame.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from rgbd_eval.detect.plane import (
    fit_plane_least_squares,
    normalise_plane,
    plane_from_points,
    ransac_ground_plane,
    signed_heights,
)
from rgbd_eval.types import Pose

FloatArray = NDArray[np.float64]

#: Passes of the per-frame refinement: the second pass re-selects the inliers
#: around the first refit, so a pitch change of a few degrees is followed at once.
REFINE_PASSES = 2
#: RANSAC hypotheses of the automatic initialisation.
RANSAC_ITERATIONS = 256


class GroundMode(enum.Enum):
    """How the detector finds the ground plane first (seed 000, 5.1, 5.4.1)."""

    AUTO = "auto"
    POINTS = "points"
    PLANE = "plane"
    #: The world frame's z = 0 (the floor of the recording's odometry or map frame), put in
    #: the camera frame by the first frame's camera pose: the floor is known, as the thesis'
    #: three clicked floor points make it known (5.4.1), without a person to click.
    WORLD = "world"


class GroundSettings(Protocol):
    """What :class:`GroundPlaneEstimator` reads of a detector's config (basso2012's)."""

    @property
    def ground_mode(self) -> GroundMode: ...
    @property
    def ground_points(self) -> Sequence[tuple[float, float, float]] | None: ...
    @property
    def ground_plane(self) -> tuple[float, float, float, float] | None: ...
    @property
    def ground_pixels(self) -> Sequence[tuple[float, float]] | None: ...
    @property
    def ground_max_tilt_deg(self) -> float: ...
    @property
    def ground_min_points(self) -> int: ...
    @property
    def voxel_size(self) -> float: ...


def gravity_up_in_optical(camera_pose: Pose) -> FloatArray:
    """World +z (up) expressed in the depth optical frame."""
    up: FloatArray = camera_pose.rotation_matrix().T @ np.array([0.0, 0.0, 1.0])
    return up


def floor_from_pose(camera_pose: Pose) -> FloatArray:
    """The world's z = 0 plane in the depth optical frame of ``camera_pose`` (normal up)."""
    up = gravity_up_in_optical(camera_pose)
    return normalise_plane((*up, float(camera_pose.translation[2])))


def auto_ground_plane(
    points: FloatArray, up: FloatArray, voxel_size: float, max_tilt_rad: float
) -> FloatArray | None:
    """RANSAC over the lower half (along ``up``) of the points below the sensor."""
    elevation = points @ up
    below = points[elevation < 0.0]
    if below.shape[0] < 3:
        return None
    lower = below[below @ up <= np.median(below @ up)]
    return ransac_ground_plane(
        lower,
        up,
        threshold=voxel_size,
        max_tilt_rad=max_tilt_rad,
        iterations=RANSAC_ITERATIONS,
        seed=0,
    )


def points_at_pixels(
    pixels: FloatArray, cloud_uv: FloatArray, cloud_points: FloatArray, radius: float
) -> FloatArray | None:
    """The 3D point under each RGB pixel: median of the cloud points projecting within ``radius``."""
    valid = np.all(np.isfinite(cloud_uv), axis=1)
    if not np.any(valid):
        return None
    tree = cKDTree(cloud_uv[valid])
    pts = cloud_points[valid]
    out = []
    for uv in pixels:
        near = tree.query_ball_point(uv, radius)
        if not near:
            return None
        out.append(np.median(pts[near], axis=0))
    return np.asarray(out)


def refine_plane(
    points: FloatArray, plane: FloatArray, band: float, min_points: int
) -> tuple[FloatArray, int]:
    """Refit the plane to the points within ``band`` of it (5.4.2).

    Returns the new plane and the inlier count; the old plane when fewer than
    ``min_points`` inliers are found.
    """
    current = plane
    count = 0
    for _ in range(REFINE_PASSES):
        inliers = np.abs(signed_heights(points, current)) < band
        count = int(inliers.sum())
        if count < min_points:
            return current, count
        current = fit_plane_least_squares(np.compress(inliers, points, axis=0))
    return current, count


def move_plane(plane: FloatArray, old_T_new: Pose) -> FloatArray:
    """A plane given in an old camera frame, expressed in the new one (``old_T_new``)."""
    R = old_T_new.rotation_matrix()
    t = np.asarray(old_T_new.translation)
    normal = plane[:3]
    return normalise_plane((*(R.T @ normal), float(normal @ t) + float(plane[3])))


@dataclass(frozen=True)
class GroundState:
    """What :class:`GroundPlaneEstimator` carries between frames (exact copies)."""

    plane: FloatArray | None
    inliers: int
    last_pose: Pose | None


class GroundPlaneEstimator:
    """Holds the plane from frame to frame; one instance per sequence."""

    def __init__(self, config: GroundSettings) -> None:
        self._config = config
        self.plane: FloatArray | None = None
        self.inliers = 0
        self._last_pose: Pose | None = None
        if config.ground_mode is GroundMode.PLANE:
            if config.ground_plane is None:
                raise ValueError("ground_mode 'plane' needs ground_plane: [a, b, c, d]")
            self.plane = normalise_plane(config.ground_plane)
        elif config.ground_mode is GroundMode.POINTS and config.ground_points is not None:
            a, b, c = (np.asarray(p, dtype=np.float64) for p in config.ground_points)
            self.plane = plane_from_points(a, b, c)

    def state(self) -> GroundState:
        """A copy of the carried state."""
        plane = None if self.plane is None else self.plane.copy()
        return GroundState(plane, self.inliers, self._last_pose)

    def restore(self, state: GroundState) -> None:
        """Continue from :meth:`state` of an estimator of the same config."""
        self.plane = None if state.plane is None else state.plane.copy()
        self.inliers = state.inliers
        self._last_pose = state.last_pose

    def initialise(
        self,
        voxel_points: FloatArray,
        camera_pose: Pose,
        cloud_uv: FloatArray,
        cloud_points: FloatArray,
        pixel_radius: float,
    ) -> FloatArray | None:
        """Find the first plane when none is known yet; None when this frame cannot."""
        cfg = self._config
        if cfg.ground_mode is GroundMode.POINTS and cfg.ground_pixels is not None:
            pts = points_at_pixels(
                np.asarray(cfg.ground_pixels, dtype=np.float64),
                cloud_uv,
                cloud_points,
                pixel_radius,
            )
            if pts is None:
                return None
            return plane_from_points(pts[0], pts[1], pts[2])
        if cfg.ground_mode is GroundMode.WORLD:
            return floor_from_pose(camera_pose)
        up = gravity_up_in_optical(camera_pose)
        return auto_ground_plane(
            voxel_points, up, cfg.voxel_size, math.radians(cfg.ground_max_tilt_deg)
        )

    def update(self, voxel_points: FloatArray, camera_pose: Pose | None = None) -> FloatArray:
        """Refine the known plane on this frame's points (kept when too few floor points).

        With ``camera_pose`` (odometry), the floor is first carried over from the
        previous frame's camera to this one: it is fixed in the world.
        """
        if self.plane is None:
            raise RuntimeError("ground plane not initialised")
        if camera_pose is not None:
            if self._last_pose is not None:
                self.plane = move_plane(self.plane, self._last_pose.inverse().compose(camera_pose))
            self._last_pose = camera_pose
        self.plane, self.inliers = refine_plane(
            voxel_points, self.plane, self._config.voxel_size, self._config.ground_min_points
        )
        return self.plane
