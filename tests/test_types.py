"""Geometry of the data model: poses, camera projection."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from rgbd_eval.types import OPTICAL_TO_BODY, CameraModel, Pose

angles = st.floats(-np.pi, np.pi)
coords = st.floats(-10, 10)


def axis_angle(ax: float, ay: float, az: float) -> tuple[float, float, float, float]:
    v = np.array([ax, ay, az])
    angle = np.linalg.norm(v)
    if angle < 1e-9:
        return (0.0, 0.0, 0.0, 1.0)
    x, y, z = np.sin(angle / 2) * v / angle
    return (float(x), float(y), float(z), float(np.cos(angle / 2)))


@given(angles, angles, angles, coords, coords, coords)
def test_pose_inverse_and_matrix_round_trip(
    a: float, b: float, c: float, x: float, y: float, z: float
) -> None:
    p = Pose((x, y, z), axis_angle(a, b, c))
    np.testing.assert_allclose(p.compose(p.inverse()).matrix(), np.eye(4), atol=1e-9)
    np.testing.assert_allclose(Pose.from_matrix(p.matrix()).matrix(), p.matrix(), atol=1e-9)


def test_optical_to_body() -> None:
    # Optical z (forward) is body x; optical x (right) is body -y; optical y (down) is body -z.
    pts = OPTICAL_TO_BODY.transform_points(np.eye(3))
    np.testing.assert_allclose(pts, [[0, -1, 0], [0, 0, -1], [1, 0, 0]], atol=1e-12)


def test_camera_project_backproject() -> None:
    cam = CameraModel(640, 480, 525.0, 525.0, 319.5, 239.5)
    # A point 2 m ahead, 0.5 m right, 0.25 m down: u = 525*0.25 + 319.5 = 450.75, v = 525*0.125 + 239.5 = 305.125
    np.testing.assert_allclose(cam.project(np.array([[0.5, 0.25, 2.0]])), [[450.75, 305.125]])
    depth = np.full((480, 640), 2.0, np.float32)
    pts = cam.backproject(depth)
    np.testing.assert_allclose(
        pts[305, 450], [(450 - 319.5) * 2 / 525, (305 - 239.5) * 2 / 525, 2.0]
    )
    # Decimation by 4 keeps the same field of view: pixel centres map consistently.
    small = cam.scaled(160, 120)
    assert (small.fx, small.cx) == (131.25, (319.5 + 0.5) / 4 - 0.5)
