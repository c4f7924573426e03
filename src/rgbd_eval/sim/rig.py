"""The robot's sensor rig: camera models and the tf tree.

Frames (REP-103/105): ``odom`` -> ``base_link`` (odometry) -> ``camera_link``
(static: ahead, up, tilted) -> ``camera_rgb_optical_frame`` and
``camera_depth_optical_frame`` (static; optical convention x right, y down,
z forward). As on the Kinect (and in openni_launch's tf), the depth (IR) camera
sits ``depth_offset_m`` to the RGB camera's left and the IR projector
``baseline_m`` to the IR camera's right, beyond the RGB camera.
"""

from __future__ import annotations

import math

import numpy as np

from rgbd_eval.sim.meshes import rotation_y, rotation_z
from rgbd_eval.sim.scenario import Robot, Sensor
from rgbd_eval.types import OPTICAL_TO_BODY, CameraModel, Pose

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
