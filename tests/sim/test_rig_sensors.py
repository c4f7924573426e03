"""Extra rig sensors: a static depth camera written on its own topics with tf, read back."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rgbd_eval.errors import ConfigError
from rgbd_eval.io.groundtruth import load_ground_truth
from rgbd_eval.io.recording import open_recording
from rgbd_eval.plugins import StreamSpec
from rgbd_eval.sim import parse_scenario, synthesize

SCENARIO = {
    "name": "rig_test",
    "duration_s": 0.2,
    "room": {"x_min": -1.0, "x_max": 8.0, "y_min": -3.0, "y_max": 3.0},
    "people": [
        {
            "id": 1,
            "height": 1.8,
            "shirt": [200, 30, 30],
            "trousers": [30, 30, 30],
            "path": [{"x": 3.0, "y": 0.5}, {"x": 3.0, "y": -0.5, "speed": 1.0}],
        },
    ],
    "sensor": {"depth_decimation": 4},
    # 6 m ahead of the robot, 2.5 m up, looking back at the person, tilted 20 deg down
    "rig": [
        {
            "kind": "static_depth",
            "name": "cam_a",
            "x": 6.5,
            "y": 0.0,
            "z": 2.5,
            "yaw_deg": 180.0,
            "pitch_deg": 20.0,
            "width": 128,
            "height": 106,
        },
    ],
}


def test_static_depth_camera_sees_the_person_where_the_ground_truth_is(tmp_path: Path) -> None:
    out = tmp_path / "rig.bag"
    synthesize(parse_scenario(SCENARIO), out)
    rec = open_recording(out, streams=(StreamSpec("depth", multiple=True),))
    roles = {topic: role for role, topic in rec.info.selected.streams.items()}
    assert set(roles) == {"/cam_a/depth/image_raw", "/camera/depth/image_raw"}  # + the Kinect
    gt = load_ground_truth(out.with_name("rig.gt.csv"))
    frame = next(iter(rec.frames()))
    cam = frame.streams[roles["/cam_a/depth/image_raw"]]
    assert cam.image.shape == (106, 128)
    # the camera's pose comes back from tf: 6.5 m along x, 2.5 m up (up to odometry noise
    # of the first frame, which the world frame carries)
    np.testing.assert_allclose(cam.pose.translation, (6.5, 0.0, 2.5), atol=0.05)
    # the person's ground-truth centre, projected into the static camera, is about as far
    # as its depth there: the visible surface is at most a body half-width nearer
    person = next(o for o in gt.frames[0][2] if o.object_id == 1)
    assert person.world_xyz is not None
    centre = cam.pose.inverse().transform_points(np.array([person.world_xyz]))
    (u, v), z = cam.camera.project(centre)[0], centre[0, 2]
    iu, iv = round(float(u)), round(float(v))
    seen = cam.image[iv - 1 : iv + 2, iu - 1 : iu + 2]
    assert np.nanmin(seen) == pytest.approx(z, abs=0.35)


def test_unknown_rig_sensor_kind_is_named() -> None:
    bad = {**SCENARIO, "rig": [{"kind": "sonar", "name": "s"}]}
    with pytest.raises(
        ConfigError, match=r"unknown rig sensor kind 'sonar' \(known: .*static_depth"
    ):
        parse_scenario(bad)
