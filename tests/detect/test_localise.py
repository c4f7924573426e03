"""The people localiser (seed 001, III-B) on hand-made depth images."""

from __future__ import annotations

import numpy as np
import pytest

from rgbd_eval.detect.localise import (
    DepthView,
    _box_depths_registered,
    _ProjectedDepth,
    localise,
)
from rgbd_eval.types import OPTICAL_TO_BODY, Box2D, CameraModel, Pose

CAM = CameraModel(8, 6, fx=4.0, fy=4.0, cx=3.5, cy=2.5)
#: world_T_body: the camera body 1 m forward of the world origin and 1 m up.
BODY = Pose((1.0, 0.0, 1.0))


def _view(depth: np.ndarray, depth_cam: CameraModel = CAM, extr: Pose | None = None) -> DepthView:
    return DepthView(
        depth=depth.astype(np.float32),
        depth_camera=depth_cam,
        rgb_camera=CAM,
        depth_to_rgb=extr or Pose.identity(),
        camera_pose=BODY.compose(OPTICAL_TO_BODY),
    )


def test_ray_through_centre_at_25th_percentile_then_world() -> None:
    depth = np.full((6, 8), np.nan)
    depth[1:5, 2:6] = np.arange(1, 17, dtype=float).reshape(4, 4)
    depth[1, 2] = np.nan  # invalid pixels are ignored: values 2..16 remain
    box = Box2D(2, 1, 4, 4)  # pixel centres: columns 2..5, rows 1..4
    loc = localise(_view(depth), [box])
    assert loc.dropped == 0 and loc.kept == [0]
    (lb,) = loc.boxes
    # 15 values 2..16: 25th percentile at index 0.25 * 14 = 3.5 -> 5 + 0.5 = 5.5
    assert lb.depth == pytest.approx(5.5)
    # centre (4, 3): ray ((4 - 3.5)/4, (3 - 2.5)/4, 1) = (0.125, 0.125, 1), times 5.5:
    # optical (0.6875, 0.6875, 5.5) -> body (z, -x, -y) = (5.5, -0.6875, -0.6875)
    # -> world + (1, 0, 1) = (6.5, -0.6875, 0.3125)
    np.testing.assert_allclose(lb.position, (6.5, -0.6875, 0.3125))
    assert lb.height == pytest.approx(4 * 5.5 / 4.0)


def test_decimated_depth_maps_the_box_exactly() -> None:
    small = CAM.scaled(4, 3)  # fx = 2, cx = (3.5 + 0.5) / 2 - 0.5 = 1.5, cy = 1.0
    depth = np.full((3, 4), 50.0)
    # Box x in [2, 6) -> depth u in [(2 - 3.5)/2 + 1.5, (6 - 3.5)/2 + 1.5) = [0.75, 2.75): cols 1, 2
    # Box y in [1, 5) -> depth v in [0.25, 2.25): rows 1, 2
    depth[1:3, 1:3] = [[2.0, 3.0], [4.0, 100.0]]
    loc = localise(_view(depth, small), [Box2D(2, 1, 4, 4)])
    # percentile of 2, 3, 4, 100 at index 0.75 -> 2 + 0.75 = 2.75
    assert loc.boxes[0].depth == pytest.approx(2.75)


def test_boxes_without_valid_depth_are_dropped_and_counted() -> None:
    depth = np.full((6, 8), np.nan)
    depth[:, 6:] = 3.0
    loc = localise(_view(depth), [Box2D(0, 0, 4, 6), Box2D(6, 0, 2, 6), Box2D(50, 50, 4, 4)])
    assert loc.kept == [1]
    assert loc.dropped == 2
    assert loc.boxes[0].depth == pytest.approx(3.0)


def test_extrinsics_take_the_general_path() -> None:
    # Colour camera 0.1 m right of the depth camera: a depth point p is at p - (0.1, 0, 0) in it,
    # so rgb_T_depth translates by -0.1 in x. A wall at z = 2 stays at z = 2 in the colour camera.
    extr = Pose((-0.1, 0.0, 0.0))
    depth = np.full((6, 8), 2.0)
    (lb,) = localise(_view(depth, extr=extr), [Box2D(2, 1, 4, 4)]).boxes
    assert lb.depth == pytest.approx(2.0)
    # Colour optical (0.125 * 2, 0.125 * 2, 2) = (0.25, 0.25, 2) -> depth optical (0.35, 0.25, 2)
    # -> body (2, -0.35, -0.25) -> world (3, -0.35, 0.75)
    np.testing.assert_allclose(lb.position, (3.0, -0.35, 0.75))


def test_projected_and_registered_paths_agree_without_extrinsics() -> None:
    rng = np.random.default_rng(3)
    depth = rng.uniform(0.5, 6.0, size=(6, 8))
    depth[rng.random((6, 8)) < 0.2] = np.nan
    view = _view(depth)
    projected = _ProjectedDepth(view)
    for box in (Box2D(2, 1, 4, 4), Box2D(0.3, 0.2, 3.4, 2.9), Box2D(5, 3, 3, 3)):
        a = np.sort(_box_depths_registered(view, box))
        b = np.sort(projected.depths(box))
        np.testing.assert_allclose(a, b, rtol=1e-6)


#: A camera with barrel distortion (k1 = -0.3, k2 = 0.1): its corner pixels see 29 % farther out.
LENS = CameraModel(64, 48, 40.0, 40.0, 31.5, 23.5, (-0.3, 0.1, 0.0, 0.0, 0.0))


def test_a_distorted_camera_localises_along_its_undistorted_ray() -> None:
    # A wall at z = 2 seen by the same lens in colour and (decimated) depth: the box still
    # maps to a depth rectangle, and the position lies on the undistorted centre ray.
    depth_cam = LENS.scaled(32, 24)
    view = DepthView(np.full((24, 32), 2.0, np.float32), depth_cam, LENS, Pose(), Pose())
    box = Box2D(2.0, 3.0, 10.0, 20.0)  # near the left edge
    (lb,) = localise(view, [box]).boxes
    assert lb.depth == pytest.approx(2.0)
    x, y, _ = LENS.points_at(7.0, 13.0, 2.0)
    np.testing.assert_allclose(lb.position, (x, y, 2.0))
    pinhole = (7.0 - 31.5) / 40.0 * 2.0
    assert x < pinhole - 0.2  # 21 cm farther out than the pinhole model says
    top, bottom = LENS.rays_at([7.0, 7.0], [3.0, 23.0])
    assert lb.height == pytest.approx((bottom[1] - top[1]) * 2.0)


def test_different_lenses_take_the_projected_path() -> None:
    # Registered (identity) but the colour lens is distorted and the depth one is not: a
    # depth pixel no longer maps to the colour image affinely, so every point is projected.
    rng = np.random.default_rng(5)
    depth = rng.uniform(1.0, 5.0, (48, 64)).astype(np.float32)
    pinhole = CameraModel(64, 48, 40.0, 40.0, 31.5, 23.5)
    view = DepthView(depth, pinhole, LENS, Pose(), Pose())
    box = Box2D(1.0, 1.0, 12.0, 30.0)
    (lb,) = localise(view, [box]).boxes
    projected = _ProjectedDepth(view).depths(box)
    assert lb.depth == pytest.approx(np.percentile(projected, 25))
    assert not np.array_equal(np.sort(projected), np.sort(_box_depths_registered(view, box)))
