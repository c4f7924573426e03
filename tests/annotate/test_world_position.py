"""World positions of annotated boxes from the depth image: one surface placed, two refused."""

from __future__ import annotations

import numpy as np

from rgbd_eval.annotate import _depth_points, world_position
from rgbd_eval.types import Box2D, CameraModel, Frame

CAMERA = CameraModel(64, 48, 50.0, 50.0, 31.5, 23.5)
BOX = Box2D(20.0, 4.0, 24.0, 40.0)  # torso window: columns 26-38, rows 12-24


def _frame(depth: np.ndarray) -> Frame:
    rgb = np.zeros((48, 64, 3), dtype=np.uint8)
    return Frame.rgbd(0, 0, rgb, depth.astype(np.float32), CAMERA, CAMERA)


def test_one_surface_is_placed_where_the_torso_is() -> None:
    points = _depth_points(_frame(np.full((48, 64), 4.0)))
    assert points is not None
    x, y, z = world_position(points, BOX, CAMERA) or (0.0, 0.0, 0.0)
    # The world is the camera's body frame (no odometry): x forward, y left, z up.
    # Torso pixels are columns 26..37 and rows 12..23: their mean ray at 4 m.
    u = np.arange(26, 38).mean()
    assert np.isclose(x, 4.0) and np.isclose(y, -(u - CAMERA.cx) / CAMERA.fx * 4.0)
    # z: half the height of the box's top edge (row 4) at 4 m, above the camera.
    assert np.isclose(z, (CAMERA.cy - 4.0) / CAMERA.fy * 4.0 / 2.0)


def test_two_surfaces_in_the_torso_give_no_position() -> None:
    depth = np.full((48, 64), 4.0)
    depth[:, :32] = 2.0  # the torso window's left half is a person in front: 2 m and 6 m
    depth[:, 32:] = 6.0
    points = _depth_points(_frame(depth))
    assert points is not None
    assert world_position(points, BOX, CAMERA) is None  # median 4 m: no surface there
    sparse = np.full((48, 64), np.nan)  # fewer than 10 depth points in the window
    sparse[12, 26:35] = 4.0
    points = _depth_points(_frame(sparse))
    assert points is not None and world_position(points, BOX, CAMERA) is None
