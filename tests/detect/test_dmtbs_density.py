"""DMT-BS density map and blobs (seed 003, 3.2-3.3): hand-computed micro-scenarios."""

from __future__ import annotations

import numpy as np
import pytest

from rgbd_eval.detect.blobs import blob_mask, disk_kernel, find_blobs
from rgbd_eval.detect.calibration import CameraCalibration
from rgbd_eval.detect.density import FloorGrid, camera_density, merge_maps, point_weights
from rgbd_eval.types import OPTICAL_TO_BODY, CameraModel, Pose

# A level camera 1.5 m above the floor looking along floor +x: optical z -> floor x,
# optical x -> floor -y, optical y -> floor -z (the optical-to-body rotation).
CAM = CameraModel(61, 61, 100.0, 100.0, 30.0, 30.0, frame_id="cam")
LEVEL = CameraCalibration("cam", CAM, Pose((0.0, 0.0, 1.5), OPTICAL_TO_BODY.rotation))
# Cells of 0.1 m; the offsets put the test points at cell centres, never on an edge.
GRID = FloorGrid(-0.05, -1.05, 3.95, 0.95, 0.1)


def _image(pixels: dict[tuple[int, int], float]) -> tuple[np.ndarray, np.ndarray]:
    depth = np.full((61, 61), np.nan, dtype=np.float32)
    fg = np.zeros((61, 61), dtype=bool)
    for (u, v), z in pixels.items():
        depth[v, u] = z
        fg[v, u] = True
    return depth, fg


def test_grid_shape_and_cell_centres() -> None:
    # x: 4.0 m / 0.1 = 40 columns; y: 2.0 m / 0.1 = 20 rows.
    assert GRID.shape == (20, 40)
    # column 20 -> x = -0.05 + 20.5 * 0.1 = 2.0; row 10 -> y = -1.05 + 10.5 * 0.1 = 0.0
    np.testing.assert_allclose(GRID.cell_centres(np.array([10]), np.array([20])), [[2.0, 0.0]])


def test_point_weight_is_squared_distance_over_focal_lengths() -> None:
    # (0.3, 0, 3): distance^2 = 0.09 + 9 = 9.09 -> 9.09 / (100 * 100) = 9.09e-4 m^2
    w = point_weights(np.array([[0.3, 0.0, 3.0], [0.0, 0.0, 2.0]]), 100.0, 100.0)
    np.testing.assert_allclose(w, [9.09e-4, 4.0e-4])


def test_density_weights_height_cut_and_binning() -> None:
    depth, fg = _image(
        {
            (30, 30): 2.0,  # ray (0, 0, 1): optical (0, 0, 2) -> floor (2, 0, 1.5)
            (40, 30): 3.0,  # ray (0.1, 0, 1): optical (0.3, 0, 3) -> floor (3, -0.3, 1.5)
            (30, 60): 2.0,  # ray (0, 0.3, 1): optical (0, 0.6, 2) -> floor z 0.9 < 1 m: dropped
        }
    )
    depth[0, 0] = 2.0  # valid but background: ignored
    m = camera_density(depth, fg, LEVEL, GRID, min_height_m=1.0)
    expected = np.zeros((20, 40))
    # (2, 0): column 20, row 10; weight 4 / 1e4 = 4e-4 m^2 over a 0.01 m^2 cell -> 0.04
    expected[10, 20] = 0.04
    # (3, -0.3): column floor((3 + 0.05) / 0.1) = 30, row floor((-0.3 + 1.05) / 0.1) = 7;
    # weight 9.09e-4 / 0.01 -> 0.0909
    expected[7, 30] = 0.0909
    np.testing.assert_allclose(m.density, expected, rtol=1e-6, atol=1e-9)
    np.testing.assert_array_equal(np.sort(m.cells), [7 * 40 + 30, 10 * 40 + 20])
    np.testing.assert_allclose(m.heights, [1.5, 1.5])


