"""Odometry from the wheels' sensor_msgs/JointState (io.wheels; satake2009, seed 002, 2.3.1)."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from rgbd_eval.config import IoConfig, WheelsConfig
from rgbd_eval.errors import DecodeError, TopicError
from rgbd_eval.io import wheels
from rgbd_eval.io.recording import open_recording
from rgbd_eval.io.writer import RecordingWriter
from rgbd_eval.types import OPTICAL_TO_BODY, Pose

from .conftest import (
    BASE_TO_CAMERA,
    DEPTH_CAM,
    DEPTH_OFFSET,
    PERIOD,
    RGB_CAM,
    T0,
    Spec,
    depth_image,
    rgb_image,
)

#: Wheel radius 0.1 m, wheels 0.4 m apart (d = 0.2 m); JointState at 50 Hz from T0 - 20 ms.
WHEELS = WheelsConfig(
    left_joint="wheel_left", right_joint="wheel_right", radius_m=0.1, separation_m=0.4
)
J0 = T0 - 20_000_000


def _write(path: Path, left_rad_s: float, right_rad_s: float, names: list[str]) -> Path:
    """5 colour + depth frames at 30 Hz, the camera's static tf, constant wheel JointStates."""
    with RecordingWriter(path, "mcap") as w:
        w.write_static_transform(T0, "base_link", "camera_link", BASE_TO_CAMERA)
        w.write_static_transform(T0, "camera_link", "camera_rgb_optical_frame", OPTICAL_TO_BODY)
        w.write_static_transform(T0, "camera_link", "camera_depth_optical_frame", DEPTH_OFFSET)
        joint_state = w.store.types[wheels.JOINT_STATE_TYPE]
        speed = {"wheel_left": left_rad_s, "wheel_right": right_rad_s, "caster": 9.0}
        for k in range(12):
            s = J0 + k * 20_000_000
            msg = joint_state(
                header=w.header(s, "", "/joint_states"),
                name=names,
                position=np.zeros(len(names)),
                velocity=np.array([speed[n] for n in names]),
                effort=np.zeros(0),
            )
            w.write_message("/joint_states", wheels.JOINT_STATE_TYPE, s, msg)
        for i in range(5):
            s = T0 + i * PERIOD
            w.write_rgb(s, rgb_image(i), RGB_CAM)
            w.write_depth(s + 2_000_000, depth_image(i), DEPTH_CAM)
    return path


def _camera_at(base: Pose) -> Pose:
    return base.compose(BASE_TO_CAMERA).compose(DEPTH_OFFSET)


def test_straight_wheels_move_the_camera_along_x(tmp_path: Path) -> None:
    # 5 rad/s * 0.1 m = 0.5 m/s on both wheels: the base is at x = 0.5 (t - J0) at frame t.
    path = _write(tmp_path / "straight.mcap", 5.0, 5.0, ["caster", "wheel_left", "wheel_right"])
    rec = open_recording(path, IoConfig(wheels=WHEELS))
    assert rec.info.has_odometry and rec.info.world_frame == "odom"
    for f in rec.frames():
        x = 0.5 * (f.stamp_ns - J0) * 1e-9
        expected = _camera_at(Pose((x, 0.0, 0.0)))
        np.testing.assert_allclose(f.camera_pose.matrix(), expected.matrix(), atol=1e-9)


def test_opposite_wheels_turn_the_robot_in_place(tmp_path: Path) -> None:
    # v_L = -0.2, v_R = +0.2 m/s, d = 0.2 m: v = 0, omega = 0.4 / 0.4 = 1 rad/s to the left;
    # the base stays at the origin with yaw = t - J0, the camera 0.1 m ahead swings with it.
    path = _write(tmp_path / "turn.mcap", -2.0, 2.0, ["wheel_right", "wheel_left"])
    for f in open_recording(path, IoConfig(wheels=WHEELS)).frames():
        yaw = (f.stamp_ns - J0) * 1e-9
        base = Pose((0.0, 0.0, 0.0), (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)))
        np.testing.assert_allclose(f.camera_pose.matrix(), _camera_at(base).matrix(), atol=1e-9)


def test_a_missing_wheel_joint_is_a_decode_error(tmp_path: Path) -> None:
    path = _write(tmp_path / "bad.mcap", 5.0, 5.0, ["caster", "wheel_left"])
    with pytest.raises(
        DecodeError, match=r"no wheel joint 'wheel_right'.*joints: caster, wheel_left"
    ):
        open_recording(path, IoConfig(wheels=WHEELS))


def test_wheels_configured_but_no_joint_state_topic(
    make_recording: Callable[..., Path],
) -> None:
    path = make_recording("mcap", Spec(ground_truth=False))
    with pytest.raises(TopicError, match="no JointState topic found"):
        open_recording(path, IoConfig(wheels=WHEELS))


def test_drive_is_the_closed_form_arc() -> None:
    # v_L = 0.1, v_R = 0.3 m/s, d = 0.2 m: v = 0.2 m/s, omega = 0.2 / 0.4 = 0.5 rad/s,
    # rho = v / omega = 0.4 m. After 2 s: theta = 1 rad, and the arc's end
    # (rho sin theta, rho (1 - cos theta)) = (0.3366, 0.1839).
    p = wheels.drive(wheels.PlanarPose(), 0.1, 0.3, 0.2, 2.0)
    assert (p.x, p.y, p.yaw) == pytest.approx((0.4 * math.sin(1), 0.4 * (1 - math.cos(1)), 1.0))
    # straight (v_L = v_R): no division by a zero angle
    assert wheels.drive(wheels.PlanarPose(1, 2, 0), 0.5, 0.5, 0.2, 2.0) == wheels.PlanarPose(
        2, 2, 0
    )
