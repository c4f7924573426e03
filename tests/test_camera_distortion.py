"""Lens distortion of CameraModel: OpenCV is the reference for both directions.

Random points and pixels come from fixed seeds. Tolerances: projection 1e-9 px; undistortion
1e-10 in normalised coordinates (4e-8 px at fx = 400), against OpenCV iterated to 1e-14;
round trips 1e-9 px.
"""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from rgbd_eval.detect.cloud import depth_to_cloud
from rgbd_eval.types import CameraModel

FloatArray = np.ndarray

#: A Kinect v2 (EPFL-RGBD's calibration) with tangential terms added.
PLUMB_BOB = CameraModel(
    512, 424, 365.8, 365.8, 254.3, 206.9, (0.0879, -0.2703, 0.0012, -0.0021, 0.0994)
)
RATIONAL = CameraModel(
    640, 480, 520.0, 522.0, 318.2, 243.7,
    (0.35, -0.12, 0.0008, -0.0011, 0.02, 0.61, -0.08, 0.05),
    distortion_model="rational_polynomial",
)  # fmt: skip
FISHEYE = CameraModel(
    848, 800, 286.0, 286.2, 421.7, 402.3, (-0.0074, 0.0436, -0.0413, 0.0077),
    distortion_model="equidistant",
)  # fmt: skip
CAMERAS = {"plumb_bob": PLUMB_BOB, "rational_polynomial": RATIONAL, "equidistant": FISHEYE}


def _points_in_view(cam: CameraModel, n: int, seed: int) -> FloatArray:
    """Points 0.5-8 m away whose undistorted image lies within the image (plus 10%)."""
    rng = np.random.default_rng(seed)
    u = rng.uniform(-0.1 * cam.width, 1.1 * cam.width, n)
    v = rng.uniform(-0.1 * cam.height, 1.1 * cam.height, n)
    z = rng.uniform(0.5, 8.0, n)
    out: FloatArray = np.stack([(u - cam.cx) / cam.fx * z, (v - cam.cy) / cam.fy * z, z], axis=1)
    return out


def _pixels(cam: CameraModel, n: int, seed: int) -> FloatArray:
    """Pixels on the image; for a fisheye, those seeing less than 80 deg off its axis."""
    rng = np.random.default_rng(seed)
    out: FloatArray = np.stack(
        [rng.uniform(-0.5, cam.width - 0.5, n), rng.uniform(-0.5, cam.height - 0.5, n)], axis=1
    )
    if cam.distortion_model == "equidistant":
        return out[_angle(cam, out) < np.radians(80.0)]
    return out


def _angle(cam: CameraModel, px: FloatArray) -> FloatArray:
    """The distorted angle theta_d of a fisheye's pixels (about the angle off the axis)."""
    out: FloatArray = np.hypot((px[:, 0] - cam.cx) / cam.fx, (px[:, 1] - cam.cy) / cam.fy)
    return out


@pytest.mark.parametrize("model", sorted(CAMERAS))
def test_projection_matches_opencv(model: str) -> None:
    cam = CAMERAS[model]
    points = _points_in_view(cam, 2000, seed=1)
    D = np.array(cam.distortion)
    if model == "equidistant":
        ref, _ = cv2.fisheye.projectPoints(points[:, None, :], np.zeros(3), np.zeros(3), cam.K, D)
    else:
        ref, _ = cv2.projectPoints(points, np.zeros(3), np.zeros(3), cam.K, D)
    np.testing.assert_allclose(cam.project(points), ref[:, 0, :], rtol=0, atol=1e-9)


@pytest.mark.parametrize("model", sorted(CAMERAS))
def test_undistortion_matches_opencv(model: str) -> None:
    cam = CAMERAS[model]
    px = _pixels(cam, 2000, seed=2)
    D = np.array(cam.distortion)
    criteria = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 100, 1e-14)
    if model == "equidistant":
        ref = cv2.fisheye.undistortPoints(px[:, None, :], cam.K, D, criteria=criteria)
    else:
        ref = cv2.undistortPointsIter(px[:, None, :], cam.K, D, None, None, criteria)
    rays = cam.rays_at(px[:, 0], px[:, 1])
    assert np.all(rays[:, 2] == 1.0)
    np.testing.assert_allclose(rays[:, :2], ref[:, 0, :], rtol=0, atol=1e-10)


