"""Frames of named streams: depth-only, two depth cameras, colour + depth + mono16 thermal.

Each recording is written with the real writers (rosbags, mcap) and read back.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rgbd_eval.config import IoConfig
from rgbd_eval.errors import SyncError, TopicError
from rgbd_eval.io.recording import open_recording
from rgbd_eval.io.streams import ALL_STREAMS
from rgbd_eval.io.writer import RecordingWriter
from rgbd_eval.plugins import StreamSpec
from rgbd_eval.types import OPTICAL_TO_BODY, CameraModel, Pose

from .conftest import DEPTH_CAM, PERIOD, RGB_CAM, T0, depth_image, rgb_image

THERMAL_CAM = CameraModel(16, 12, 14.0, 14.0, 7.5, 5.5, (0.0,) * 5, "thermal_optical_frame")
CAM2 = CameraModel(32, 24, 26.25, 26.25, 15.5, 11.5, (0.0,) * 5, "cam2_optical_frame")
#: The second depth camera sits 4 m along world x, looking back (yaw 180 deg).
WORLD_TO_CAM1 = Pose((0.0, 0.0, 2.0), OPTICAL_TO_BODY.rotation)
WORLD_TO_CAM2 = Pose((4.0, 0.0, 2.0), (0.0, 0.0, 1.0, 0.0)).compose(OPTICAL_TO_BODY)


def put(
    w: RecordingWriter, topic: str, stamp: int, image: np.ndarray, cam: CameraModel, enc: str
) -> None:
    """Write ``image`` on ``topic`` and its CameraInfo on ``<namespace>/camera_info``."""
    w.write_image(topic, topic.rsplit("/", 1)[0] + "/camera_info", stamp, image, cam, enc)


def thermal_image(i: int) -> np.ndarray:
    """16-bit raw counts around 30000, as radiometric thermal cameras give."""
    y, x = np.mgrid[0 : THERMAL_CAM.height, 0 : THERMAL_CAM.width]
    return (30000 + 10 * x + 100 * y + i).astype(np.uint16)


def test_depth_only_recording(tmp_path: Path) -> None:
    path = tmp_path / "depth_only.mcap"
    with RecordingWriter(path, "mcap") as w:
        for i in range(3):
            put(w, "/cam/depth/image_raw", T0 + i * PERIOD, depth_image(i), DEPTH_CAM, "16UC1")
    with pytest.raises(TopicError, match="no colour image topic found"):
        open_recording(path)  # colour + depth, the RGB-D default
    rec = open_recording(path, streams=(StreamSpec("depth"), StreamSpec("colour", required=False)))
    assert dict(rec.info.selected.streams) == {"depth": "/cam/depth/image_raw"}
    frames = list(rec.frames())
    assert len(frames) == 3 and set(frames[0].streams) == {"depth"}
    # 16UC1 keeps millimetres: equal to 0.5 mm
    valid = ~np.isnan(depth_image(2))
    assert np.allclose(frames[2].depth[valid], depth_image(2)[valid], atol=5e-4 + 1e-6)
    with pytest.raises(KeyError, match="no 'colour' stream"):
        _ = frames[0].rgb


def test_two_depth_cameras_are_two_streams(tmp_path: Path) -> None:
    path = tmp_path / "rig.bag"
    with RecordingWriter(path, "ros1") as w:
        w.write_static_transform(T0, "world", DEPTH_CAM.frame_id, WORLD_TO_CAM1)
        w.write_static_transform(T0, "world", CAM2.frame_id, WORLD_TO_CAM2)
        for i in range(4):
            s = T0 + i * PERIOD
            put(
                w,
                "/cam1/depth/image_raw",
                s,
                depth_image(i),
                DEPTH_CAM,
                "16UC1",
            )
            # the second camera runs 3 ms late
            put(w, "/cam2/depth/image_raw", s + 3_000_000, depth_image(10 + i), CAM2, "16UC1")
    rec = open_recording(path, streams=(StreamSpec("depth", multiple=True),))
    assert dict(rec.info.selected.streams) == {
        "depth": "/cam1/depth/image_raw",
        "depth_2": "/cam2/depth/image_raw",
    }
    assert rec.info.has_odometry and rec.info.world_frame == "world"  # a static rig in the world
    frames = list(rec.frames())
    assert len(frames) == 4
    f = frames[1]
    assert [r for r, _ in f.depth_streams()] == ["depth", "depth_2"]
    assert f.streams["depth_2"].stamp_ns == f.stamp_ns + 3_000_000
    # each camera has its own pose in the world, from tf
    np.testing.assert_allclose(f.streams["depth"].pose.matrix(), WORLD_TO_CAM1.matrix(), atol=1e-12)
    np.testing.assert_allclose(
        f.streams["depth_2"].pose.matrix(), WORLD_TO_CAM2.matrix(), atol=1e-12
    )
    # a point 1 m in front of camera 2 is at x = 3 m in the world (it looks back along -x)
    p = f.streams["depth_2"].pose.transform_points(np.array([[0.0, 0.0, 1.0]]))
    np.testing.assert_allclose(p, [[3.0, 0.0, 2.0]], atol=1e-12)
    # the roles can be given explicitly too, in any order
    io = IoConfig(topics={"depth": "/cam2/depth/image_raw", "depth_2": "/cam1/depth/image_raw"})
    swapped = open_recording(path, io, streams=(StreamSpec("depth", multiple=True),))
    assert swapped.info.selected.streams["depth"] == "/cam2/depth/image_raw"


def _write_thermal_rig(path: Path, thermal_topic: str) -> None:
    with RecordingWriter(path, "mcap") as w:
        for i in range(3):
            s = T0 + i * PERIOD
            put(
                w,
                "/camera/rgb/image_color",
                s,
                rgb_image(i),
                RGB_CAM,
                "rgb8",
            )
            put(w, "/camera/depth/image_raw", s + 1_000_000, depth_image(i), DEPTH_CAM, "16UC1")
            put(w, thermal_topic, s + 2_000_000, thermal_image(i), THERMAL_CAM, "mono16")


def test_colour_depth_and_mono16_thermal_get_the_right_roles(tmp_path: Path) -> None:
    path = tmp_path / "thermal.mcap"
    _write_thermal_rig(path, "/thermal/image_raw")
    # The RGB-D default reads colour and depth: the mono16 thermal image is never taken for depth.
    rgbd = open_recording(path)
    assert dict(rgbd.info.selected.streams) == {
        "colour": "/camera/rgb/image_color",
        "depth": "/camera/depth/image_raw",
    }
    streams = (StreamSpec("thermal"), StreamSpec("colour"), StreamSpec("depth", required=False))
    rec = open_recording(path, streams=streams)
    assert rec.info.selected.streams["thermal"] == "/thermal/image_raw"
    assert rec.info.sync.reference == "thermal"
    f = next(iter(rec.frames()))
    t = f.streams["thermal"]
    assert t.encoding == "mono16" and t.image.dtype == np.uint16
    np.testing.assert_array_equal(t.image, thermal_image(0))
    np.testing.assert_array_equal(f.rgb, rgb_image(0))
    assert f.stamp_ns == T0 + 2_000_000  # the reference (thermal) stamp
    # inspect's view: every role found, none required
    assert set(open_recording(path, streams=ALL_STREAMS).info.selected.streams) == {
        "colour", "depth", "thermal",
    }  # fmt: skip


def test_an_ambiguous_mono16_topic_is_not_guessed(tmp_path: Path) -> None:
    """mono16 on a topic whose name says neither depth nor thermal: the user chooses."""
    path = tmp_path / "ambiguous.mcap"
    with RecordingWriter(path, "mcap") as w:
        put(w, "/cam/image_raw", T0, thermal_image(0), THERMAL_CAM, "mono16")
    with pytest.raises(TopicError, match=r"could be depth image or another kind.*--topic depth="):
        open_recording(path, streams=(StreamSpec("depth"),))
    rec = open_recording(
        path, IoConfig(topics={"thermal": "/cam/image_raw"}), (StreamSpec("thermal"),)
    )
    assert rec.info.selected.streams == {"thermal": "/cam/image_raw"}


REGISTERED_CAM = CameraModel(
    32, 24, 26.25, 26.25, 15.5, 11.5, (0.0,) * 5, "camera_rgb_optical_frame"
)


def _registered(path: Path) -> Path:
    """depth_registered/image_raw without a CameraInfo of its own, and rgb/image_rect_color."""
    cam = REGISTERED_CAM
    with RecordingWriter(path, "ros1") as w:
        for i in range(2):
            s = T0 + i * PERIOD
            put(w, "/camera/rgb/image_rect_color", s, rgb_image(i)[:24, :32], cam, "rgb8")
            # the depth image's CameraInfo goes to a topic of another namespace: none of its own
            depth = depth_image(i)
            w.write_image(
                "/camera/depth_registered/image_raw", "/other/info", s, depth, cam, "16UC1"
            )
    return path


def test_registered_depth_without_its_own_camera_info(tmp_path: Path) -> None:
    """depth_registered/image with only rgb/camera_info: the colour model, and a warning."""
    path = _registered(tmp_path / "registered.bag")
    rec = open_recording(path)
    assert rec.info.cameras["depth"] == rec.info.cameras["colour"]
    assert any("registered to the colour image" in w for w in rec.info.warnings)
    assert len(list(rec.frames())) == 2
    with pytest.raises(TopicError, match="--topic depth_info=/nonexistent: not a CameraInfo topic"):
        open_recording(path, IoConfig(topics={"depth_info": "/nonexistent"}))


def test_no_pair_names_the_smallest_offset_and_the_option(tmp_path: Path) -> None:
    path = tmp_path / "snapshot.mcap"
    with RecordingWriter(path, "mcap") as w:
        put(w, "/camera/rgb/image_color", T0, rgb_image(0), RGB_CAM, "rgb8")
        put(w, "/camera/depth/image_raw", T0 + 200_000_000, depth_image(0), DEPTH_CAM, "16UC1")
    with pytest.raises(SyncError, match=r"smallest offset is 200\.0 ms.*io\.max_sync_gap_ms=201"):
        open_recording(path)
    assert len(open_recording(path, IoConfig(max_sync_gap_ms=201)).frame_stamps) == 1


@pytest.mark.parametrize("method", ["basso2012", "pinto2022", "dmtbs"])
def test_every_method_takes_the_colour_model_for_a_registered_depth_image(
    tmp_path: Path, method: str
) -> None:
    """Issue 28: dmtbs (depth only) refused what basso2012 and pinto2022 accept."""
    from rgbd_eval.config import load_config
    from rgbd_eval.pipeline import open_for

    rec = open_for(_registered(tmp_path / "registered.bag"), load_config(method=method))
    assert rec.info.cameras["depth"] == REGISTERED_CAM
    warning = (
        "/camera/depth_registered/image_raw has no CameraInfo of its own: registered to the "
        "colour image (/camera/rgb/camera_info), whose camera model it takes"
    )
    assert warning in rec.info.warnings
    assert len(list(rec.frames())) == 2


def test_a_depth_image_unlike_the_colour_camera_keeps_needing_its_camera_info(
    tmp_path: Path,
) -> None:
    """Another frame id than the colour image's: not registered, refused for every method."""
    path = tmp_path / "unregistered.bag"
    with RecordingWriter(path, "ros1") as w:
        put(w, "/camera/rgb/image_rect_color", T0, rgb_image(0)[:24, :32], REGISTERED_CAM, "rgb8")
        w.write_image(
            "/camera/depth/image_raw", "/other/info", T0, depth_image(0), DEPTH_CAM, "16UC1"
        )
    for streams in (
        (StreamSpec("colour"), StreamSpec("depth")),
        (StreamSpec("depth", multiple=True),),
    ):
        with pytest.raises(TopicError, match="no CameraInfo for this image topic"):
            open_recording(path, streams=streams)