def test_density_sums_points_in_one_cell_and_drops_points_outside_the_roi() -> None:
    # Two pixels 1 px apart at 2 m land 2 cm apart on the floor: same cell, weights add:
    # (0, 0, 2): 4e-4; (0.02, 0, 2): (0.0004 + 4) / 1e4 = 4.0004e-4 -> (8.0004e-4) / 0.01
    # Depth 5 m puts a point at x = 5 > 3.95: outside the region, dropped.
    depth, fg = _image({(30, 30): 2.0, (31, 30): 2.0, (30, 29): 5.0})
    m = camera_density(depth, fg, LEVEL, GRID, min_height_m=1.0)
    assert m.density[10, 20] == pytest.approx(0.080004, rel=1e-6)
    assert m.density.sum() == pytest.approx(0.080004, rel=1e-6)


def test_density_bins_a_distorted_camera_along_its_undistorted_rays() -> None:
    # Barrel distortion (k1 = -0.4) at fx = 40: pixel (50, 20) sees the ray (0.62, -0.31, 1)
    # instead of the pinhole's (0.5, -0.25, 1); with the row and the column both off axis
    # the rays are no longer a column term and a row term. At 1.5 m: floor y = -0.93 m.
    cam = CameraModel(61, 61, 40.0, 40.0, 30.0, 30.0, (-0.4, 0.0, 0.0, 0.0, 0.0), "cam")
    calib = CameraCalibration("cam", cam, LEVEL.floor_from_optical)
    depth, fg = _image({(50, 20): 1.5})
    m = camera_density(depth, fg, calib, GRID, min_height_m=1.0)
    floor = calib.floor_from_optical.transform_points(cam.points_at(50, 20, 1.5)[None, :])[0]
    col, row = np.floor(GRID.to_cell(floor[None, :2])[0]).astype(int)
    assert m.cells.tolist() == [row * 40 + col]
    pinhole = (50 - 30) / 40.0 * 1.5  # optical x, floor -y
    assert floor[1] < -pinhole - 0.1  # more than a cell from the pinhole model's point
    assert m.heights[0] == pytest.approx(floor[2])


def test_density_does_not_depend_on_focal_length() -> None:
    # The same surface seen by a camera with twice the focal length (and 4x the pixels)
    # gives the same density: 4x the points, each with a quarter of the weight.
    wide = CameraModel(21, 21, 50.0, 50.0, 10.0, 10.0)
    tele = CameraModel(41, 41, 100.0, 100.0, 20.0, 20.0)
    grid = FloorGrid(-0.05, -1.05, 3.95, 0.95, 1.0)
    maps = []
    for cam in (wide, tele):
        depth = np.full((cam.height, cam.width), 2.0, dtype=np.float32)
        calib = CameraCalibration("c", cam, Pose((0.0, 0.0, 1.5), OPTICAL_TO_BODY.rotation))
        maps.append(camera_density(depth, np.ones_like(depth, dtype=bool), calib, grid, 1.0))
    # A 2 m deep wall; the pixel footprint tiles the visible wall: ~ its area above 1 m.
    assert maps[0].density.sum() == pytest.approx(maps[1].density.sum(), rel=0.1)


def test_merge_is_pixelwise_maximum() -> None:
    a = np.array([[0.0, 2.0], [5.0, 1.0]], dtype=np.float32)
    b = np.array([[3.0, 1.0], [4.0, 1.5]], dtype=np.float32)
    np.testing.assert_array_equal(merge_maps([a, b]), [[3.0, 2.0], [5.0, 1.5]])
    np.testing.assert_array_equal(merge_maps([a]), a)
    with pytest.raises(ValueError, match="differ in shape"):
        merge_maps([a, np.zeros((3, 3), dtype=np.float32)])
    with pytest.raises(ValueError, match="at least one"):
        merge_maps([])


def test_disk_kernel() -> None:
    # radius 1: the centre and its 4 neighbours (corners are at sqrt(2) > 1)
    np.testing.assert_array_equal(disk_kernel(1), [[0, 1, 0], [1, 1, 1], [0, 1, 0]])
    assert disk_kernel(5).sum() == 81  # lattice points with i^2 + j^2 <= 25


