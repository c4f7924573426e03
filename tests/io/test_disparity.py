"""stereo_msgs/DisparityImage as satake2009's depth instead of a stereo pair (seed 002, 2.4 step 1)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rgbd_eval.detect import stereo
from rgbd_eval.errors import DecodeError
from rgbd_eval.io.images import encode_depth_raw
from rgbd_eval.io.messages import DISPARITY_TYPE, IMAGE_TYPE
from rgbd_eval.io.recording import open_recording
from rgbd_eval.io.writer import RecordingWriter
from rgbd_eval.methods.satake2009 import search as search

from .conftest import PERIOD, RGB_CAM, T0, rgb_image

LEFT = RGB_CAM  # 64 x 48, fx = 52.5 px
BASELINE = 0.12


def _disparity(i: int) -> np.ndarray:
    """A wall at 3 m (d = 52.5 * 0.12 / 3 = 2.1 px), a 1.5 m box (4.2 px), no match, too small."""
    d = np.full((LEFT.height, LEFT.width), 2.1, np.float32)
    d[10:20, 10:20] = 4.2
    d[0, :4] = 0.0  # no disparity
    d[1, :4] = 0.3  # below min_disparity = 0.5
    return d


def _write(path: Path, container: str = "mcap", f: float = 52.5) -> Path:
    with RecordingWriter(path, container) as w:  # type: ignore[arg-type]
        t_img, t_disp = w.store.types[IMAGE_TYPE], w.store.types[DISPARITY_TYPE]
        roi = w.store.types["sensor_msgs/msg/RegionOfInterest"](
            x_offset=0, y_offset=0, height=0, width=0, do_rectify=False
        )
        for i in range(3):
            s = T0 + i * PERIOD
            w.write_image("/stereo/left/image_rect", "/stereo/left/camera_info", s,
                          rgb_image(i), LEFT, "rgb8")  # fmt: skip
            image = t_img(header=w.header(s, LEFT.frame_id, "/stereo/disparity"),
                          **encode_depth_raw(_disparity(i), "32FC1"))  # fmt: skip
            baseline = {"T" if w.ros_version == 1 else "t": BASELINE}  # ROS1 T, ROS2 t
            msg = t_disp(
                header=w.header(s, LEFT.frame_id, "/stereo/disparity"), image=image, f=f,
                valid_window=roi, min_disparity=0.5, max_disparity=64.0, delta_d=0.0625,
                **baseline,
            )  # fmt: skip
            w.write_message("/stereo/disparity", DISPARITY_TYPE, s, msg)
    return path


@pytest.mark.parametrize("container", ["mcap", "ros1"])
def test_a_disparity_image_becomes_the_left_views_depth(tmp_path: Path, container: str) -> None:
    path = _write(tmp_path / ("d.bag" if container == "ros1" else "d.mcap"), container)
    rec = open_recording(path, streams=search.STREAMS)
    assert rec.info.selected.streams == {
        "left": "/stereo/left/image_rect",
        "disparity": "/stereo/disparity",
    }
    frames = list(rec.frames())
    assert len(frames) == 3
    f = frames[0]
    assert f.stream("disparity").camera == LEFT  # in the left camera's frame
    # Z = f T / d: 52.5 * 0.12 / 2.1 = 3.0 m, / 4.2 = 1.5 m; d = 0 and d = 0.3 < 0.5: none
    depth = f.stream("disparity").image
    assert depth[30, 40] == pytest.approx(3.0)
    assert depth[15, 15] == pytest.approx(1.5)
    assert np.isnan(depth[0, :4]).all() and np.isnan(depth[1, :4]).all()
    # satake2009 takes it instead of SGBM, at its processed size (here 32 x 24)
    sd = search.frame_depth(f, (32, 24), stereo.SgbmParams())
    assert sd.depth.shape == (24, 32) and sd.camera == LEFT.scaled(32, 24)
    assert sd.depth[15, 20] == pytest.approx(3.0)


def test_a_bad_disparity_message_is_a_decode_error(tmp_path: Path) -> None:
    rec = open_recording(_write(tmp_path / "bad.mcap", f=0.0), streams=search.STREAMS)
    with pytest.raises(
        DecodeError,
        match=r"\[/stereo/disparity\]: DisparityImage has f=0, T=0.12: both must be > 0",
    ):
        list(rec.frames())


def test_neither_right_image_nor_disparity(tmp_path: Path) -> None:
    path = tmp_path / "left_only.mcap"
    with RecordingWriter(path, "mcap") as w:
        w.write_image("/stereo/left/image_rect", "/stereo/left/camera_info", T0, rgb_image(0),
                      LEFT, "rgb8")  # fmt: skip
    frame = next(iter(open_recording(path, streams=search.STREAMS).frames()))
    with pytest.raises(ValueError, match="no right image and no DisparityImage"):
        search.frame_depth(frame, (32, 24), stereo.SgbmParams())