def test_streams_that_pair_on_no_common_frame(tmp_path: Path) -> None:
    # Depth pairs with the first two colour frames only, thermal with the last two only.
    path = tmp_path / "apart.mcap"
    with RecordingWriter(path, "mcap") as w:
        for i in range(4):
            s = T0 + i * 200_000_000
            put(w, "/camera/rgb/image_color", s, rgb_image(i), RGB_CAM, "rgb8")
            if i < 2:
                put(w, "/camera/depth/image_raw", s + 1_000_000, depth_image(i), DEPTH_CAM, "16UC1")
            else:
                put(w, "/thermal/image_raw", s + 1_000_000, thermal_image(i), THERMAL_CAM, "mono16")
    streams = (StreamSpec("colour"), StreamSpec("depth"), StreamSpec("thermal"))
    with pytest.raises(SyncError, match="no frame has every stream within the sync gap"):
        open_recording(path, streams=streams)
    rec = open_recording(path, streams=streams, unpaired_ok=True)
    assert len(rec) == 0
    (problem,) = rec.info.sync.problems
    assert problem.role is None and "no frame has every stream" in problem.message


def test_no_pair_suggests_the_gap_that_pairs_the_most(tmp_path: Path) -> None:
    # Colour runs for a second at 10 Hz; depth only for its last four tenths, 40 ms late.
    # Every depth image pairs within 40 ms; the first colour image is 640 ms from any depth.
    path = tmp_path / "late_depth.mcap"
    ms = 1_000_000
    with RecordingWriter(path, "mcap") as w:
        for i in range(10):
            put(w, "/camera/rgb/image_color", T0 + i * 100 * ms, rgb_image(i), RGB_CAM, "rgb8")
            if i >= 6:
                depth = depth_image(i)
                put(
                    w,
                    "/camera/depth/image_raw",
                    T0 + (i * 100 + 40) * ms,
                    depth,
                    DEPTH_CAM,
                    "16UC1",
                )
    with pytest.raises(
        SyncError,
        match=r"within 40\.0 ms: accept them with --set io\.max_sync_gap_ms=41 \(pairs 4 of 10",
    ):
        open_recording(path)
    (problem,) = open_recording(path, unpaired_ok=True).info.sync.problems
    assert (problem.smallest_gap_ms, problem.needed_gap_ms, problem.pairs_accepted) == (
        40.0,
        40.0,
        4,
    )
    assert len(open_recording(path, IoConfig(max_sync_gap_ms=41)).frame_stamps) == 4
