"""In-memory DMT-BS runs and the reproduce claims (seed 003, 4.3)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rgbd_eval.methods.dmtbs.detector import DmtbsDetectorConfig
from rgbd_eval.methods.dmtbs.experiments import (
    arc_camera,
    check_claims,
    left_object,
    left_object_frames,
    run_frames,
    with_noise,
    yaw_error,
)
from rgbd_eval.methods.dmtbs.tracker import DmtbsTrackerConfig
from rgbd_eval.sim.rig_config import StaticDepthConfig
from rgbd_eval.sim.rig_sensors import StaticDepthCamera
from rgbd_eval.sim.scenario import Scenario, parse_scenario
from rgbd_eval.sim.tof import TofFrame, TofImage
from rgbd_eval.types import GroundTruthObject, Pose

CAM = StaticDepthCamera(
    StaticDepthConfig(name="a", x=0.0, y=0.0, z=3.0, pitch_deg=90.0, width=64, height=48), "world"
)


def _frames(n: int) -> list[TofFrame]:
    """An empty floor for 2 frames, then a 1.8 m box top under the camera, its centre truth."""
    frames = []
    centre = CAM.pose.transform_points(
        CAM.camera.backproject(np.full((48, 64), 1.2))[22:28, 30:36].reshape(-1, 3)
    )
    xy = centre[:, :2].mean(axis=0)
    for k in range(n):
        depth = np.full((48, 64), 3.0, dtype=np.float32)
        gt = []
        if k >= 2:
            depth[22:28, 30:36] = 1.2
            gt = [GroundTruthObject(k, k * 33_333_333, 7, None, (float(xy[0]), float(xy[1]), 0.9))]
        frames.append(TofFrame(k, k * 33_333_333, [TofImage("a", depth, CAM.camera, CAM.pose)], gt))
    return frames


def test_run_frames_scores_after_the_initialisation() -> None:
    # The 6x6-pixel box top is ~0.026 m^2 of surface, below the default smallest blob.
    det = DmtbsDetectorConfig(init_frames=2, roi=(-2, -2, 2, 2), min_blob_area_m2=0.0)
    run = run_frames(_frames(8), ["a"], det, DmtbsTrackerConfig(confirm_hits=3))
    row = run.row()
    # Frames 2..7 are scored (6 instances); the track is confirmed at its third hit (frame 4),
    # so frames 2 and 3 are misses: MOTA = 1 - 2 / 6.
    assert row["num_gt"] == 6 and row["fn"] == 2 and row["fp"] == 0
    assert row["mota"] == pytest.approx(1 - 2 / 6)
    with pytest.raises(ValueError, match="no camera"):
        run_frames(_frames(1), ["b"], det, DmtbsTrackerConfig())


def test_yaw_error_turns_about_the_vertical_through_the_camera() -> None:
    pose = Pose((1.0, 2.0, 3.0), (0.0, 0.0, 0.0, 1.0))
    turned = yaw_error(pose, 90.0)
    assert turned.translation == pytest.approx((1.0, 2.0, 3.0))
    # x axis -> y axis, z unchanged
    np.testing.assert_allclose(
        turned.rotation_matrix() @ [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], atol=1e-12
    )
    half = math.sqrt(0.5)
    assert turned.rotation == pytest.approx((0.0, 0.0, half, half))


def test_with_noise_adds_the_requested_std_and_keeps_zero_noise_frames() -> None:
    frames = _frames(3)
    assert next(with_noise(frames, 0.0, 1)) is frames[0]
    noisy = list(with_noise(frames, 0.05, 1))
    diff = noisy[0].images[0].depth - frames[0].images[0].depth
    assert float(np.std(diff)) == pytest.approx(0.05, rel=0.1)
    again = list(with_noise(frames, 0.05, 1))
    np.testing.assert_array_equal(again[2].images[0].depth, noisy[2].images[0].depth)


def _rows(mota: dict[float, float], **key: object) -> list[dict[str, object]]:
    return [{**key, "noise_m": k, "mota": v} for k, v in mota.items()]


def test_claims_are_checked_on_the_rows() -> None:
    # Angles 0..90: 0-30 deg average 0.85, 40-90 deg 0.93 -> lower at shallow angles, all >= 0.80.
    angles = [{"angle_deg": float(a), "mota": 0.85 if a <= 30 else 0.93} for a in range(0, 91, 10)]
    cams = [{"cameras": n, "mota": m} for n, m in ((1, 0.80), (2, 0.95), (3, 0.955), (4, 0.96))]
    noise = _rows({0.0: 0.95, 0.05: 0.93, 0.15: 0.4}, background="running_average") + _rows(
        {0.0: 0.96, 0.05: 0.96, 0.125: 0.95, 0.15: 0.9}, background="mog2"
    )
    yaw = [{"yaw_error_deg": 0.0, "mota": 0.95}, {"yaw_error_deg": 1.0, "mota": 0.94}]
    left = {"object_tracked_share": 0.95}
    held = [ok for _, ok in check_claims(cams, noise, yaw, angles, left)]
    assert held == [True] * 8
    # One angle at 0.79: not "well at every angle"; 2 -> 4 cameras gains 3 points: not "only
    # slightly"; 1 deg costs 3 points: not tolerated; the object tracked in 89% of the frames
    # (under 90%): the limitation is not shown.
    angles[0]["mota"] = 0.79
    cams[3]["mota"] = 0.98
    yaw[1]["mota"] = 0.92
    left["object_tracked_share"] = 0.89
    held = [ok for _, ok in check_claims(cams, noise, yaw, angles, left)]
    assert held == [False, True, False, True, True, True, False, False]
    # Steep angles no better than shallow ones: "lower at shallow angles" fails.
    flat = [{"angle_deg": r["angle_deg"], "mota": 0.9} for r in angles]
    assert not check_claims(cams, noise, yaw, flat, left)[1][1]


def test_arc_camera_looks_at_the_target_from_level_to_straight_down() -> None:
    base = StaticDepthConfig(name="c", x=9.0, y=9.0, z=9.0, yaw_deg=30.0, pitch_deg=5.0)
    level = arc_camera(base, 0.0, (0.0, 0.0, 1.0), 5.0)
    # 0 deg: 5 m behind the target along -x, at its height, looking along +x.
    assert (level.x, level.y, level.z, level.yaw_deg, level.pitch_deg) == pytest.approx(
        (-5.0, 0.0, 1.0, 0.0, 0.0)
    )
    down = arc_camera(base, 90.0, (0.0, 0.0, 1.0), 5.0)
    # 90 deg: 5 m above the target (z = 6), looking straight down.
    assert (down.x, down.z, down.pitch_deg) == pytest.approx((0.0, 6.0, 90.0), abs=1e-12)
    # 30 deg: x = -5 cos 30 = -4.330, z = 1 + 5 sin 30 = 3.5; the optical axis hits the target.
    mid = arc_camera(base, 30.0, (0.0, 0.0, 1.0), 5.0)
    assert (mid.x, mid.z) == pytest.approx((-4.330127, 3.5))
    pose = StaticDepthCamera(mid, "world").pose
    axis = pose.rotation_matrix() @ [0.0, 0.0, 1.0]
    np.testing.assert_allclose(np.array(pose.translation) + 5.0 * axis, [0, 0, 1], atol=1e-9)
    with pytest.raises(ValueError, match="angle_deg"):
        arc_camera(base, 95.0, (0.0, 0.0, 1.0), 5.0)


def _box_scene() -> Scenario:
    """A 32x24 camera 3 m above the floor looking down at a 1.5 m box; 6 frames at 30 Hz."""
    return parse_scenario(
        {
            "name": "left_box",
            "duration_s": 0.2,
            "room": {"x_min": -2, "x_max": 2, "y_min": -2, "y_max": 2, "walls": False},
            "obstacles": [{"kind": "box", "x": 0.0, "y": 0.0, "size": [0.5, 0.5, 1.5]}],
            "rig": [
                {
                    "kind": "static_depth",
                    "name": "top",
                    "x": 0.0,
                    "y": 0.0,
                    "z": 3.0,
                    "pitch_deg": 90.0,
                    "width": 32,
                    "height": 24,
                }
            ],
        }
    )


def test_left_object_frames_show_the_object_from_its_time_on() -> None:
    frames = list(left_object_frames(_box_scene(), 0.1))
    # 0.1 s at 30 Hz = frame 3: frames 0-2 see the floor 3 m below the camera at the image
    # centre, frames 3-5 the box top, 3 - 1.5 = 1.5 m below it.
    centre = [float(f.images[0].depth[12, 16]) for f in frames]
    assert centre == pytest.approx([3.0, 3.0, 3.0, 1.5, 1.5, 1.5], abs=1e-3)
    with pytest.raises(ValueError, match="no obstacle"):
        next(left_object_frames(_box_scene().model_copy(update={"obstacles": []}), 0.1))


def test_an_object_left_behind_is_tracked_from_its_third_frame() -> None:
    scene = _box_scene().model_copy(update={"duration_s": 3.0})  # 90 frames
    det = DmtbsDetectorConfig(roi=(-2, -2, 2, 2))  # background learnt over frames 0-29
    row = left_object(scene, det, DmtbsTrackerConfig(confirm_hits=3), 2.0, settle_s=0.0)
    # The box appears at 2.0 s = frame 60; frames 60-89 are counted (30). Its track is
    # confirmed at its third measured frame, 62: frames 62-89 have it, 28 of 30. No person is
    # ground truth, so each of those 28 outputs is a false positive.
    assert (row["object_frames"], row["object_tracked_frames"]) == (30, 28)
    assert row["object_tracked_share"] == pytest.approx(28 / 30)
    assert row["fp"] == 28 and row["num_gt"] == 0


def _walker_scene() -> Scenario:
    """One person walking 1 m across a 64x48 camera's view for 1.5 s (45 frames), with noise."""
    return parse_scenario(
        {
            "name": "walker",
            "duration_s": 1.5,
            "seed": 1,
            "room": {"x_min": -2, "x_max": 2, "y_min": -2, "y_max": 2, "walls": False},
            "truth_visibility": "present",
            "rig": [
                {
                    "kind": "static_depth",
                    "name": "cam",
                    "x": -3.0,
                    "y": 0.0,
                    "z": 3.0,
                    "pitch_deg": 40.0,
                    "width": 64,
                    "height": 48,
                    "noise_k": 0.0002,
                    "random_dropout": 0.05,
                }
            ],
            "people": [
                {"id": 1, "height": 1.8, "path": [{"x": 0.0, "y": -0.5}, {"x": 0.0, "y": 0.5}]}
            ],
        }
    )