def _squares(gap_cells: int) -> tuple[np.ndarray, FloorGrid]:
    """Two 10x10-cell squares of density 4 on a 1 cm grid, ``gap_cells`` apart along x."""
    grid = FloorGrid(0.0, 0.0, 0.6, 0.3, 0.01)
    d = np.zeros(grid.shape, dtype=np.float32)
    d[10:20, 10:20] = 4.0
    d[10:20, 20 + gap_cells : 30 + gap_cells] = 4.0
    return d, grid


def test_blobs_centroids_of_two_separate_squares() -> None:
    d, grid = _squares(gap_cells=20)
    binary, _ = blob_mask(d, grid, blur_sigma_m=0.0, threshold=1.0, closing_radius_m=0.0)
    blobs, labels = find_blobs(binary, d, grid)
    assert len(blobs) == 2
    # Square 1: columns 10..19 -> x = (10.5 .. 19.5) cm, mean 15 cm; rows likewise y = 15 cm.
    # Square 2: columns 40..49 -> x = 45 cm.
    np.testing.assert_allclose(sorted(b.centroid for b in blobs), [(0.15, 0.15), (0.45, 0.15)])
    assert all(b.cells.shape == (100, 2) for b in blobs)
    assert labels.max() == 2


def test_closing_bridges_gaps_narrower_than_the_disk() -> None:
    # A 5 cm gap is bridged by a closing of radius 10 cm (dilation spans 20 cm), a 25 cm
    # gap is not: one blob, then two.
    for gap, count in ((5, 1), (25, 2)):
        d, grid = _squares(gap)
        binary, _ = blob_mask(d, grid, blur_sigma_m=0.0, threshold=1.0, closing_radius_m=0.1)
        blobs, _ = find_blobs(binary, d, grid)
        assert len(blobs) == count, gap


def test_blur_spreads_an_isolated_cell_below_the_threshold() -> None:
    # One cell of density 1 blurred with sigma = 1 cell keeps about 1 / (2 pi) ~ 0.16 at its
    # peak: a single noisy point is no blob at threshold 0.5, a 3x3 patch is.
    grid = FloorGrid(0.0, 0.0, 0.2, 0.2, 0.02)
    d = np.zeros(grid.shape, dtype=np.float32)
    d[5, 5] = 1.0
    binary, blurred = blob_mask(d, grid, blur_sigma_m=0.02, threshold=0.5, closing_radius_m=0.0)
    assert 0.14 < blurred.max() < 0.17
    assert binary.sum() == 0
    d[4:7, 4:7] = 1.0
    binary, _ = blob_mask(d, grid, blur_sigma_m=0.02, threshold=0.5, closing_radius_m=0.0)
    assert binary[5, 5] == 1


def test_blobs_smaller_than_the_minimum_surface_are_dropped() -> None:
    # Two squares of density 4 on a 1 cm grid: 100 cells of 1e-4 m^2 each -> 4 * 100 * 1e-4
    # = 0.04 m^2 of surface per square. Shrink the second to 5x5 cells: 4 * 25 * 1e-4 =
    # 0.01 m^2. With min_area 0.02 only the first is kept, renumbered 1, and the second's
    # cells are labelled 0.
    d, grid = _squares(gap_cells=20)
    d[10:20, 40:50] = 0.0
    d[10:15, 40:45] = 4.0
    binary, _ = blob_mask(d, grid, blur_sigma_m=0.0, threshold=1.0, closing_radius_m=0.0)
    blobs, _ = find_blobs(binary, d, grid)
    assert sorted(round(b.area_m2, 6) for b in blobs) == [0.01, 0.04]
    kept, labels = find_blobs(binary, d, grid, min_area_m2=0.02)
    assert [b.centroid for b in kept] == [pytest.approx((0.15, 0.15))]
    assert kept[0].area_m2 == pytest.approx(0.04)
    assert labels.max() == 1 and int((labels == 1).sum()) == 100
    assert labels[10:15, 40:45].sum() == 0
    with pytest.raises(ValueError, match="min_area_m2"):
        find_blobs(binary, d, grid, min_area_m2=-1.0)
