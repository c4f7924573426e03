"""Point cloud, voxel grid and plane maths (seed 000, 5.1, 5.2)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rgbd_eval.detect.cloud import depth_to_cloud, voxel_grid
from rgbd_eval.detect.ground import refine_plane
from rgbd_eval.detect.plane import (
    fit_plane_least_squares,
    normalise_plane,
    plane_from_points,
    ransac_ground_plane,
    signed_heights,
)
from rgbd_eval.types import CameraModel


def test_depth_to_cloud_drops_invalid_and_too_deep_points() -> None:
    # 2x2 camera, f = 1, centre (0.5, 0.5): pixel (u, v) has ray ((u-0.5), (v-0.5), 1).
    cam = CameraModel(2, 2, 1.0, 1.0, 0.5, 0.5)
    depth = np.array([[2.0, np.nan], [0.0, 7.0]], dtype=np.float32)
    cloud = depth_to_cloud(depth, cam.rays(), max_depth=6.5)
    # Only pixel 0 survives: NaN, 0 and 7 m > 6.5 m are dropped.
    assert cloud.pixels.tolist() == [0]
    # Pixel (0, 0) at depth 2: x = (0 - 0.5) * 2 = -1, y = -1, z = 2.
    np.testing.assert_allclose(cloud.points, [[-1.0, -1.0, 2.0]])


def test_voxel_grid_keeps_one_centroid_per_cube() -> None:
    pts = np.array(
        [
            [0.01, 0.01, 0.01],  # voxel (0,0,0)
            [0.05, 0.03, 0.02],  # voxel (0,0,0)
            [0.07, 0.00, 0.00],  # voxel (1,0,0)
            [-0.01, 0.0, 0.0],  # voxel (-1,0,0)
        ]
    )
    grid = voxel_grid(pts, 0.06)
    assert grid.centroids.shape == (3, 3)
    assert grid.counts.sum() == 4
    # The first two share a voxel: centroid ((0.01+0.05)/2, (0.01+0.03)/2, (0.01+0.02)/2).
    shared = grid.point_voxel[0]
    assert grid.point_voxel[1] == shared
    np.testing.assert_allclose(grid.centroids[shared], [0.03, 0.02, 0.015])
    assert len({int(v) for v in grid.point_voxel}) == 3


@settings(max_examples=50, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 400), st.floats(0.02, 0.5))
def test_voxel_grid_properties(seed: int, n: int, size: float) -> None:
    points = np.random.default_rng(seed).uniform(-3, 3, (n, 3))
    grid = voxel_grid(points, size)
    # Every point belongs to exactly one voxel, shared only with points of its cube,
    # and each centroid lies inside that cube.
    assert grid.counts.sum() == n
    cells = np.floor(points / size)
    for v in range(grid.centroids.shape[0]):
        members = cells[grid.point_voxel == v]
        assert np.all(members == members[0])
    lo = cells * size
    c = grid.centroids[grid.point_voxel]
    assert np.all(c >= lo - 1e-9) and np.all(c <= lo + size + 1e-9)


def test_voxel_grid_rejects_bad_size() -> None:
    with pytest.raises(ValueError, match="voxel_size"):
        voxel_grid(np.zeros((3, 3)), 0.0)


def test_plane_from_three_floor_points() -> None:
    # Floor 1 m below a level camera (optical y down): y = 1 -> plane (0, -1, 0, 1)
    # after orienting the normal towards the sensor (d > 0).
    plane = plane_from_points(
        np.array([0.0, 1.0, 2.0]), np.array([1.0, 1.0, 3.0]), np.array([-1.0, 1.0, 4.0])
    )
    np.testing.assert_allclose(plane, [0.0, -1.0, 0.0, 1.0], atol=1e-12)
    # A point 1.75 m above the floor (y = 1 - 1.75) has height 1.75.
    assert signed_heights(np.array([[0.3, -0.75, 3.0]]), plane)[0] == pytest.approx(1.75)


def test_collinear_points_raise() -> None:
    with pytest.raises(ValueError, match="collinear"):
        plane_from_points(np.zeros(3), np.array([1.0, 0, 0]), np.array([2.0, 0, 0]))


def test_normalise_rejects_zero_normal() -> None:
    with pytest.raises(ValueError, match="non-zero"):
        normalise_plane((0.0, 0.0, 0.0, 1.0))


@settings(max_examples=50, deadline=None)
@given(st.lists(st.floats(-10, 10, allow_nan=False), min_size=9, max_size=9))
def test_plane_through_points_contains_them(coords: list[float]) -> None:
    a, b, c = (np.array(coords[i : i + 3]) for i in (0, 3, 6))
    if np.linalg.norm(np.cross(b - a, c - a)) < 1e-3:
        return
    plane = plane_from_points(a, b, c)
    assert np.linalg.norm(plane[:3]) == pytest.approx(1.0)
    assert plane[3] >= 0.0
    np.testing.assert_allclose(signed_heights(np.stack([a, b, c]), plane), 0.0, atol=1e-8)


def _floor_and_table(rng: np.random.Generator) -> np.ndarray:
    # Floor y = 1 (1 m below the camera), 600 points; a table top y = 0.3, 300 points.
    floor = np.column_stack([rng.uniform(-2, 2, 600), np.full(600, 1.0), rng.uniform(1, 6, 600)])
    table = np.column_stack([rng.uniform(0, 1, 300), np.full(300, 0.3), rng.uniform(2, 3, 300)])
    return np.vstack([floor, table]) + rng.normal(0, 0.005, (900, 3))


def test_ransac_finds_the_floor_not_the_table() -> None:
    pts = _floor_and_table(np.random.default_rng(1))
    up = np.array([0.0, -1.0, 0.0])  # optical y points down
    plane = ransac_ground_plane(pts, up, threshold=0.06, max_tilt_rad=np.radians(30))
    assert plane is not None
    np.testing.assert_allclose(plane, [0, -1, 0, 1.0], atol=0.01)
    # Deterministic for a seed.
    again = ransac_ground_plane(pts, up, threshold=0.06, max_tilt_rad=np.radians(30))
    np.testing.assert_array_equal(plane, again)


def test_ransac_rejects_planes_against_gravity() -> None:
    # A wall z = 3 only: its normal is 90 degrees from up, so no ground plane.
    rng = np.random.default_rng(2)
    wall = np.column_stack([rng.uniform(-2, 2, 500), rng.uniform(-1, 1, 500), np.full(500, 3.0)])
    assert ransac_ground_plane(wall, np.array([0, -1.0, 0]), 0.06, np.radians(30)) is None


def test_least_squares_fit_and_refine_follow_a_small_tilt() -> None:
    rng = np.random.default_rng(3)
    # True floor tilted by 2 degrees about x: normal (0, -cos, sin), 1 m below the camera.
    t = np.radians(2.0)
    normal = np.array([0.0, -np.cos(t), np.sin(t)])
    xs, zs = rng.uniform(-2, 2, 800), rng.uniform(1, 5, 800)
    # Solve n . p + 1 = 0 for y.
    ys = (1.0 + normal[0] * xs + normal[2] * zs) / np.cos(t)
    pts = np.column_stack([xs, ys, zs])
    fit = fit_plane_least_squares(pts)
    np.testing.assert_allclose(fit, [*normal, 1.0], atol=1e-9)
    # Starting from the level plane, refinement within a 6 cm band converges on the tilt.
    refined, count = refine_plane(pts, np.array([0.0, -1.0, 0.0, 1.0]), 0.06, 30)
    assert count >= 30
    np.testing.assert_allclose(refined, [*normal, 1.0], atol=1e-3)


def test_refine_keeps_the_plane_when_too_few_floor_points() -> None:
    plane = np.array([0.0, -1.0, 0.0, 1.0])
    pts = np.array([[0.0, 1.0, 2.0], [1.0, 1.0, 2.0], [0.0, 0.0, 2.0]])  # 2 floor points
    kept, count = refine_plane(pts, plane, 0.06, 30)
    assert count == 2
    assert kept is plane
