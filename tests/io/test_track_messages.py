"""Tracks recorded in a bag: each supported message type written with our writer, read back.

Every recording holds a static transform odom -> base_link of (+1, +2, 0) m, and
the tracks are published in base_link: positions read back are in odom, shifted
by exactly that. Two frames, two tracks each (ids 3 and 5).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from typer.testing import CliRunner

from rgbd_eval.cli.main import app
from rgbd_eval.errors import InputError
from rgbd_eval.io.groundtruth import write_csv
from rgbd_eval.io.track_message_types import (
    DETECTION2D_TYPE,
    DETECTION3D_TYPE,
    OPT_TYPE,
    PEOPLE_TYPE,
    SPENCER_TYPE,
)
from rgbd_eval.io.track_messages import read_bag_tracks
from rgbd_eval.io.writer import RecordingWriter
from rgbd_eval.types import GroundTruthObject, Pose, Visibility

T0 = 1_700_000_000_000_000_000
PERIOD = 100_000_000
# (id, x, y) in base_link per frame; frame 1 moves everyone 0.5 m along x.
TRACKS = [[(3, 1.0, 0.0), (5, 4.0, -1.0)], [(3, 1.5, 0.0), (5, 4.5, -1.0)]]
SHIFT = (1.0, 2.0, 0.0)


def _point(w: RecordingWriter, x: float, y: float, z: float = 0.0) -> Any:
    return w._t("geometry_msgs/msg/Point")(x=x, y=y, z=z)


def _pose_cov(w: RecordingWriter, x: float, y: float) -> Any:
    t = w._t
    pose = t("geometry_msgs/msg/Pose")(
        position=_point(w, x, y), orientation=t("geometry_msgs/msg/Quaternion")(0.0, 0.0, 0.0, 1.0)
    )
    return t("geometry_msgs/msg/PoseWithCovariance")(pose=pose, covariance=np.zeros(36))


def _message(
    w: RecordingWriter, msgtype: str, stamp: int, tracks: list[tuple[int, float, float]]
) -> Any:
    t = w._t
    header = w.header(stamp, "base_link", msgtype)
    ros1 = w.ros_version == 1
    if msgtype == SPENCER_TYPE:
        twist = t("geometry_msgs/msg/TwistWithCovariance")(
            twist=t("geometry_msgs/msg/Twist")(
                linear=t("geometry_msgs/msg/Vector3")(0.0, 0.0, 0.0),
                angular=t("geometry_msgs/msg/Vector3")(0.0, 0.0, 0.0),
            ),
            covariance=np.zeros(36),
        )
        persons = [
            t("spencer_tracking_msgs/msg/TrackedPerson")(
                track_id=i,
                is_occluded=i == 5,
                is_matched=True,
                detection_id=0,
                age=t("builtin_interfaces/msg/Duration")(sec=1, nanosec=0),
                pose=_pose_cov(w, x, y),
                twist=twist,
            )
            for i, x, y in tracks
        ]
        return t(SPENCER_TYPE)(header=header, tracks=persons)
    if msgtype == PEOPLE_TYPE:
        people = [
            t("people_msgs/msg/Person")(
                name=str(i),
                position=_point(w, x, y),
                velocity=_point(w, 0.0, 0.0),
                reliability=1.0,
                tagnames=[],
                tags=[],
            )
            for i, x, y in tracks
        ]
        return t(PEOPLE_TYPE)(header=header, people=people)
    if msgtype == OPT_TYPE:
        items = [
            t("opt_msgs/msg/Track")(
                id=i,
                x=x,
                y=y,
                height=1.7,
                distance=3.0,
                age=1.0,
                confidence=1.0,
                visibility=0,
                box_2D=t("opt_msgs/msg/BoundingBox2D")(x=10 * i, y=20, width=30, height=60),
            )
            for i, x, y in tracks
        ]
        return t(OPT_TYPE)(header=header, tracks=items)
    if msgtype == DETECTION3D_TYPE:
        dets = []
        for i, x, y in tracks:
            pose = _pose_cov(w, x, y).pose
            bbox = t("vision_msgs/msg/BoundingBox3D")(
                center=pose, size=t("geometry_msgs/msg/Vector3")(0.5, 0.5, 1.8)
            )
            common = {"header": header, "results": [], "bbox": bbox}
            if ros1:
                cloud = t("sensor_msgs/msg/PointCloud2")(
                    header=header,
                    height=0,
                    width=0,
                    fields=[],
                    is_bigendian=False,
                    point_step=0,
                    row_step=0,
                    data=np.zeros(0, np.uint8),
                    is_dense=True,
                )
                dets.append(
                    t("vision_msgs/msg/Detection3D")(
                        **common, source_cloud=cloud, is_tracking=True, tracking_id=str(i)
                    )
                )
            else:
                dets.append(t("vision_msgs/msg/Detection3D")(**common, id=str(i)))
        return t(DETECTION3D_TYPE)(header=header, detections=dets)
    # Detection2DArray: boxes centred at (100 x, 200), 40 x 80 pixels.
    dets = []
    for i, x, _ in tracks:
        if ros1:
            center = t("geometry_msgs/msg/Pose2D")(x=100 * x, y=200.0, theta=0.0)
        else:
            center = t("vision_msgs/msg/Pose2D")(
                position=t("vision_msgs/msg/Point2D")(x=100 * x, y=200.0), theta=0.0
            )
        bbox = t("vision_msgs/msg/BoundingBox2D")(center=center, size_x=40.0, size_y=80.0)
        common = {"header": header, "results": [], "bbox": bbox}
        if ros1:
            img = t("sensor_msgs/msg/Image")(
                header=header,
                height=0,
                width=0,
                encoding="",
                is_bigendian=0,
                step=0,
                data=np.zeros(0, np.uint8),
            )
            dets.append(
                t("vision_msgs/msg/Detection2D")(
                    **common, source_img=img, is_tracking=True, tracking_id=str(i)
                )
            )
        else:
            dets.append(t("vision_msgs/msg/Detection2D")(**common, id=str(i)))
    return t(DETECTION2D_TYPE)(header=header, detections=dets)


def _write(path: Path, msgtype: str, topic: str = "/tracks") -> None:
    with RecordingWriter(path) as w:
        w.write_static_transform(T0, "odom", "base_link", Pose(SHIFT))
        for k, tracks in enumerate(TRACKS):
            w.write_message(
                topic, msgtype, T0 + k * PERIOD, _message(w, msgtype, T0 + k * PERIOD, tracks)
            )


@pytest.mark.parametrize("suffix", [".bag", ".mcap"])
@pytest.mark.parametrize(
    "msgtype", [SPENCER_TYPE, PEOPLE_TYPE, OPT_TYPE, DETECTION3D_TYPE, DETECTION2D_TYPE]
)
def test_each_type_round_trips(tmp_path: Path, msgtype: str, suffix: str) -> None:
    path = tmp_path / f"tracks{suffix}"
    _write(path, msgtype)
    out = read_bag_tracks(path)
    assert [s for _, s, _ in out.frames] == [T0, T0 + PERIOD]
    for (_, _, tracks), expected in zip(out.frames, TRACKS, strict=True):
        assert [t.track_id for t in tracks] == [i for i, _, _ in expected]
        for t, (_, x, y) in zip(tracks, expected, strict=True):
            if msgtype == DETECTION2D_TYPE:  # image boxes only: centre (100 x, 200), 40 x 80
                assert math.isnan(t.x)
                assert t.box2d is not None
                assert t.box2d.as_tuple() == pytest.approx((100 * x - 20, 160.0, 40.0, 80.0))
            else:  # base_link -> odom adds (1, 2)
                assert (t.x, t.y) == pytest.approx((x + SHIFT[0], y + SHIFT[1]))
    first = out.frames[0][2]
    if msgtype == SPENCER_TYPE:
        assert [t.visibility for t in first] == [Visibility.VISIBLE, Visibility.OCCLUDED]
    if msgtype == OPT_TYPE:
        assert first[0].box2d is not None and first[0].box2d.as_tuple() == (30.0, 20.0, 30.0, 60.0)
        assert first[0].height == pytest.approx(1.7)
    if msgtype == DETECTION3D_TYPE:
        assert first[0].height == pytest.approx(1.8)


def test_the_tracks_frame_gives_the_sensor_pose(tmp_path: Path) -> None:
    bag = tmp_path / "tracks.mcap"
    _write(bag, SPENCER_TYPE)
    poses = read_bag_tracks(bag).sensor_poses
    assert [p.translation if p else None for p in poses] == [SHIFT, SHIFT]
    # Tracks published in the world frame itself: no sensor pose.
    assert read_bag_tracks(_write_in(tmp_path / "odom.bag", "odom")).sensor_poses == (None, None)


def test_topic_must_be_chosen_when_several(tmp_path: Path) -> None:
    path = tmp_path / "two.mcap"
    with RecordingWriter(path) as w:
        w.write_static_transform(T0, "odom", "base_link", Pose(SHIFT))
        for topic, msgtype in (("/a", PEOPLE_TYPE), ("/b", OPT_TYPE)):
            w.write_message(topic, msgtype, T0, _message(w, msgtype, T0, TRACKS[0]))
    with pytest.raises(InputError, match="expected one topic"):
        read_bag_tracks(path)
    assert [t.track_id for t in read_bag_tracks(path, "/b").frames[0][2]] == [3, 5]


def test_score_a_bag_against_world_ground_truth(tmp_path: Path) -> None:
    # Ground truth in odom exactly where the tracks end up; metric gating: all 4 match.
    bag = tmp_path / "run.bag"
    _write(bag, SPENCER_TYPE)
    gt = tmp_path / "gt.csv"
    write_csv(
        gt,
        [
            GroundTruthObject(k, T0 + k * PERIOD, 10 * i, None, (x + 1.0, y + 2.0, 0.9))
            for k, tracks in enumerate(TRACKS)
            for i, x, y in tracks
        ],
    )
    out = tmp_path / "out"
    result = CliRunner().invoke(
        app, ["score", str(bag), "--gt", str(gt), "--gating", "metric", "--out", str(out)]
    )
    assert result.exit_code == 0, result.output
    import json

    sequence = json.loads((out / "report.json").read_text())["sequences"][0]
    counts = sequence["counts"]
    assert (counts["num_matches"], counts["fp"], counts["fn"], counts["id_switches"]) == (
        4,
        0,
        0,
        0,
    )
    # The tracks' frame, base_link, is the sensor: at (1, 2) in odom by the tf. Person 0 is
    # 1 then 1.5 m from it, person 10 hypot(4, 1) = 4.1 then 4.6 m: two instances in 0-2 m,
    # two in 4-6 m; the static tf: standing.
    distance = {
        b["band"]: b["counts"]["num_gt"] for b in sequence["breakdowns"]["distance"]["bands"]
    }
    assert distance == {"0-2 m": 2, "2-4 m": 0, "4-6 m": 2, "6+ m": 0}
    motion = {b["band"]: b["counts"]["frames"] for b in sequence["breakdowns"]["motion"]["bands"]}
    assert motion == {"standing": 2, "turning": 0, "driving": 0}


def _world_gt(path: Path) -> Path:
    """Ground truth exactly at the tracks' positions as written (no shift)."""
    write_csv(
        path,
        [
            GroundTruthObject(k, T0 + k * PERIOD, 10 * i, None, (x, y, 0.9))
            for k, tracks in enumerate(TRACKS)
            for i, x, y in tracks
        ],
    )
    return path


