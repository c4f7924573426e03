"""One-time calibration of static depth cameras (seed 003, section 3, Fig. 1).

Two results: the floor plane, found in the first depth image of a camera (or given), and,
per camera, the rigid transform from its optical frame to the common world frame (from the
recording's tf, or from a calibration YAML). Both combine into ``floor_T_optical`` per
camera: floor coordinates have x, y on the floor and z the height above it, so the density
map bins x, y and the 1 m height cut reads z.

Calibration YAML (``detector.calibration``), poses ``world_T_optical`` with ROS quaternions::

    cameras:
      cam0_depth_optical_frame: {translation: [0.0, -2.5, 2.6], rotation: [x, y, z, w]}
      cam1_depth_optical_frame: {translation: [2.5, 0.0, 2.6], rotation: [x, y, z, w]}
    floor: [0.0, 0.0, 1.0, 0.0]   # optional: a, b, c, d in the world frame (default z = 0)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, ValidationError

from rgbd_eval.detect.plane import normalise_plane, ransac_ground_plane
from rgbd_eval.errors import ConfigError
from rgbd_eval.files import parse_yaml, read_text
from rgbd_eval.types import CameraModel, Pose

FloatArray = NDArray[np.float64]

#: RANSAC hypotheses for the floor search in the first depth image.
FLOOR_RANSAC_ITERATIONS = 256
#: Every n-th pixel (both axes) of the first depth image enters the floor search.
FLOOR_PIXEL_STRIDE = 4


def floor_from_depth(
    depth: NDArray[np.floating],
    camera: CameraModel,
    up: FloatArray,
    inlier_band_m: float,
    max_tilt_deg: float,
) -> FloatArray:
    """The floor plane ``(a, b, c, d)`` in the camera's optical frame, from one depth image.

    RANSAC over the lower half (along ``up``, the world's up in the optical frame) of the
    valid points, keeping planes whose normal is within ``max_tilt_deg`` of ``up``; ties go
    to the lowest plane, so a table top never wins over the floor. ``d > 0`` (the camera is
    above the floor). :class:`ValueError` when no such plane is seen.
    """
    step = FLOOR_PIXEL_STRIDE
    points = camera.backproject(depth)[::step, ::step].reshape(-1, 3)
    points = points[np.all(np.isfinite(points), axis=1)]
    up = np.asarray(up, dtype=np.float64) / float(np.linalg.norm(up))
    if points.shape[0] >= 3:
        lower = points[points @ up <= np.median(points @ up)]
        plane = ransac_ground_plane(
            lower,
            up,
            threshold=inlier_band_m,
            max_tilt_rad=math.radians(max_tilt_deg),
            iterations=FLOOR_RANSAC_ITERATIONS,
            seed=0,
        )
        if plane is not None:
            return plane
    raise ValueError(
        f"no floor plane within {max_tilt_deg} deg of the vertical in the depth image "
        f"of camera {camera.frame_id or '?'} ({points.shape[0]} sampled points)"
    )


def floor_frame(plane: FloatArray, forward: FloatArray) -> Pose:
    """``floor_T_frame`` for a plane ``(a, b, c, d)`` given in some frame.

    The floor frame has z along the plane normal (up, away from the floor), its origin at the
    foot of the perpendicular from the frame's origin, and x along ``forward`` projected on the
    floor (y completes a right-handed frame). A point's floor z is its height above the floor.
    """
    p = normalise_plane(plane)
    n = p[:3]
    f = np.asarray(forward, dtype=np.float64)
    x = f - (f @ n) * n
    if float(np.linalg.norm(x)) < 1e-6:
        # Looking straight down the normal: any horizontal direction will do; take the
        # frame's x (or y when x too is vertical).
        for axis in (np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])):
            x = axis - (axis @ n) * n
            if float(np.linalg.norm(x)) > 1e-6:
                break
    x = x / float(np.linalg.norm(x))
    y = np.cross(n, x)
    T = np.eye(4)
    T[:3, :3] = np.stack([x, y, n])
    T[:3, 3] = (0.0, 0.0, float(p[3]))
    return Pose.from_matrix(T)


def world_floor_frame(plane_world: FloatArray) -> Pose:
    """``floor_T_world`` for a floor plane given in a z-up world frame (x kept along world x).

    For the plane z = 0 this is the identity.
    """
    return floor_frame(plane_world, np.array([1.0, 0.0, 0.0]))


def plane_in_world(plane_optical: FloatArray, world_T_optical: Pose) -> FloatArray:
    """A plane given in a camera's optical frame, expressed in the world frame."""
    p = normalise_plane(plane_optical)
    R = world_T_optical.rotation_matrix()
    t = np.asarray(world_T_optical.translation)
    n_world = R @ p[:3]
    # A world point q maps to the optical point R^T (q - t): n . R^T (q - t) + d = 0.
    d_world = float(p[3]) - float(n_world @ t)
    a, b, c = (float(v) for v in n_world)
    world = np.array([a, b, c, d_world])
    norm = float(np.linalg.norm(world[:3]))
    world = world / norm
    # Orient the normal up (world +z side), which normalise_plane would not do here.
    return world if world[2] >= 0 else -world


@dataclass(frozen=True)
class CameraCalibration:
    """One camera's intrinsics and ``floor_T_optical``, the transform the density map uses."""

    name: str
    camera: CameraModel
    floor_from_optical: Pose


class _CalibrationPose(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)

    translation: tuple[float, float, float]
    rotation: tuple[float, float, float, float] = Field(
        (0.0, 0.0, 0.0, 1.0), description="unit quaternion x, y, z, w"
    )


class CalibrationFile(BaseModel):
    """The calibration YAML: ``world_T_optical`` per camera frame, optionally the floor."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    cameras: dict[str, _CalibrationPose] = Field(min_length=1)
    floor: tuple[float, float, float, float] | None = Field(
        None, description="floor plane a, b, c, d in the world frame; default z = 0"
    )

    def pose(self, name: str) -> Pose:
        """``world_T_optical`` of a camera; :class:`ConfigError` naming the known ones."""
        entry = self.cameras.get(name)
        if entry is None:
            known = ", ".join(sorted(self.cameras))
            raise ConfigError(f"calibration has no camera {name!r} (known: {known})")
        return Pose(entry.translation, entry.rotation)

    def floor_plane(self) -> FloatArray:
        """The world floor plane (default z = 0)."""
        plane = (0.0, 0.0, 1.0, 0.0) if self.floor is None else self.floor
        return np.asarray(plane, dtype=np.float64)


def load_calibration(path: Path) -> CalibrationFile:
    """Read and validate a calibration YAML; :class:`ConfigError` on any problem."""

    # A regular, bounded UTF-8 file, strict YAML (duplicate keys and alias bombs refused).
    def error(message: str) -> ConfigError:
        return ConfigError(f"{path}: {message}")

    raw = parse_yaml(read_text(Path(path), error, "calibration"), error)
    try:
        calibration = CalibrationFile.model_validate(raw)
    except ValidationError as err:
        first = err.errors()[0]
        where = ".".join(str(part) for part in first["loc"]) or "(top level)"
        raise ConfigError(f"{path}: calibration {where}: {first['msg']}") from err
    for name, entry in calibration.cameras.items():
        if float(np.linalg.norm(entry.rotation)) < 1e-9:
            raise ConfigError(f"{path}: calibration cameras.{name}.rotation is a zero quaternion")
    if calibration.floor is not None and float(np.linalg.norm(calibration.floor[:3])) < 1e-9:
        raise ConfigError(f"{path}: calibration floor normal (a, b, c) must be non-zero")
    return calibration
