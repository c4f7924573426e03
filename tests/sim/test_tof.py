"""Static ToF cameras (seed 003, 4.3): noise model, rig rendering, recording round trip."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from rgbd_eval.errors import ConfigError
from rgbd_eval.io.groundtruth import load_ground_truth
from rgbd_eval.io.recording import open_recording
from rgbd_eval.plugins import StreamSpec
from rgbd_eval.sim import load_scenario, parse_scenario, synthesize
from rgbd_eval.sim.rig_config import StaticDepthConfig
from rgbd_eval.sim.rig_sensors import StaticDepthCamera
from rgbd_eval.sim.sensor import radial_position, tof_depth, tof_sigma
from rgbd_eval.sim.simulate import Simulator
from rgbd_eval.sim.tof import TofRig
from rgbd_eval.types import CameraModel

SCENE2 = Path(__file__).parents[2] / "configs" / "scenarios" / "dmtbs" / "scene2.yaml"


def _cfg(**kw: object) -> StaticDepthConfig:
    return StaticDepthConfig.model_validate({"name": "c", "x": 0, "y": 0, "z": 2.0, **kw})


def test_kinect_v2_camera_model() -> None:
    cam = StaticDepthCamera(_cfg(), "world").camera
    assert (cam.width, cam.height) == (512, 424)
    # fx = 256 / tan(35.3 deg) = 361.6; fy = 212 / tan(30 deg) = 367.2
    assert cam.fx == pytest.approx(256 / math.tan(math.radians(35.3)))
    assert cam.fy == pytest.approx(367.195, abs=1e-3)
    assert (cam.cx, cam.cy) == (255.5, 211.5)


def test_pose_looks_along_yaw_and_down_by_pitch() -> None:
    pose = StaticDepthCamera(_cfg(x=-2.7, y=-2.7, z=2.6, yaw_deg=45.0, pitch_deg=30.0), "w").pose
    forward = pose.rotation_matrix() @ np.array([0.0, 0.0, 1.0])  # optical z in the world
    c30, s30 = math.cos(math.radians(30)), math.sin(math.radians(30))
    np.testing.assert_allclose(forward, [c30 / math.sqrt(2), c30 / math.sqrt(2), -s30], atol=1e-12)


def test_noise_grows_with_depth_squared_and_off_centre() -> None:
    cfg = _cfg(noise_k=0.0002, off_centre_gain=1.0)
    z = np.array([[5.0, 2.5, 5.0]])
    rho2 = np.array([[0.0, 0.0, 1.0]], dtype=np.float32)
    # 0.0002 * 25 = 5 mm at 5 m on the axis; a quarter of it at 2.5 m; doubled in a corner.
    np.testing.assert_allclose(tof_sigma(z, rho2, cfg), [[0.005, 0.00125, 0.01]], rtol=1e-6)
    # Added noise is independent: sqrt(0.005^2 + 0.05^2)
    noisy = _cfg(noise_k=0.0002, extra_noise_m=0.05)
    assert float(tof_sigma(z[:, :1], rho2[:, :1], noisy)[0, 0]) == pytest.approx(
        math.hypot(0.005, 0.05), rel=1e-9
    )


def test_radial_position_is_zero_at_centre_and_near_one_in_corners() -> None:
    rho2 = radial_position(CameraModel(5, 3, 10.0, 10.0, 2.0, 1.0))
    assert rho2[1, 2] == 0.0
    # corner (0, 0): u = -2 / 2.5, v = -1 / 1.5 -> (0.64 + 0.444) / 2
    assert float(rho2[0, 0]) == pytest.approx((0.64 + 4 / 9) / 2, rel=1e-6)
    kinect = radial_position(StaticDepthCamera(_cfg(), "w").camera)
    # corner pixel of 512x424: u = -255.5 / 256, v = -211.5 / 212
    expected = ((255.5 / 256) ** 2 + (211.5 / 212) ** 2) / 2
    assert float(kinect[0, 0]) == pytest.approx(expected, rel=1e-6)


def test_noisy_depth_statistics_and_invalid_pixels() -> None:
    cfg = _cfg(noise_k=0.0002)
    z = np.full((200, 200), 5.0, dtype=np.float32)
    z[0, 0] = np.nan  # nothing hit
    z[0, 1] = 9.0  # beyond the 8 m range
    z[0, 2] = 0.3  # nearer than 0.5 m
    out = tof_depth(z, cfg, np.random.default_rng(0))
    assert np.isnan(out[0, :3]).all()
    body = out[10:, :]
    assert float(np.std(body - 5.0)) == pytest.approx(0.005, rel=0.05)
    assert abs(float(np.mean(body - 5.0))) < 0.0005
    # Dropout: 2% random, all of an edge at dropout 1.
    z[100:, 100:] = 2.0
    holes = tof_depth(z, _cfg(random_dropout=0.02, edge_dropout=1.0), np.random.default_rng(1))
    assert np.isnan(holes[99:101, 100:]).all() and np.isnan(holes[100:, 99:101]).all()
    assert np.isnan(holes[20:90, 20:90]).mean() == pytest.approx(0.02, abs=0.005)


def test_ideal_camera_is_exact() -> None:
    z = np.array([[1.0, 2.0], [np.nan, 3.0]], dtype=np.float32)
    np.testing.assert_array_equal(tof_depth(z, _cfg(), np.random.default_rng(0)), z)


def test_rig_renders_the_floor_at_the_expected_depth() -> None:
    scenario = parse_scenario(
        {
            "name": "floor",
            "duration_s": 0.1,
            "room": {"x_min": -3, "x_max": 3, "y_min": -3, "y_max": 3, "walls": False},
            "rig": [{"kind": "static_depth", "name": "c", "x": 0, "y": 0, "z": 2.0,
                     "pitch_deg": 90.0, "width": 64, "height": 48}],
        }
    )  # fmt: skip
    rig = TofRig(scenario)
    frame = rig.frame(0)
    depth = frame.images[0].depth
    # Looking straight down from 2 m: every pixel sees the floor at optical depth z = 2 m.
    np.testing.assert_allclose(depth[np.isfinite(depth)], 2.0, atol=1e-4)
    assert np.isfinite(depth).mean() > 0.95
    assert frame.ground_truth == []
    assert rig.names == ["c"]


@pytest.mark.slow
def test_scene2_recording_round_trip(tmp_path: Path) -> None:
    """Two frames of scene 2: four ToF topics with tf; the in-memory rig renders the same."""
    scenario = load_scenario(SCENE2, [("duration_s", 2 / 30)])
    out = tmp_path / "scene2.mcap"
    synthesize(scenario, out)
    rec = open_recording(out, streams=(StreamSpec("depth", multiple=True),))
    topics = set(rec.info.selected.streams.values())
    assert {f"/cam{k}/depth/image_raw" for k in range(4)} <= topics
    # robot_camera: false: the robot's Kinect (/camera/...) is neither rendered nor written.
    assert not [t.name for t in rec.info.topics if t.name.startswith("/camera/")]
    frame = next(iter(rec.frames()))
    memory = TofRig(scenario).frame(0)
    by_topic = {t: r for r, t in rec.info.selected.streams.items()}
    for im in memory.images:
        stream = frame.streams[by_topic[f"/{im.name}/depth/image_raw"]]
        np.testing.assert_allclose(stream.pose.matrix(), im.pose.matrix(), atol=1e-9)
        both = np.isfinite(stream.image) & np.isfinite(im.depth)
        # 16UC1 stores millimetres: the recording is the rendering rounded to 1 mm.
        np.testing.assert_allclose(stream.image[both], im.depth[both], atol=0.0006)
        assert (np.isfinite(stream.image) == np.isfinite(im.depth)).mean() > 0.999
    # Ground truth counts everyone present (truth_visibility: present), none ignored.
    gt = load_ground_truth(out.with_name("scene2.gt.csv"))
    objects = [o for f in gt.frames for o in f[2]]
    assert len(objects) == 8 and not any(o.ignore for o in objects)
    # Without the Kinect there are no image boxes; the positions are the in-memory rig's.
    assert all(o.box2d is None for o in objects)
    first = sorted((o for o in objects if o.frame == 0), key=lambda o: o.object_id)
    expected = sorted(memory.ground_truth, key=lambda o: o.object_id)
    for got, want in zip(first, expected, strict=True):
        assert got.world_xyz == pytest.approx(want.world_xyz, abs=1e-6)


def test_no_robot_camera_needs_present_truth_and_renders_no_kinect() -> None:
    data = {
        "name": "rig_only",
        "duration_s": 0.1,
        "robot_camera": False,
        "people": [{"id": 1, "height": 1.8, "path": [{"x": 1.0, "y": 0.5}]}],
    }
    with pytest.raises(ConfigError, match="truth_visibility: present"):
        parse_scenario(data)
    scenario = parse_scenario({**data, "truth_visibility": "present"})
    frame = Simulator(scenario).frame(0)
    assert frame.rgb.size == 0 and frame.depth.size == 0
    # Everyone present is ground truth at their floor position, half their height up, with
    # no image box (as TofRig's): the person stands at (1.0, 0.5).
    (gt,) = frame.ground_truth
    assert gt.box2d is None and gt.object_id == 1
    assert gt.world_xyz[:2] == pytest.approx((1.0, 0.5))
    assert 0.8 < gt.world_xyz[2] < 0.95