def _write_in(path: Path, frame_id: str) -> Path:
    """opt_msgs/TrackArray in ``frame_id``, and no /tf at all."""
    with RecordingWriter(path) as w:
        for k, tracks in enumerate(TRACKS):
            msg = _message(w, OPT_TYPE, T0 + k * PERIOD, tracks)
            msg.header.frame_id = frame_id
            w.write_message("/tracks", OPT_TYPE, T0 + k * PERIOD, msg)
    return path


def test_tracks_with_no_tf_to_the_ground_truths_frame_are_refused(tmp_path: Path) -> None:
    """Issue 28: tracks in 'world' with no /tf were scored as they are (MOTA -106 %)."""
    bag, gt = _write_in(tmp_path / "world.bag", "world"), _world_gt(tmp_path / "gt.csv")
    base = ["score", str(bag), "--gt", str(gt), "--gating", "metric"]
    result = CliRunner().invoke(app, [*base, "--out", str(tmp_path / "a")])
    assert result.exit_code == 3, result.output
    message = " ".join(result.output.split())
    assert message.startswith(f"error: {bag} [/tracks]: "), message
    assert "tracks' frame 'world'" in message and "ground truth's frame 'odom'" in message
    assert "no tf chain from 'odom' to 'world'" in message and "io.world_frame" in message
    assert not (tmp_path / "a").exists()
    # Saying the ground truth is in 'world' scores them: all 4 match.
    out = tmp_path / "b"
    result = CliRunner().invoke(app, [*base, "--set", "io.world_frame=world", "--out", str(out)])
    assert result.exit_code == 0, result.output
    import json

    counts = json.loads((out / "report.json").read_text())["sequences"][0]["counts"]
    assert (counts["num_matches"], counts["fp"], counts["fn"]) == (4, 0, 0)


def test_tracks_in_the_default_world_frame_need_no_tf(tmp_path: Path) -> None:
    # 'odom' is io.world_frame's default: tracks already there are read as they are.
    out = read_bag_tracks(_write_in(tmp_path / "odom.bag", "odom"))
    assert [(t.x, t.y) for t in out.frames[0][2]] == [(1.0, 0.0), (4.0, -1.0)]
    with pytest.raises(InputError, match="tracks' frame 'odom'"):
        read_bag_tracks(tmp_path / "odom.bag", world_frame="map")
