"""Round trips through every container and encoding, read back with the project's reader."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from rgbd_eval.io import recording as reader
from rgbd_eval.io.images import depth_to_mm
from rgbd_eval.io.recording import open_recording
from rgbd_eval.io.writer import StreamOptions
from rgbd_eval.types import OPTICAL_TO_BODY

from .conftest import (
    BASE_TO_CAMERA,
    DEPTH_CAM,
    DEPTH_OFFSET,
    PERIOD,
    RGB_CAM,
    T0,
    Spec,
    depth_image,
    odom_pose,
    rgb_image,
)

CONTAINERS = ["ros1", "mcap", "ros2-sqlite3", "ros2-mcap"]


@pytest.mark.parametrize("container", CONTAINERS)
def test_round_trip_pixels_and_poses(make_recording: Callable[..., Path], container: str) -> None:
    path = make_recording(container, Spec(options=StreamOptions(depth_encoding="32FC1")))
    rec = open_recording(path)
    assert len(rec) == 5
    assert rec.info.has_odometry
    assert rec.info.world_frame == "odom"
    assert rec.info.tf_chain == ("odom", "base_link", "camera_link", "camera_depth_optical_frame")
    assert rec.info.rgb_camera == RGB_CAM
    assert rec.info.depth_camera == DEPTH_CAM
    frames = list(rec.frames())
    assert [f.index for f in frames] == list(range(5))
    for i, f in enumerate(frames):
        assert f.stamp_ns == T0 + i * PERIOD
        np.testing.assert_array_equal(f.rgb, rgb_image(i))
        np.testing.assert_array_equal(f.depth, depth_image(i))  # NaN positions equal too
        # world_T_depth = odom_T_base(t) * base_T_camera * camera_T_depth, odometry interpolated.
        expected = odom_pose(f.stamp_ns).compose(BASE_TO_CAMERA).compose(DEPTH_OFFSET)
        np.testing.assert_allclose(f.camera_pose.matrix(), expected.matrix(), atol=1e-9)
        # rgb_T_depth = (camera_T_rgb)^-1 camera_T_depth: a 2.5 cm shift along optical x... (-y body)
        np.testing.assert_allclose(
            f.depth_to_rgb.matrix(),
            OPTICAL_TO_BODY.inverse().compose(DEPTH_OFFSET).matrix(),
            atol=1e-12,
        )
    gt = rec.ground_truth_topic
    assert gt is not None and gt.num_objects == 5
    assert gt.frames[2][2][0].world_xyz == (2.0, 0.2, 0.9)


@pytest.mark.parametrize("compression", ["none", "lz4", "bz2"])
def test_ros1_chunk_compression(make_recording: Callable[..., Path], compression: str) -> None:
    spec = Spec(n=3, options=StreamOptions(ros1_compression=compression))  # type: ignore[arg-type]
    rec = open_recording(make_recording("ros1", spec))
    frames = list(rec.frames())
    np.testing.assert_array_equal(frames[1].rgb, rgb_image(1))
    # 16UC1 stores millimetres: the round trip is exact to the millimetre.
    mm = depth_to_mm(depth_image(1)).astype(np.float32) * np.float32(0.001)
    mm[mm == 0] = np.nan
    np.testing.assert_array_equal(frames[1].depth, mm)


@pytest.mark.parametrize("container", ["ros1", "mcap"])
@pytest.mark.parametrize("encoding", ["16UC1", "32FC1"])
def test_compressed_images(
    make_recording: Callable[..., Path], container: str, encoding: str
) -> None:
    options = StreamOptions(rgb_format="jpeg", depth_encoding=encoding, depth_compressed=True)  # type: ignore[arg-type]
    rec = open_recording(make_recording(container, Spec(n=2, options=options)))
    assert rec.info.selected.rgb.endswith("/compressed")
    assert rec.info.selected.depth.endswith("/compressedDepth")
    f = next(iter(rec.frames()))
    # jpeg is lossy, but the ramps survive: a channel swap would be off by ~100 on average.
    assert np.abs(f.rgb.astype(int) - rgb_image(0).astype(int)).mean() < 8
    truth = depth_image(0)
    assert np.array_equal(np.isnan(f.depth), np.isnan(truth))
    valid = ~np.isnan(truth)
    # 16UC1: 0.5 mm rounding. 32FC1: inverse-depth quantisation, step A/q^2 ~ d^2/A (< 6 mm at 7.5 m).
    tol = 0.0005 + 1e-6 if encoding == "16UC1" else 0.006
    assert np.max(np.abs(f.depth[valid] - truth[valid])) <= tol


def test_lone_db3_and_folder(make_recording: Callable[..., Path]) -> None:
    folder = make_recording("ros2-sqlite3", Spec(n=2))
    db3 = next(folder.glob("*.db3"))
    assert open_recording(folder).info.container == "ros2"
    rec = open_recording(db3)
    assert rec.info.container == "db3"
    assert len(list(rec.frames())) == 2


def test_without_odometry_uses_camera_frame(make_recording: Callable[..., Path]) -> None:
    rec = open_recording(make_recording("mcap", Spec(n=2, odometry=False)))
    assert not rec.info.has_odometry
    assert any("no odometry" in w for w in rec.info.warnings)
    f = next(iter(rec.frames()))
    assert f.camera_pose == OPTICAL_TO_BODY
    assert not f.has_odometry


def test_sync_drops_and_counts_unpaired(make_recording: Callable[..., Path]) -> None:
    rgb = [T0 + i * PERIOD for i in range(6)]
    # depth for frames 0, 1, 3, 5 (+1 ms), plus one far from any RGB stamp.
    depth = [
        rgb[0] + 1_000_000,
        rgb[1] + 1_000_000,
        rgb[3] + 1_000_000,
        rgb[5] - 1_000_000,
        rgb[5] + 15_000_000,
    ]
    spec = Spec(rgb_stamps=rgb, depth_stamps=depth, ground_truth=False)
    # the writer writes pairs; write unequal streams by padding rgb with the last stamps
    spec.rgb_stamps = rgb[:5]
    spec.depth_stamps = depth
    rec = open_recording(make_recording("mcap", spec))
    s = rec.info.sync
    # rgb 0,1,3 pair (1 ms); rgb 4 (t0+133ms) and depth t0+166ms-1ms: 32.3 ms > 20 ms -> unpaired.
    assert s.frames == 3 and s.reference == "colour"
    assert [(x.role, x.dropped) for x in s.streams] == [("colour", 2), ("depth", 2)]
    assert s.worst_gap_ms == pytest.approx(1.0)
    assert [f.stamp_ns for f in rec.frames()] == [rgb[0], rgb[1], rgb[3]]


@pytest.mark.parametrize(
    ("container", "suffix"), [("ros2-sqlite3", ".db3"), ("ros2-mcap", ".mcap")]
)
def test_ros2_folder_keeps_no_temporary_names(
    make_recording: Callable[..., Path], container: str, suffix: str
) -> None:
    # The folder is written under a temporary name and renamed; its storage file and
    # metadata.yaml must carry the recording's name, as `ros2 bag` would write them.
    path = make_recording(container, Spec())
    assert sorted(p.name for p in path.iterdir()) == sorted(["metadata.yaml", path.name + suffix])
    assert ".tmp-" not in (path / "metadata.yaml").read_text()
    assert len(open_recording(path)) == 5


@pytest.mark.parametrize("container", CONTAINERS)
def test_a_late_frame_range_reads_from_its_first_message_on(
    make_recording: Callable[..., Path], container: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    rec = open_recording(make_recording(container, Spec(n=12)))
    whole = list(rec.frames())
    read: list[str] = []  # the topics of the messages the frame pass is handed
    opened = reader.open_source

    def counting(path: Path) -> Any:
        src = opened(path)
        messages = src.messages

        def counted(topics: set[str], start_ns: int | None = None) -> Any:
            for item in messages(topics, start_ns):
                read.append(item[0])
                yield item

        src.messages = counted  # type: ignore[method-assign]
        return src

    monkeypatch.setattr(reader, "open_source", counting)
    late = list(rec.frames(8, 12))
    assert [f.index for f in late] == [8, 9, 10, 11]
    for a, b in zip(whole[8:], late, strict=True):
        assert a.stamp_ns == b.stamp_ns and a.camera_pose == b.camera_pose
        assert np.array_equal(a.depth, b.depth, equal_nan=True)
        assert np.array_equal(a.rgb, b.rgb)
    # 4 frames of 2 images each: the 16 messages of frames 0-7 were not read.
    assert len(read) == 8


def test_a_frame_range_reads_from_the_start_when_log_times_are_out_of_order(
    make_recording: Callable[..., Path],
) -> None:
    rec = open_recording(make_recording("mcap", Spec(n=6)))
    whole = list(rec.frames())
    depth_topic = rec.info.selected.streams["depth"]
    times = rec._log_ns[depth_topic].copy()
    times[[0, 1]] = times[[1, 0]]  # as a reader handing messages in file order might
    rec._log_ns[depth_topic] = times
    late = list(rec.frames(3, 6))
    assert [f.index for f in late] == [3, 4, 5]
    for a, b in zip(whole[3:], late, strict=True):
        assert np.array_equal(a.depth, b.depth, equal_nan=True)
