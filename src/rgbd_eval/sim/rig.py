"""The robot's sensor rig: camera models and the tf tree; the view a rig sensor renders from.

Frames (REP-103/105): ``odom`` -> ``base_link`` (odometry) -> ``camera_link``
(static: ahead, up, tilted) -> ``camera_rgb_optical_frame`` and
``camera_depth_optical_frame`` (static; optical convention x right, y down,
z forward). As on the Kinect (and in openni_launch's tf), the depth (IR) camera
sits ``depth_offset_m`` to the RGB camera's left and the IR projector
``baseline_m`` to the IR camera's right, beyond the RGB camera.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Protocol

import numpy as np
from numpy.typing import NDArray

from rgbd_eval import exact
from rgbd_eval.sim.meshes import rotation_y, rotation_z
from rgbd_eval.sim.scenario import Robot, Sensor
from rgbd_eval.types import OPTICAL_TO_BODY, CameraModel, Pose

if TYPE_CHECKING:
    from rgbd_eval.io.writer import RecordingWriter
    from rgbd_eval.sim.render import Hits

WORLD_FRAME = "odom"
BASE_FRAME = "base_link"
CAMERA_LINK = "camera_link"
RGB_FRAME = "camera_rgb_optical_frame"
DEPTH_FRAME = "camera_depth_optical_frame"


def rgb_camera(sensor: Sensor) -> CameraModel:
    """The RGB camera at full resolution (focal lengths from the field of view)."""
    return CameraModel(
        sensor.width,
        sensor.height,
        sensor.fx,
        sensor.fy,
        (sensor.width - 1) / 2.0,
        (sensor.height - 1) / 2.0,
        (0.0, 0.0, 0.0, 0.0, 0.0),
        RGB_FRAME,
    )


def depth_camera_full(sensor: Sensor) -> CameraModel:
    """The depth camera before decimation (same intrinsics as the RGB camera)."""
    c = rgb_camera(sensor)
    return CameraModel(c.width, c.height, c.fx, c.fy, c.cx, c.cy, c.distortion, DEPTH_FRAME)


def depth_camera(sensor: Sensor) -> CameraModel:
    """The depth camera as published (decimated per ``depth_decimation``)."""
    d = sensor.depth_decimation
    full = depth_camera_full(sensor)
    if d == 1:
        return full
    return full.scaled(sensor.width // d, sensor.height // d)


def base_to_camera_link(robot: Robot) -> Pose:
    """base_link_T_camera_link: ahead by camera_x, up by camera_height, pitched down by tilt."""
    T = np.eye(4)
    T[:3, :3] = rotation_y(math.radians(robot.camera_tilt_deg))
    T[:3, 3] = (robot.camera_x, 0.0, robot.camera_height)
    return Pose.from_matrix(T)


def camera_link_to_rgb() -> Pose:
    """camera_link_T_rgb_optical."""
    return OPTICAL_TO_BODY


def camera_link_to_depth(sensor: Sensor) -> Pose:
    """camera_link_T_depth_optical: the depth camera is to the left (+y) of the RGB camera."""
    return Pose((0.0, sensor.depth_offset_m, 0.0), OPTICAL_TO_BODY.rotation)


def base_pose(x: float, y: float, yaw: float) -> Pose:
    """world_T_base_link for a planar pose."""
    T = np.eye(4)
    T[:3, :3] = rotation_z(yaw)
    T[:3, 3] = (x, y, 0.0)
    return Pose.from_matrix(T)


def pinhole_from_fov(
    width: int, height: int, hfov_deg: float, vfov_deg: float, frame_id: str
) -> CameraModel:
    """An undistorted camera with the given fields of view, principal point at the centre."""
    fx = (width / 2.0) / exact.tan(math.radians(hfov_deg) / 2.0)
    fy = (height / 2.0) / exact.tan(math.radians(vfov_deg) / 2.0)
    return CameraModel(
        width, height, fx, fy, (width - 1) / 2.0, (height - 1) / 2.0, (0.0,) * 5, frame_id
    )


@dataclass(frozen=True)
class SceneView:
    """One instant of the scene, for a rig sensor to render and write."""

    index: int
    stamp_ns: int
    world_frame: str
    #: Ray-cast static scene + people from ``pose`` (world_T_optical) through ``camera``.
    render: Callable[[CameraModel, Pose], Hits]
    rng: np.random.Generator
    #: world_T_base_link of the robot at this instant (robot-mounted sensors render from it).
    base_pose: Pose = field(default_factory=Pose.identity)
    #: Lit colour ((H, W, 3) float32, 0..255) of rendered hits, as the Kinect's RGB is shaded.
    shade: Callable[[Hits], NDArray[np.float32]] | None = None
    #: Per-pixel (object id, material) of a :meth:`render` result (``NO_HIT``, -1: nothing).
    surface: Callable[[Hits], tuple[NDArray[np.int32], NDArray[np.int32]]] | None = None
    #: The colour camera's true world_T_optical (the thermal camera sits beside it).
    rgb_pose: Pose = field(default_factory=Pose.identity)


class RigSensor(Protocol):
    """A sensor of the rig: its static tf, and what it writes each frame."""

    def static_transforms(self) -> list[tuple[str, str, Pose]]:
        """``(parent, child, parent_T_child)`` written once to ``/tf_static``."""
        ...

    def write(self, writer: RecordingWriter, view: SceneView) -> None:
        """Render and write this sensor's messages of one frame."""
        ...