def test_camera_angle_pools_the_runs_of_each_angle() -> None:
    from rgbd_eval.methods.dmtbs.experiments import camera_angle

    scene = _walker_scene()
    det = DmtbsDetectorConfig(init_frames=10, roi=(-2, -2, 2, 2), min_blob_area_m2=0.0)
    trk = DmtbsTrackerConfig()
    args = ([90.0], (0.0, 0.0, 1.0), 5.0)
    both = camera_angle(scene, det, trk, args[0], args[1], args[2], [1, 2])
    one = [camera_angle(scene, det, trk, args[0], args[1], args[2], [s])[0] for s in (1, 2)]
    (row,) = both
    # Frames 10-44 are scored in each run (35 ground-truth instances): 70 pooled; the pooled
    # counts are the runs' sums, and the pooled MOTA lies between the runs' (it is their
    # mean weighted by ground truth, here equal).
    assert row["runs"] == 2 and row["num_gt"] == 70 == one[0]["num_gt"] + one[1]["num_gt"]
    for key in ("fp", "fn", "id_switches", "splits"):
        assert row[key] == one[0][key] + one[1][key], key
    assert row["mota"] == pytest.approx((one[0]["mota"] + one[1]["mota"]) / 2)
    assert row["mota_min"] == min(one[0]["mota"], one[1]["mota"])
    assert row["mota_max"] == max(one[0]["mota"], one[1]["mota"])
    with pytest.raises(ValueError, match="at least one seed"):
        camera_angle(scene, det, trk, args[0], args[1], args[2], [])