@pytest.mark.parametrize("model", sorted(CAMERAS))
def test_every_pixel_ray_projects_back_to_its_pixel(model: str) -> None:
    cam = CAMERAS[model]
    rays = cam.rays()
    assert rays.shape == (cam.height, cam.width, 3) and not rays.flags.writeable
    assert cam.rays() is rays  # the table is computed once per camera
    uu, vv = np.meshgrid(np.arange(cam.width, dtype=float), np.arange(cam.height, dtype=float))
    px = np.stack([uu, vv], -1).reshape(-1, 2)
    flat = rays.reshape(-1, 3)
    seen = np.isfinite(flat[:, 0])
    if model == "equidistant":  # the corners of this fisheye look more than 90 deg off axis
        t = np.pi / 2
        k1, k2, k3, k4 = cam.distortion
        theta_d_90 = t * (1 + k1 * t**2 + k2 * t**4 + k3 * t**6 + k4 * t**8)  # 1.433
        angle = _angle(cam, px)
        clear = np.abs(angle - theta_d_90) > 1e-4  # the fold search's step aside
        assert np.array_equal(seen[clear], angle[clear] < theta_d_90)
        assert np.isnan(flat[~seen]).all() and 0 < np.count_nonzero(~seen) < px.shape[0] // 2
    else:
        assert seen.all()
    back = cam.project(flat[seen] * 3.0)  # any depth along the ray
    np.testing.assert_allclose(back, px[seen], rtol=0, atol=1e-9)
    np.testing.assert_array_equal(cam.rays_at(uu[::7, ::5], vv[::7, ::5]), rays[::7, ::5])
    # A cloud leaves out the pixels without a ray.
    cloud = depth_to_cloud(np.full((cam.height, cam.width), 2.0, np.float32), rays, 10.0)
    assert np.array_equal(cloud.pixels, np.flatnonzero(seen))
    np.testing.assert_array_equal(cloud.points, flat[seen] * 2.0)


def test_hand_computed_plumb_bob_point() -> None:
    cam = CameraModel(100, 100, 100.0, 100.0, 50.0, 50.0, (0.1, 0.01, 0.001, 0.002, 0.0))
    # Point (0.5, 0.25, 1): x = 0.5, y = 0.25, r^2 = 0.25 + 0.0625 = 0.3125.
    # radial = 1 + 0.1 * 0.3125 + 0.01 * 0.3125^2 = 1 + 0.03125 + 0.0009765625 = 1.0322265625
    # x_d = x radial + 2 p1 x y + p2 (r^2 + 2 x^2)
    #     = 0.51611328125 + 2 * 0.001 * 0.125 + 0.002 * 0.8125
    #     = 0.51611328125 + 0.00025 + 0.001625 = 0.51798828125
    # y_d = y radial + p1 (r^2 + 2 y^2) + 2 p2 x y
    #     = 0.258056640625 + 0.001 * 0.4375 + 2 * 0.002 * 0.125
    #     = 0.258056640625 + 0.0004375 + 0.0005 = 0.258994140625
    # u = 100 x_d + 50 = 101.798828125, v = 100 y_d + 50 = 75.8994140625
    # (the pinhole projection would be (100, 75): the lens moves it by 1.8 px).
    uv = cam.project(np.array([[0.5, 0.25, 1.0], [1.0, 0.5, 2.0]]))
    np.testing.assert_allclose(uv, [[101.798828125, 75.8994140625]] * 2, rtol=0, atol=1e-12)
    np.testing.assert_allclose(cam.rays_at(101.798828125, 75.8994140625), [0.5, 0.25, 1.0])
    np.testing.assert_allclose(
        cam.points_at(101.798828125, 75.8994140625, 2.0), [1.0, 0.5, 2.0], rtol=0, atol=1e-12
    )


