"""DMT-BS one-time calibration (seed 003, section 3): floor plane and camera transforms."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest

from rgbd_eval.detect.calibration import (
    floor_frame,
    floor_from_depth,
    load_calibration,
    plane_in_world,
    world_floor_frame,
)
from rgbd_eval.errors import ConfigError
from rgbd_eval.types import OPTICAL_TO_BODY, CameraModel, Pose

CAM = CameraModel(64, 48, 50.0, 50.0, 31.5, 23.5, frame_id="cam0")


def _pitched_camera(height: float, pitch_deg: float) -> Pose:
    """world_T_optical of a camera ``height`` above z = 0, looking along +x, pitched down."""
    p = math.radians(pitch_deg)
    T = np.eye(4)
    T[:3, :3] = [[math.cos(p), 0, math.sin(p)], [0, 1, 0], [-math.sin(p), 0, math.cos(p)]]
    T[:3, 3] = (0.0, 0.0, height)
    return Pose.from_matrix(T).compose(OPTICAL_TO_BODY)


def _floor_depth(pose: Pose) -> np.ndarray:
    """Exact depth of the floor z = 0 seen by CAM at ``pose`` (NaN where the ray misses it)."""
    rays = CAM.rays().reshape(-1, 3)
    down = rays @ pose.rotation_matrix().T  # world directions (per unit optical z)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = -pose.translation[2] / down[:, 2]
    t[~(t > 0)] = np.nan
    return t.reshape(CAM.height, CAM.width).astype(np.float32)


def test_floor_of_the_world_is_the_identity() -> None:
    np.testing.assert_allclose(
        world_floor_frame(np.array([0.0, 0.0, 1.0, 0.0])).matrix(), np.eye(4)
    )
    # A floor 0.2 m below z = 0 (z = -0.2: 0 x + 0 y + 1 z + 0.2 = 0): heights rise by 0.2.
    shifted = world_floor_frame(np.array([0.0, 0.0, 1.0, 0.2]))
    np.testing.assert_allclose(
        shifted.transform_points(np.array([[1.0, 2.0, 0.0]])), [[1.0, 2.0, 0.2]]
    )


def test_floor_found_in_the_first_depth_image() -> None:
    pose = _pitched_camera(2.0, 30.0)
    depth = _floor_depth(pose)
    up = pose.rotation_matrix().T @ np.array([0.0, 0.0, 1.0])
    plane = floor_from_depth(depth, CAM, up, inlier_band_m=0.02, max_tilt_deg=30.0)
    # The camera is 2 m above the floor; the normal is the world's up seen from the camera.
    assert plane[3] == pytest.approx(2.0, abs=1e-6)
    np.testing.assert_allclose(plane[:3], up, atol=1e-6)
    # floor_T_optical: floor points get height 0, the camera centre height 2.
    floor_T_optical = floor_frame(plane, np.array([0.0, 0.0, 1.0]))
    pts = CAM.backproject(depth)[::8, ::8].reshape(-1, 3)
    pts = pts[np.isfinite(pts).all(axis=1)]
    np.testing.assert_allclose(floor_T_optical.transform_points(pts)[:, 2], 0.0, atol=1e-6)
    np.testing.assert_allclose(floor_T_optical.transform_points(np.zeros((1, 3))), [[0, 0, 2.0]])
    # Expressed in the world, the plane is z = 0 again.
    np.testing.assert_allclose(plane_in_world(plane, pose), [0.0, 0.0, 1.0, 0.0], atol=1e-6)


def test_no_floor_in_view_is_an_error() -> None:
    pose = _pitched_camera(2.0, -30.0)  # looking up: no ray reaches the floor
    depth = _floor_depth(pose)
    up = pose.rotation_matrix().T @ np.array([0.0, 0.0, 1.0])
    with pytest.raises(ValueError, match="no floor plane"):
        floor_from_depth(depth, CAM, up, 0.02, 30.0)


def test_calibration_file_round_trip(tmp_path: Path) -> None:
    pose = _pitched_camera(2.6, 25.0)
    path = tmp_path / "calib.yaml"
    path.write_text(
        "cameras:\n"
        f"  cam0: {{translation: {list(pose.translation)}, rotation: {list(pose.rotation)}}}\n"
        "floor: [0, 0, 1, 0.1]\n"
    )
    calib = load_calibration(path)
    np.testing.assert_allclose(calib.pose("cam0").matrix(), pose.matrix(), atol=1e-12)
    np.testing.assert_allclose(calib.floor_plane(), [0, 0, 1, 0.1])
    with pytest.raises(ConfigError, match="no camera 'cam9' \\(known: cam0\\)"):
        calib.pose("cam9")


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("cameras: {c: {translation: [0, 0, 1], rotation: [0, 0, 0, 0]}}\n", "zero quaternion"),
        ("cameras: {c: {translation: [0, 0, 1], scale: 2}}\n", "cameras.c.scale"),
        ("cameras: {}\n", "cameras"),
        ("cameras: {c: {translation: [0, 0]}}\n", "translation"),
        ("floor: [0, 0, 1, 0]\n", "cameras"),
        ("cameras: {c: {translation: [0, 0, 1]}}\nfloor: [0, 0, 0, 1]\n", "floor normal"),
        ("cameras: [\n", "not valid YAML"),
        ("cameras: {}\ncameras: {c: {translation: [0, 0, 1]}}\n", "duplicate key 'cameras'"),
    ],
)
def test_bad_calibration_files_are_refused(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError, match=message):
        load_calibration(path)


def test_calibration_that_is_not_utf8_or_a_pipe_is_refused(tmp_path: Path) -> None:
    latin = tmp_path / "latin.yaml"
    latin.write_bytes("cameras: {caf\xe9: {translation: [0, 0, 1]}}\n".encode("latin-1"))
    with pytest.raises(ConfigError, match="not UTF-8"):  # was UnicodeDecodeError
        load_calibration(latin)
    os.mkfifo(tmp_path / "pipe.yaml")
    with pytest.raises(ConfigError, match="named pipe"):  # was a read that never returned
        load_calibration(tmp_path / "pipe.yaml")


def test_missing_calibration_file(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="cannot read calibration"):
        load_calibration(tmp_path / "absent.yaml")
