"""Static ToF cameras (seed 003, 4.3): camera model, noise model, rig rendering."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from rgbd_eval.errors import ConfigError
from rgbd_eval.sim.scenario import parse_scenario
from rgbd_eval.sim.tof import (
    TofCamera,
    TofRig,
    load_tof_cameras,
    noisy_tof_depth,
    radial_position,
    tof_sigma,
)
from rgbd_eval.types import CameraModel

CAMERAS = Path(__file__).parents[2] / "configs" / "scenarios" / "dmtbs" / "scene2_cameras.yaml"


def test_kinect_v2_camera_model() -> None:
    cam = TofCamera(name="c", x=0, y=0, z=2.0).camera()
    assert (cam.width, cam.height) == (512, 424)
    # fx = 256 / tan(35.3 deg) = 361.6; fy = 212 / tan(30 deg) = 367.2
    assert cam.fx == pytest.approx(256 / math.tan(math.radians(35.3)))
    assert cam.fy == pytest.approx(367.195, abs=1e-3)
    assert (cam.cx, cam.cy) == (255.5, 211.5)
    assert cam.frame_id == "c_depth_optical_frame"


def test_pose_looks_along_yaw_and_down_by_pitch() -> None:
    spec = TofCamera(name="c", x=-2.7, y=-2.7, z=2.6, yaw_deg=45.0, pitch_deg=30.0)
    pose = spec.pose()
    forward = pose.rotation_matrix() @ np.array([0.0, 0.0, 1.0])  # optical z in the world
    c30, s30 = math.cos(math.radians(30)), math.sin(math.radians(30))
    np.testing.assert_allclose(forward, [c30 / math.sqrt(2), c30 / math.sqrt(2), -s30], atol=1e-12)
    # The optical axis meets the floor 2.6 / tan(30 deg) = 4.50 m away (horizontally).
    t = 2.6 / s30
    hit = np.asarray(pose.translation) + t * forward
    assert hit[2] == pytest.approx(0.0, abs=1e-12)
    assert math.hypot(hit[0] + 2.7, hit[1] + 2.7) == pytest.approx(2.6 / math.tan(math.radians(30)))


def test_noise_grows_with_depth_squared_and_off_centre() -> None:
    spec = TofCamera(name="c", x=0, y=0, z=2, sigma_5m=0.005, off_centre_gain=1.0)
    z = np.array([[5.0, 2.5, 5.0]], dtype=np.float32)
    rho2 = np.array([[0.0, 0.0, 1.0]], dtype=np.float32)
    # 5 mm at 5 m on the axis; (2.5/5)^2 = 1/4 of it at 2.5 m; doubled in a corner.
    np.testing.assert_allclose(tof_sigma(z, rho2, spec), [[0.005, 0.00125, 0.01]], rtol=1e-6)
    noisy = TofCamera(name="c", x=0, y=0, z=2, extra_noise_m=0.05)
    # Added noise is independent: sqrt(0.005^2 + 0.05^2)
    assert float(tof_sigma(z[:, :1], rho2[:, :1], noisy)[0, 0]) == pytest.approx(
        math.hypot(0.005, 0.05), rel=1e-6
    )


def test_radial_position_is_zero_at_centre_and_near_one_in_corners() -> None:
    rho2 = radial_position(CameraModel(5, 3, 10.0, 10.0, 2.0, 1.0))
    assert rho2[1, 2] == 0.0
    # corner (0, 0): u = -2 / 2.5, v = -1 / 1.5 -> (0.64 + 0.444) / 2 = 0.542
    assert float(rho2[0, 0]) == pytest.approx((0.64 + 4 / 9) / 2, rel=1e-6)
    # Kinect v2: corner pixel (0, 0): u = -255.5 / 256, v = -211.5 / 212 -> rho^2 = 0.9958
    kinect = radial_position(TofCamera(name="c", x=0, y=0, z=2).camera())
    assert float(kinect[0, 0]) == pytest.approx(
        ((255.5 / 256) ** 2 + (211.5 / 212) ** 2) / 2, rel=1e-6
    )


def test_noisy_depth_statistics_and_invalid_pixels() -> None:
    spec = TofCamera(
        name="c", x=0, y=0, z=2, sigma_5m=0.005, off_centre_gain=0.0, random_dropout=0.0
    )
    rng = np.random.default_rng(0)
    z = np.full((200, 200), 5.0, dtype=np.float32)
    z[0, 0] = np.nan  # nothing hit
    z[0, 1] = 9.0  # beyond the 8 m range
    z[0, 2] = 0.3  # nearer than 0.5 m
    out = noisy_tof_depth(z, np.zeros_like(z), spec, rng)
    assert np.isnan(out[0, :3]).all()
    body = out[10:, :]
    assert float(np.std(body - 5.0)) == pytest.approx(0.005, rel=0.05)
    assert abs(float(np.mean(body - 5.0))) < 0.0005


def test_camera_file_and_its_errors(tmp_path: Path) -> None:
    cams = load_tof_cameras(CAMERAS)
    assert [c.name for c in cams] == ["cam0", "cam1", "cam2", "cam3"]
    bad = tmp_path / "bad.yaml"
    bad.write_text("cameras: [{name: a, x: 0, y: 0, z: 2, roll_deg: 3}]\n")
    with pytest.raises(ConfigError, match="roll_deg"):
        load_tof_cameras(bad)
    bad.write_text("cameras: [{name: a, x: 0, y: 0, z: 2}, {name: a, x: 1, y: 0, z: 2}]\n")
    with pytest.raises(ConfigError, match="unique"):
        load_tof_cameras(bad)
    with pytest.raises(ConfigError, match="cannot read"):
        load_tof_cameras(tmp_path / "absent.yaml")


def test_rig_renders_the_floor_at_the_expected_depth() -> None:
    scenario = parse_scenario(
        {
            "name": "floor",
            "duration_s": 0.1,
            "room": {
                "x_min": -3,
                "x_max": 3,
                "y_min": -3,
                "y_max": 3,
                "walls": False,
                "ceiling": False,
            },
        }
    )
    spec = TofCamera(
        name="c",
        x=0,
        y=0,
        z=2.0,
        pitch_deg=90.0,
        width=64,
        height=48,
        sigma_5m=0.0,
        random_dropout=0.0,
    )
    frame = TofRig(scenario, [spec]).frame(0)
    depth = frame.images[0].depth
    # Looking straight down from 2 m: every pixel sees the floor at optical depth z = 2 m.
    np.testing.assert_allclose(depth[np.isfinite(depth)], 2.0, atol=1e-4)
    assert np.isfinite(depth).mean() > 0.95
    assert frame.ground_truth == []
