"""Fixtures: small recordings written with the real writers into tmp_path."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

from rgbd_eval.io.writer import Container, RecordingWriter, StreamOptions
from rgbd_eval.types import OPTICAL_TO_BODY, Box2D, CameraModel, GroundTruthObject, Pose

RGB_CAM = CameraModel(64, 48, 52.5, 52.5, 31.5, 23.5, (0.0,) * 5, "camera_rgb_optical_frame")
DEPTH_CAM = CameraModel(32, 24, 26.25, 26.25, 15.5, 11.5, (0.0,) * 5, "camera_depth_optical_frame")
T0 = 1_700_000_000_000_000_000
PERIOD = 33_333_333
#: camera_link -> depth optical: 2.5 cm to the left of the RGB optical frame.
DEPTH_OFFSET = Pose((0.0, 0.025, 0.0), OPTICAL_TO_BODY.rotation)
BASE_TO_CAMERA = Pose((0.1, 0.0, 1.2))


def rgb_image(i: int) -> np.ndarray:
    """Distinct smooth ramps per channel (so a channel swap shows) plus a little noise."""
    rng = np.random.default_rng(i)
    y, x = np.mgrid[0 : RGB_CAM.height, 0 : RGB_CAM.width]
    img = np.stack([x * 4 + i, y * 5, np.full_like(x, 128)], axis=-1)
    img = img + rng.integers(-8, 9, img.shape)
    return np.clip(img, 0, 255).astype(np.uint8)


def depth_image(i: int) -> np.ndarray:
    rng = np.random.default_rng(1000 + i)
    depth = rng.uniform(0.5, 7.5, (DEPTH_CAM.height, DEPTH_CAM.width)).astype(np.float32)
    depth[0, :3] = np.nan  # invalid pixels
    return depth


def odom_pose(stamp_ns: int) -> Pose:
    """The robot drives along x at 0.5 m/s and turns at 0.2 rad/s."""
    t = (stamp_ns - T0) / 1e9
    yaw = 0.2 * t
    return Pose((0.5 * t, 0.0, 0.0), (0.0, 0.0, float(np.sin(yaw / 2)), float(np.cos(yaw / 2))))


@dataclass
class Spec:
    """What to write."""

    n: int = 5
    options: StreamOptions = field(default_factory=StreamOptions)
    odometry: bool = True
    camera_tf: bool = True
    ground_truth: bool = True
    depth_delay_ns: int = 2_000_000
    rgb_stamps: list[int] | None = None
    depth_stamps: list[int] | None = None


def write_recording(path: Path, container: Container, spec: Spec | None = None) -> Path:
    spec = spec or Spec()
    rgb_stamps = spec.rgb_stamps or [T0 + i * PERIOD for i in range(spec.n)]
    depth_stamps = spec.depth_stamps or [s + spec.depth_delay_ns for s in rgb_stamps]
    with RecordingWriter(path, container, spec.options) as w:
        if spec.camera_tf:
            w.write_static_transform(T0, "base_link", "camera_link", BASE_TO_CAMERA)
            w.write_static_transform(T0, "camera_link", "camera_rgb_optical_frame", OPTICAL_TO_BODY)
            w.write_static_transform(T0, "camera_link", "camera_depth_optical_frame", DEPTH_OFFSET)
        if spec.odometry:
            # Odometry at 50 Hz covering the whole sequence.
            for k in range(int((rgb_stamps[-1] - T0) / 20_000_000) + 3):
                s = T0 - 20_000_000 + k * 20_000_000
                w.write_odometry(s, "odom", "base_link", odom_pose(s))
        for i, (rs, ds) in enumerate(zip(rgb_stamps, depth_stamps, strict=False)):
            w.write_rgb(rs, rgb_image(i), RGB_CAM)
            w.write_depth(ds, depth_image(i), DEPTH_CAM)
            if spec.ground_truth:
                w.write_ground_truth(
                    rs,
                    "odom",
                    [
                        GroundTruthObject(
                            i, rs, 7, Box2D(10.0 + i, 5.0, 8.0, 30.0), (2.0, 0.1 * i, 0.9), 0.8
                        )
                    ],
                )
    return path


@pytest.fixture
def make_recording(tmp_path: Path) -> Callable[..., Path]:
    def make(
        container: Container = "mcap", spec: Spec | None = None, name: str | None = None
    ) -> Path:
        suffix = {"ros1": ".bag", "mcap": ".mcap"}.get(container, "")
        return write_recording(tmp_path / (name or f"rec_{container}{suffix}"), container, spec)

    return make
