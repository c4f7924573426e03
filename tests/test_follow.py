"""Person following (seed 002, section 3): the path-C law by hand, and a short closed loop."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest

from rgbd_eval.config import load_config
from rgbd_eval.errors import ConfigError
from rgbd_eval.io.recording import open_recording
from rgbd_eval.methods.satake2009.follow import (
    FollowControl,
    drive,
    follow,
    follow_paths,
    in_robot_frame,
    path_c_wheel_speeds,
    wheel_command,
    write_follow,
)
from rgbd_eval.pipeline import run_sequence
from rgbd_eval.plugins import StreamSpec
from rgbd_eval.sim import parse_scenario


def test_path_c_wheel_speeds_by_hand() -> None:
    # target X = 2, Y = 1 (left): X^2 + Y^2 = 5; v = 0.5, d = 0.2
    # k = 1 (path A): 2dY / 5 = 0.4 / 5 = 0.08 -> v_L = 0.5 * 0.92 = 0.46, v_R = 0.5 * 1.08 = 0.54;
    # the same as v (1 -+ d / rho) with rho = (X^2 + Y^2) / 2Y = 2.5: d / rho = 0.08
    assert path_c_wheel_speeds(2.0, 1.0, 0.5, 1.0, 0.2) == pytest.approx((0.46, 0.54))
    # k = 2 (path C): 0.16 -> 0.42, 0.58 (radius rho / k = 1.25: tighter)
    assert path_c_wheel_speeds(2.0, 1.0, 0.5, 2.0, 0.2) == pytest.approx((0.42, 0.58))
    # target on the right turns right; straight ahead drives straight
    assert path_c_wheel_speeds(2.0, -1.0, 0.5, 2.0, 0.2) == pytest.approx((0.58, 0.42))
    assert path_c_wheel_speeds(3.0, 0.0, 0.5, 2.0, 0.2) == (0.5, 0.5)
    assert path_c_wheel_speeds(0.0, 0.0, 0.5, 2.0, 0.2) == (0.5, 0.5)  # no division by 0


def test_path_a_arc_ends_on_the_target() -> None:
    # Path A (k = 1) is the circle through the robot and the target, tangent to the
    # heading: rho = 2.5 for (2, 1); it turns by phi = 2 atan(Y / X) = 0.9273 rad over an
    # arc of rho phi = 2.318 m. Driving it in one step of the 2.3.1 kinematics lands on
    # (2, 1): chord 2 rho sin(phi / 2) = 5 * 0.4472 = 2.236 = sqrt(5) at angle phi / 2.
    v, d = 0.5, 0.2
    v_L, v_R = path_c_wheel_speeds(2.0, 1.0, v, 1.0, d)
    phi = 2.0 * math.atan2(1.0, 2.0)
    x, y, yaw = drive((0.0, 0.0, 0.0), v_L, v_R, d, 2.5 * phi / v)
    assert (x, y, yaw) == pytest.approx((2.0, 1.0, phi))


def test_drive_straight_and_in_place() -> None:
    # both wheels 0.5 m/s for 2 s: 1 m along the heading (yaw 90 deg: +y)
    assert drive((1.0, 1.0, math.pi / 2), 0.5, 0.5, 0.2, 2.0) == pytest.approx(
        (1.0, 2.0, math.pi / 2)
    )
    # -0.1 / +0.1 m/s with d = 0.2: omega = 0.2 / 0.4 = 0.5 rad/s, no translation
    assert drive((0.0, 0.0, 0.0), -0.1, 0.1, 0.2, 1.0) == pytest.approx((0.0, 0.0, 0.5))


def test_wheel_command_slows_near_the_target_and_saturates() -> None:
    c = FollowControl(v=0.6, k=2.0, d=0.2, stop_m=1.5, full_m=2.5, v_max=0.9)
    assert wheel_command(1.4, 0.0, c) == (0.0, 0.0)  # nearer than stop_m: stand
    assert wheel_command(2.0, 0.0, c) == pytest.approx((0.3, 0.3))  # half way: v / 2
    assert wheel_command(4.0, 0.0, c) == pytest.approx((0.6, 0.6))
    # X = 0, Y = 3 (to the left, beside the robot): turn = 2 * 2 * 0.2 * 3 / 9 = 0.2667,
    # v = 0.6: (0.44, 0.76) within 0.9, unchanged
    assert wheel_command(0.0, 3.0, c) == pytest.approx((0.44, 0.76))
    # k = 6: turn = 0.8 -> (0.12, 1.08): 1.08 > 0.9 scales both by 0.9 / 1.08 -> (0.1, 0.9)
    fast = FollowControl(v=0.6, k=6.0, d=0.2, stop_m=1.5, full_m=2.5, v_max=0.9)
    assert wheel_command(0.0, 3.0, fast) == pytest.approx((0.1, 0.9))
    with pytest.raises(ValueError, match="stop_m"):
        FollowControl(stop_m=3.0, full_m=2.5)


def test_in_robot_frame() -> None:
    # robot at (1, 1) facing +y: a point at (1, 3) is 2 m ahead, (0, 1) is 1 m to the left
    pose = (1.0, 1.0, math.pi / 2)
    assert in_robot_frame(pose, (1.0, 3.0)) == pytest.approx((2.0, 0.0))
    assert in_robot_frame(pose, (0.0, 1.0)) == pytest.approx((0.0, 1.0))


def _walker(**extra: Any) -> dict[str, Any]:
    """One person 2.6 m ahead, standing 0.5 s, then walking straight away at 0.5 m/s."""
    data: dict[str, Any] = {
        "name": "walk_away",
        "duration_s": 2.0,
        "seed": 1,
        "room": {"x_min": -1.0, "x_max": 10.0, "y_min": -4.0, "y_max": 4.0},
        "sensor": {
            "rate_hz": 20.0, "width": 512, "height": 384, "hfov_deg": 100.0,
            "vfov_deg": 83.58, "depth_decimation": 4,
        },
        "people": [
            # short hair: long hair down the back of a dark top, seen from behind, is the
            # colour test's known failure (methods/satake2009/colour.py), not this test's
            {"id": 7, "hair_style": "short",
             "path": [{"x": 2.6, "y": 0.0, "wait_s": 0.5}, {"x": 8.0, "y": 0.0, "speed": 0.5}]}
        ],
        "robot": {"camera_x": 0.1, "camera_height": 1.2},
        "rig": [{"kind": "stereo_pair", "name": "stereo", "width": 512, "height": 384}],
    }  # fmt: skip
    data.update(extra)
    return data


def test_follow_refuses_a_scenario_without_a_pair_or_target() -> None:
    with pytest.raises(ConfigError, match="no stereo_pair"):
        follow(parse_scenario(_walker(rig=[])), 7)
    with pytest.raises(ConfigError, match="no such person"):
        follow(parse_scenario(_walker()), 3)


@pytest.mark.slow
def test_closed_loop_keeps_a_target_walking_straight(tmp_path: Path) -> None:
    # 40 frames (2 s at 20 fps). The robot locks onto person 7 once the tracker outputs
    # it (two matches), drives after it (2.6 m is past stop_m = 1.5 m) and keeps it.
    out = tmp_path / "walk.mcap"
    result = follow(parse_scenario(_walker()), 7, out_path=out)
    s = result.summary
    assert s.lock_frame is not None and s.lock_frame <= 3
    assert s.kept and s.frames_lost == 0 and s.frames_wrong == 0
    assert s.frames_following == 40 - s.lock_frame
    last = result.steps[-1]
    assert last.robot_x > 0.4  # it drove: without the loop the robot stands at x = 0
    assert abs(last.robot_y) < 0.1 and s.bearing_max_abs_deg is not None
    assert s.bearing_max_abs_deg < 5.0  # a straight walker stays ahead
    assert s.track_error_mean_m is not None and s.track_error_mean_m < 0.3
    # the recording holds the driven path: its odometry ends near the true final pose
    rec = open_recording(out, streams=(StreamSpec("left"), StreamSpec("right")))
    frames = list(rec.frames())
    assert len(frames) == 40
    x_odom = frames[-1].stream("left").pose.translation[0] - 0.1  # left camera 0.1 m ahead
    assert x_odom == pytest.approx(last.robot_x, abs=0.05)
    # replaying the recording offline gives the tracks the loop saw online, bit for bit:
    # the frames built in the loop are the frames a reader builds (the reader takes the
    # odometry recorded at a frame's stamp as recorded; interpolating it re-normalised
    # the quaternion and moved a position in its last bit)
    replay = run_sequence(out, load_config(method="satake2009"))
    assert replay.tracks == result.tracks
    csv_path, json_path = write_follow(result, out)
    assert (csv_path, json_path) == follow_paths(out)
    assert len(csv_path.read_text().splitlines()) == 41
    # deterministic: the first frames again give the same steps
    again = follow(parse_scenario(_walker()), 7, max_frames=6)
    assert again.steps == result.steps[:6]


def test_the_method_runs_on_one_opencv_thread_and_its_cpu_time_excludes_rendering(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # The timing claim of `reproduce satake2009` is the detector's and tracker's CPU time
    # per frame, one core's work: OpenCV runs on one thread while the loop runs (so
    # process_time counts no thread pool), and its setting is restored afterwards.
    import cv2

    from rgbd_eval.components import create_detector as real
    from rgbd_eval.methods.satake2009 import follow as follow_module

    seen: list[int] = []

    def spy(config: Any) -> Any:
        detector = real(config)
        detect = detector.detect

        def counted(frame: Any) -> Any:
            seen.append(cv2.getNumThreads())
            return detect(frame)

        detector.detect = counted  # type: ignore[method-assign]
        return detector

    monkeypatch.setattr(follow_module, "create_detector", spy)
    before = cv2.getNumThreads()
    cv2.setNumThreads(2)  # a thread pool, as on any multi-core machine
    try:
        result = follow(parse_scenario(_walker()), 7, max_frames=2)
        assert seen == [1, 1]
        assert cv2.getNumThreads() == 2
    finally:
        cv2.setNumThreads(before)
    assert set(result.cpu_s) == {"render", "detect", "track"}
    assert result.cpu_s["detect"] > 0.0 and result.cpu_s["render"] > 0.0
