"""Each kind of bad input gets one clear line naming file/topic, and its documented exit code."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from rgbd_eval.cli.main import app
from rgbd_eval.io.images import encode_color_raw
from rgbd_eval.io.writer import RecordingWriter, StreamOptions

from .conftest import DEPTH_CAM, RGB_CAM, T0, Spec, depth_image, rgb_image

runner = CliRunner()


def inspect(path: Path, *args: str) -> tuple[int, str]:
    result = runner.invoke(app, ["inspect", str(path), *args])
    return result.exit_code, result.output


def assert_one_line_error(output: str, *fragments: str) -> None:
    lines = [line for line in output.splitlines() if line.strip()]
    assert len(lines) == 1, output
    assert lines[0].startswith("error: ")
    assert "Traceback" not in output
    for fragment in fragments:
        assert fragment in lines[0], (fragment, lines[0])


def test_missing_file(tmp_path: Path) -> None:
    code, out = inspect(tmp_path / "nope.bag")
    assert code == 3
    assert_one_line_error(out, "nope.bag", "no such file")


def test_unsupported_file_type(tmp_path: Path) -> None:
    path = tmp_path / "data.txt"
    path.write_text("hello")
    code, out = inspect(path)
    assert code == 3
    assert_one_line_error(out, "data.txt", "unsupported file type")


@pytest.mark.parametrize("container", ["ros1", "mcap"])
def test_truncated(make_recording: Callable[..., Path], container: str) -> None:
    path = make_recording(container, Spec(n=4))
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    code, out = inspect(path)
    assert code == 3
    assert_one_line_error(out, path.name, "cannot read recording")


@pytest.mark.parametrize("container", ["ros1", "mcap"])
def test_empty(tmp_path: Path, container: str) -> None:
    path = tmp_path / ("empty.bag" if container == "ros1" else "empty.mcap")
    with RecordingWriter(path, container):  # type: ignore[arg-type]
        pass
    code, out = inspect(path)
    assert code == 3
    assert_one_line_error(out, path.name, "empty")


def test_no_depth_topic(tmp_path: Path) -> None:
    path = tmp_path / "rgb_only.mcap"
    with RecordingWriter(path, "mcap") as w:
        w.write_rgb(T0, rgb_image(0), RGB_CAM)
    code, out = inspect(path, "--method", "basso2012")
    assert code == 3
    assert_one_line_error(out, "rgb_only.mcap", "no depth image topic found", "--topic depth=/name")
    code, out = inspect(path)  # without a method, inspect shows whatever streams there are
    assert code == 0, out
    assert "colour" in out


def test_several_rgb_topics_are_listed(make_recording: Callable[..., Path]) -> None:
    path = make_recording("mcap", Spec(n=2))
    # Add a second RGB stream by writing a copy with an extra topic.
    extra = path.with_name("two_rgb.mcap")
    with RecordingWriter(extra, "mcap") as w:
        for i in range(2):
            w.write_rgb(T0 + i, rgb_image(i), RGB_CAM)
            w.write_depth(T0 + i, depth_image(i), DEPTH_CAM)
            msg = w._t("sensor_msgs/msg/Image")(
                header=w.header(T0 + i, "cam2"), **encode_color_raw(rgb_image(i))
            )
            w.write_message("/camera2/image_color", "sensor_msgs/msg/Image", T0 + i, msg)
    code, out = inspect(extra)
    assert code == 3
    assert_one_line_error(
        out,
        "several colour image topics",
        "/camera/rgb/image_color",
        "/camera2/image_color",
        "--topic colour=/name",
    )
    code, out = inspect(extra, "--topic", "colour=/camera/rgb/image_color")
    assert code == 0, out


def test_unsupported_encoding(tmp_path: Path) -> None:
    path = tmp_path / "yuv.mcap"
    with RecordingWriter(path, "mcap") as w:
        img = np.zeros((RGB_CAM.height, RGB_CAM.width * 2), np.uint8)
        msg = w._t("sensor_msgs/msg/Image")(
            header=w.header(T0, RGB_CAM.frame_id),
            height=RGB_CAM.height,
            width=RGB_CAM.width,
            encoding="yuv422",
            is_bigendian=0,
            step=RGB_CAM.width * 2,
            data=img.reshape(-1),
        )
        w.write_message("/camera/rgb/image_color", "sensor_msgs/msg/Image", T0, msg)
        w.write_message(
            "/camera/rgb/camera_info",
            "sensor_msgs/msg/CameraInfo",
            T0,
            w.camera_info(T0, RGB_CAM, "x"),
        )
        w.write_depth(T0, depth_image(0), DEPTH_CAM)
    code, out = inspect(path)
    assert code == 3
    assert_one_line_error(out, "yuv.mcap", "[/camera/rgb/image_color]", "'yuv422'")


def test_size_disagrees_with_camera_info(tmp_path: Path) -> None:
    # The depth CameraInfo claims 40x30 while the depth image is 32x24.
    wrong = type(DEPTH_CAM)(40, 30, 26.0, 26.0, 19.5, 14.5, frame_id=DEPTH_CAM.frame_id)
    path = tmp_path / "size.mcap"
    with RecordingWriter(path, "mcap") as w:
        w.write_rgb(T0, rgb_image(0), RGB_CAM)
        w.write_message(
            "/camera/depth/camera_info",
            "sensor_msgs/msg/CameraInfo",
            T0,
            w.camera_info(T0, wrong, "x"),
        )
        w.write_depth(T0, depth_image(0), DEPTH_CAM)
    code, out = inspect(path)
    assert code == 3
    assert_one_line_error(out, "size.mcap", "image is 32x24 but its CameraInfo", "40x30")


def test_non_monotonic_stamps(tmp_path: Path) -> None:
    # Log times increase, but the third header stamp goes back in time.
    headers = [T0, T0 + 33_000_000, T0 + 20_000_000, T0 + 66_000_000]
    path = tmp_path / "backwards.bag"
    with RecordingWriter(path, "ros1") as w:
        for i, stamp in enumerate(headers):
            log = T0 + i * 33_000_000
            img = encode_color_raw(rgb_image(i))
            msg = w._t("sensor_msgs/msg/Image")(header=w.header(stamp, RGB_CAM.frame_id), **img)
            w.write_message("/camera/rgb/image_color", "sensor_msgs/msg/Image", log, msg)
            w.write_message(
                "/camera/rgb/camera_info",
                "sensor_msgs/msg/CameraInfo",
                log,
                w.camera_info(log, RGB_CAM, "x"),
            )
            w.write_depth(log, depth_image(i), DEPTH_CAM)
    code, out = inspect(path)
    assert code == 3
    assert_one_line_error(out, "[/camera/rgb/image_color]", "not increasing at message 2")


def test_broken_tf_chain(make_recording: Callable[..., Path]) -> None:
    path = make_recording("mcap", Spec(n=2, camera_tf=False))
    code, out = inspect(path)
    assert code == 3
    assert_one_line_error(out, "broken tf chain", "'odom'", "'camera_depth_optical_frame'")


def test_bad_option_value_is_a_config_error(make_recording: Callable[..., Path]) -> None:
    path = make_recording("mcap", Spec(n=2))
    code, out = inspect(path, "--set", "io.max_sync_gap_ms=-5")
    assert code == 4
    assert_one_line_error(out, "--set io.max_sync_gap_ms=-5", "max_sync_gap_ms")
    code, out = inspect(path, "--topic", "sonar=/x")
    assert code == 4
    assert_one_line_error(out, "unknown topic role 'sonar'")


def test_compressed_rgb_garbage(tmp_path: Path) -> None:
    path = tmp_path / "garbage.mcap"
    with RecordingWriter(path, "mcap", StreamOptions(rgb_format="jpeg")) as w:
        msg = w._t("sensor_msgs/msg/CompressedImage")(
            header=w.header(T0, RGB_CAM.frame_id),
            format="jpeg",
            data=np.frombuffer(b"notajpeg", np.uint8),
        )
        w.write_message(
            "/camera/rgb/image_color/compressed", "sensor_msgs/msg/CompressedImage", T0, msg
        )
        w.write_message(
            "/camera/rgb/camera_info",
            "sensor_msgs/msg/CameraInfo",
            T0,
            w.camera_info(T0, RGB_CAM, "x"),
        )
        w.write_depth(T0, depth_image(0), DEPTH_CAM)
    code, out = inspect(path)
    assert code == 3
    assert_one_line_error(out, "[/camera/rgb/image_color/compressed]", "could not be decoded")


def test_inspect_reports_colour_and_depth_that_do_not_pair(
    make_recording: Callable[..., Path],
) -> None:
    # A robot's snapshot recording: one colour/depth pair a second, 113 to 336 ms apart.
    rgb = [T0 + i * 1_000_000_000 for i in range(4)]
    offsets_ms = (113, 336, 200, 150)
    depth = [s + ms * 1_000_000 for s, ms in zip(rgb, offsets_ms, strict=True)]
    path = make_recording("mcap", Spec(rgb_stamps=rgb, depth_stamps=depth))
    assert runner.invoke(app, ["run", str(path), "--out", str(path.parent / "out")]).exit_code == 3

    code, out = inspect(path)
    assert code == 0, out
    assert "Traceback" not in out
    for shown in ("/camera/rgb/image_color", "/camera/depth/image_raw", "colour camera: 64x48"):
        assert shown in out, shown
    lines = [line for line in out.splitlines() if "do not pair" in line]
    assert len(lines) == 1, out
    for fragment in ("colour", "depth", "113.0", "336.0", "--set io.max_sync_gap_ms=337", "4 of 4"):
        assert fragment in lines[0], (fragment, lines[0])

    result = runner.invoke(app, ["inspect", str(path), "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    rec = data["recording"]
    assert rec["num_frames"] == 0
    assert rec["cameras"]["depth"]["width"] == 32
    assert {t["name"] for t in rec["topics"]} >= {
        "/camera/rgb/image_color",
        "/camera/depth/image_raw",
    }
    (problem,) = rec["sync"]["problems"]
    assert problem["role"] == "depth"
    assert problem["smallest_gap_ms"] == pytest.approx(113.0)
    assert problem["needed_gap_ms"] == pytest.approx(336.0)
    assert problem["option"] == "io.max_sync_gap_ms"
    assert problem["accept_with"] == "--set io.max_sync_gap_ms=337"
    assert problem["pairs_accepted"] == 4
    assert "do not pair" in problem["message"]

    # With the option the recording pairs, and inspect reports no problem.
    result = runner.invoke(app, ["inspect", str(path), "--json", "--set", "io.max_sync_gap_ms=337"])
    assert result.exit_code == 0, result.output
    rec = json.loads(result.stdout)["recording"]
    assert rec["num_frames"] == 4 and rec["sync"]["problems"] == []
