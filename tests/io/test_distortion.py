"""CameraInfo distortion through the reader: models, ROS1/ROS2 field names, warnings, rectified.

Recordings are written with the real writers and read back; OpenCV is the reference.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import cv2
import numpy as np
import pytest

from rgbd_eval.config import load_config
from rgbd_eval.detect.cloud import depth_to_cloud
from rgbd_eval.io.decode import camera_model_from_info
from rgbd_eval.io.recording import open_recording
from rgbd_eval.io.writer import Container, RecordingWriter
from rgbd_eval.pipeline import run_sequence
from rgbd_eval.report.run import sequence_record
from rgbd_eval.types import CameraModel

from .conftest import PERIOD, T0

FRAME = "head_rgbd_sensor_rgb_frame"
#: A head camera calibrated with ROS' camera_calibration (plumb_bob), at 160x120: the rays
#: of its corner pixels are about 20 px from the pinhole model's (at 640x480, 80 px).
PLUMB_BOB = CameraModel(
    160, 120, 134.0, 134.0, 80.3, 59.6, (-0.28, 0.09, 0.0012, -0.0008, 0.0), FRAME
)
#: ROS1 writes ``D``/``K``/``P``, ROS2 (mcap) ``d``/``k``/``p``.
CONTAINERS: dict[str, Container] = {"rec.bag": "ros1", "rec.mcap": "mcap"}


def _write(
    path: Path, colour: CameraModel, depth: CameraModel, prefix: str = "/camera", n: int = 2
) -> Path:
    """``n`` frames: a grey colour image and a wall 2 m ahead on a 16UC1 depth image."""
    with RecordingWriter(path, CONTAINERS[path.name]) as w:
        for i in range(n):
            s = T0 + i * PERIOD
            grey = np.full((colour.height, colour.width, 3), 128, np.uint8)
            w.write_image(
                f"{prefix}/rgb/image_raw", f"{prefix}/rgb/camera_info", s, grey, colour, "rgb8"
            )
            wall = np.full((depth.height, depth.width), 2.0, np.float32)
            w.write_image(
                f"{prefix}/depth/image_raw", f"{prefix}/depth/camera_info", s, wall, depth, "16UC1"
            )
    return path


@pytest.mark.parametrize("name", sorted(CONTAINERS))
def test_a_plumb_bob_camera_info_gives_distortion_aware_clouds(tmp_path: Path, name: str) -> None:
    rec = open_recording(_write(tmp_path / name, PLUMB_BOB, PLUMB_BOB))
    cam = rec.info.depth_camera
    assert cam is not None and cam == PLUMB_BOB  # model and coefficients kept
    assert not any("distortion" in w for w in rec.info.warnings)
    frame = next(iter(rec.frames()))
    cloud = depth_to_cloud(frame.depth, frame.depth_camera.rays(), 10.0)
    assert cloud.points.shape == (160 * 120, 3) and np.all(cloud.points[:, 2] == 2.0)
    # Each point lies on the ray OpenCV finds for its pixel (iterated to convergence).
    v, u = np.divmod(cloud.pixels, 160)
    px = np.stack([u, v], axis=1).astype(np.float64)[:, None, :]
    criteria = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 100, 1e-14)
    ref = cv2.undistortPointsIter(px, cam.K, np.array(cam.distortion), None, None, criteria)
    np.testing.assert_allclose(cloud.points[:, :2], 2.0 * ref[:, 0, :], rtol=0, atol=1e-9)
    # The corner's point is far from where the pinhole model puts it: 20 px (0.30 m at 2 m).
    pinhole = np.array([(0 - cam.cx) / cam.fx, (0 - cam.cy) / cam.fy]) * 2.0
    assert np.linalg.norm(cloud.points[0, :2] - pinhole) * cam.fx / 2.0 > 19.0
    # Projection (boxes, overlays) applies the lens: each point lands on its own pixel.
    np.testing.assert_allclose(cam.project(cloud.points), px[:, 0, :], rtol=0, atol=1e-9)


@pytest.mark.parametrize("name", sorted(CONTAINERS))
def test_an_unknown_distortion_model_is_named_once_per_camera(tmp_path: Path, name: str) -> None:
    custom = replace(
        PLUMB_BOB, distortion=(0.1, 0.02, 0.0, 0.0), distortion_model="kannala_brandt_custom"
    )
    rec = open_recording(_write(tmp_path / name, custom, PLUMB_BOB, n=2))
    named = [w for w in rec.info.warnings if "kannala_brandt_custom" in w]
    assert named == [
        "/camera/rgb/camera_info: distortion model 'kannala_brandt_custom' is not supported "
        "(only plumb_bob, rational_polynomial, equidistant): its coefficients "
        "(0.1, 0.02, 0, 0) are ignored"
    ]
    colour = rec.info.rgb_camera
    assert colour is not None and colour.lens is None  # taken as undistorted
    assert rec.info.depth_camera is not None and rec.info.depth_camera.lens is not None


def test_the_distortion_warning_reaches_the_report(tmp_path: Path) -> None:
    custom = replace(
        PLUMB_BOB, distortion=(0.1, 0.02, 0.0, 0.0), distortion_model="kannala_brandt_custom"
    )
    path = _write(tmp_path / "rec.mcap", custom, custom)
    result = run_sequence(path, load_config(method="basso2012"))
    record = sequence_record(result, "digest")
    named = [w for w in record["warnings"] if "kannala_brandt_custom" in w]
    # colour and depth: two cameras with a CameraInfo each
    assert [w.split(":")[0] for w in named] == [
        "/camera/rgb/camera_info",
        "/camera/depth/camera_info",
    ]


@pytest.mark.parametrize("name", sorted(CONTAINERS))
def test_equidistant_round_trips_through_camera_info(tmp_path: Path, name: str) -> None:
    fisheye = CameraModel(
        848, 800, 286.0, 286.2, 421.7, 402.3, (-0.0074, 0.0436, -0.0413, 0.0077), "fisheye_optical",
        distortion_model="equidistant",
    )  # fmt: skip
    with RecordingWriter(tmp_path / name, CONTAINERS[name]) as w:
        back = camera_model_from_info(w.camera_info(0, fisheye, "/fisheye/camera_info"))
    assert back == fisheye and back.lens is not None and back.lens.fisheye


def test_a_rectified_topic_takes_p_and_no_distortion(tmp_path: Path) -> None:
    """image_proc's image_rect topics share the raw image's CameraInfo: K and D are the raw
    camera's, the rectified image follows P and has no distortion left."""
    path = tmp_path / "rect.bag"
    with RecordingWriter(path, "ros1") as w:
        for i in range(2):
            s = T0 + i * PERIOD
            grey = np.full((120, 160, 3), 128, np.uint8)
            wall = np.full((120, 160), 2.0, np.float32)
            w.write_image(
                "/hsrb/rgb/image_rect_color", "/hsrb/rgb/camera_info", s, grey, PLUMB_BOB, "rgb8"
            )
            w.write_image(
                "/hsrb/depth_registered/image_rect_raw", "/hsrb/depth_registered/camera_info", s,
                wall, PLUMB_BOB, "16UC1",
            )  # fmt: skip
    rec = open_recording(path)
    cam = rec.info.rgb_camera
    assert cam is not None and cam.distortion == () and cam.lens is None
    assert (cam.fx, cam.cx, cam.cy) == (PLUMB_BOB.fx, PLUMB_BOB.cx, PLUMB_BOB.cy)  # P = K here
    assert (
        "/hsrb/rgb/image_rect_color is rectified: the plumb_bob distortion in "
        "/hsrb/rgb/camera_info describes the raw image and is not applied "
        "(intrinsics from its P, where set)"
    ) in rec.info.warnings
    # P's intrinsics (camera_calibration's new camera matrix) where they differ from K.
    with RecordingWriter(tmp_path / "p.bag", "ros1") as w:
        msg = w.camera_info(0, PLUMB_BOB, "/hsrb/rgb/camera_info")
    P = np.array([120.0, 0, 79.0, 0, 0, 121.0, 58.5, 0, 0, 0, 1, 0])
    rect = camera_model_from_info(replace(msg, P=P), rectified=True)
    assert (rect.fx, rect.fy, rect.cx, rect.cy, rect.distortion) == (120.0, 121.0, 79.0, 58.5, ())
    raw = camera_model_from_info(replace(msg, P=P))
    assert raw == PLUMB_BOB
    unset = camera_model_from_info(replace(msg, P=np.zeros(12)), rectified=True)
    assert unset == replace(PLUMB_BOB, distortion=())  # K, and still no distortion