def test_zero_coefficients_are_the_pinhole_arithmetic_bit_for_bit() -> None:
    rng = np.random.default_rng(3)
    points = rng.uniform(-2.0, 2.0, (500, 3))
    points[:, 2] += 4.0
    u, v, z = rng.uniform(0, 640, 500), rng.uniform(0, 480, 500), rng.uniform(0.5, 8, 500)
    for D in [(), (0.0,) * 5, (0.0,) * 8]:
        cam = CameraModel(640, 480, 525.0, 521.0, 319.5, 239.5, D)
        assert cam.lens is None and cam.distortion_problem() is None
        uv = cam.project(points)
        assert np.array_equal(uv[:, 0], 525.0 * points[:, 0] / points[:, 2] + 319.5)
        assert np.array_equal(uv[:, 1], 521.0 * points[:, 1] / points[:, 2] + 239.5)
        rays = cam.rays_at(u, v)
        assert np.array_equal(rays[:, 0], (u - 319.5) / 525.0)
        assert np.array_equal(rays[:, 1], (v - 239.5) / 521.0)
        pts = cam.points_at(u, v, z)
        assert np.array_equal(pts[:, 0], (u - 319.5) * z / 525.0)
        assert np.array_equal(pts[:, 2], z)
        table = cam.rays()
        assert np.array_equal(table[0, :, 0], (np.arange(640.0) - 319.5) / 525.0)
        assert np.array_equal(table[:, 0, 1], (np.arange(480.0) - 239.5) / 521.0)


def test_a_strongly_barrel_lens_does_not_fold_far_points_into_the_image() -> None:
    # k1 = -0.5: OpenCV's radius r (1 - 0.5 r^2) peaks at r = 0.816 and falls back to 0 at
    # r = 1.41; the image corner is at r = 1.0. Beyond the peak the radial factor is held.
    cam = CameraModel(640, 480, 400.0, 400.0, 319.5, 239.5, (-0.5, 0.0, 0.0, 0.0, 0.0))
    r = np.linspace(0.05, 3.0, 60)
    along = np.stack([r, np.zeros_like(r), np.ones_like(r)], axis=1)
    u = cam.project(along)[:, 0]
    assert np.all(np.diff(u) > 0)  # further out stays further out
    ref, _ = cv2.projectPoints(along, np.zeros(3), np.zeros(3), cam.K, np.array(cam.distortion))
    folded = ref[:, 0, 0] < 639.5
    assert folded[-1]  # OpenCV brings r = 3 back into the image ...
    assert u[-1] > 639.5  # ... we do not
    near = r < 0.8
    np.testing.assert_allclose(u[near], ref[near, 0, 0], rtol=0, atol=1e-9)
    # Every pixel still has one ray, which projects back onto it.
    back = cam.project(cam.rays().reshape(-1, 3))
    uu, vv = np.meshgrid(np.arange(640.0), np.arange(480.0))
    np.testing.assert_allclose(back, np.stack([uu, vv], -1).reshape(-1, 2), rtol=0, atol=1e-9)


def test_scaling_keeps_the_lens() -> None:
    half = PLUMB_BOB.scaled(256, 212)
    assert half.lens == PLUMB_BOB.lens and half.distortion_model == "plumb_bob"
    # The same ray through the same physical point of the sensor at either resolution.
    ray = PLUMB_BOB.rays_at(400.0, 50.0)
    np.testing.assert_allclose(half.rays_at((400.0 + 0.5) / 2 - 0.5, (50.0 + 0.5) / 2 - 0.5), ray)


def test_unsupported_distortion_is_named_and_ignored() -> None:
    custom = CameraModel(
        64,
        48,
        50.0,
        50.0,
        31.5,
        23.5,
        (0.1, 0.02, 0.0, 0.0),
        distortion_model="kannala_brandt_custom",
    )
    assert custom.lens is None  # treated as undistorted
    problem = custom.distortion_problem()
    assert problem is not None and "'kannala_brandt_custom' is not supported" in problem
    assert "0.1, 0.02, 0, 0" in problem
    # OpenCV's thin-prism terms (s1..s4) after the rational model's eight are not applied.
    prism = CameraModel(
        64, 48, 50.0, 50.0, 31.5, 23.5, (0.1,) + (0.0,) * 7 + (0.003, 0.0, 0.0, 0.0),
        distortion_model="rational_polynomial",
    )  # fmt: skip
    assert prism.lens is not None and prism.lens.coefficients == (0.1,) + (0.0,) * 7
    assert prism.distortion_problem() == (
        "rational_polynomial distortion takes 8 coefficients: the further ones (0.003, 0, 0, 0) "
        "are ignored"
    )
