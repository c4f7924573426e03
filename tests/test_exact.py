"""rgbd_eval.exact: accurate to a few ulp, scalar and array paths bit-identical, exact linear algebra."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import ndimage, stats

from rgbd_eval import exact

RNG = np.random.default_rng(20261127)


def _ulps(got: np.ndarray, want: np.ndarray) -> float:
    scale = np.spacing(np.maximum(np.abs(want), np.finfo(np.float64).tiny))
    return float(np.max(np.abs(got - want) / scale))


@pytest.mark.parametrize(
    ("ours", "reference", "low", "high", "max_ulps"),
    [
        (exact.sin, np.sin, -100.0, 100.0, 2),
        (exact.cos, np.cos, -100.0, 100.0, 2),
        (exact.tan, np.tan, -1.5, 1.5, 4),
        (exact.atan, np.arctan, -50.0, 50.0, 4),
        (exact.exp, np.exp, -700.0, 700.0, 2),
        (exact.log, np.log, 1e-300, 1e300, 2),
    ],
)
def test_elementary_functions_are_within_a_few_ulp(
    ours: object, reference: object, low: float, high: float, max_ulps: float
) -> None:
    x = RNG.uniform(low, high, 100_000)
    if ours is exact.log:  # spread over the exponents, not only the top of the range
        x = np.exp(RNG.uniform(math.log(low), math.log(high), 100_000))
    assert _ulps(ours(x), reference(x)) <= max_ulps  # type: ignore[operator]


def test_atan2_quadrants_and_axes() -> None:
    y, x = RNG.uniform(-5, 5, 50_000), RNG.uniform(-5, 5, 50_000)
    # atan(y / x) plus pi: the rounded quotient and the sum cost a few ulp more than atan
    assert _ulps(exact.atan2(y, x), np.arctan2(y, x)) <= 8
    # the axes, as math.atan2 (signed zeros aside): pi/2 up, -pi/2 down, pi left, 0 at 0
    for yy, xx in [(1.0, 0.0), (-1.0, 0.0), (0.0, -1.0), (0.0, 1.0), (0.0, 0.0), (-2.0, -2.0)]:
        assert exact.atan2(yy, xx) == pytest.approx(math.atan2(yy, xx), abs=1e-15)


def test_cube_root_within_a_few_ulp_and_odd() -> None:
    x = RNG.uniform(-1e6, 1e6, 100_000)
    assert _ulps(exact.cbrt(x), np.cbrt(x)) <= 4
    assert exact.cbrt(-8.0) == pytest.approx(-2.0, rel=1e-15) and exact.cbrt(0.0) == 0.0
    assert exact.cbrt(-27.0) == float(exact.cbrt(np.array([-27.0]))[0])


def test_special_values() -> None:
    assert exact.exp(-800.0) == 0.0 and exact.exp(800.0) == math.inf
    assert exact.log(0.0) == -math.inf and math.isnan(exact.log(-1.0))
    assert exact.log(math.inf) == math.inf
    assert exact.power(0.0, 2.0) == 0.0 and exact.power(3.0, 0.0) == 1.0
    assert math.isnan(exact.power(-1.0, 0.5))
    # e**1 and ln 10, to the last digit printed by math
    assert exact.exp(1.0) == pytest.approx(math.e, rel=2.3e-16)
    assert exact.log(10.0) == math.log(10.0)


@settings(max_examples=300, deadline=None)
@given(st.floats(min_value=-1e4, max_value=1e4, allow_nan=False))
def test_scalar_and_array_paths_agree_bit_for_bit(x: float) -> None:
    for f in (exact.sin, exact.cos, exact.tan, exact.atan, exact.exp):
        assert f(x) == float(f(np.array([x]))[0]) or (math.isnan(f(x)))
    p = abs(x) + 1e-3
    assert exact.log(p) == float(exact.log(np.array([p]))[0])
    assert exact.power(p, 0.7) == float(exact.power(np.array([p]), 0.7)[0])
    assert exact.atan2(x, 0.3) == float(exact.atan2(np.array([x]), np.array([0.3]))[0])


def test_matmul_sums_in_index_order() -> None:
    a = RNG.normal(size=(50, 3))
    b = RNG.normal(size=(3, 4))
    # (a @ b)[i, j] = ((a0 b0j + a1 b1j) + a2 b2j), each product rounded first
    want = (a[:, 0:1] * b[0] + a[:, 1:2] * b[1]) + a[:, 2:3] * b[2]
    assert np.array_equal(exact.matmul(a, b), want)
    assert np.allclose(exact.matmul(a, b), a @ b, rtol=0, atol=1e-14)
    with pytest.raises(ValueError, match="cannot multiply"):
        exact.matmul(a, b.T)


def test_linear_algebra_against_numpy() -> None:
    R = exact.matmul(exact.rotation_z(0.3), exact.rotation_x(-0.7))
    assert np.allclose(exact.inv3(R), R.T, atol=1e-15)
    assert exact.det3(np.diag([2.0, 3.0, 4.0])) == 24.0  # 2 * 3 * 4
    a, b = RNG.normal(size=(10, 3)), RNG.normal(size=(10, 3))
    assert np.allclose(exact.cross(a, b), np.cross(a, b), atol=1e-14)
    assert np.allclose(exact.norm(a), np.linalg.norm(a, axis=1), atol=1e-14)
    with pytest.raises(ValueError, match="singular"):
        exact.inv3(np.zeros((3, 3)))


def test_standard_normal_is_normal_and_reproducible() -> None:
    z = exact.standard_normal(np.random.default_rng(3), 200_000)
    again = exact.standard_normal(np.random.default_rng(3), 200_000)
    assert np.array_equal(z, again)
    assert abs(z.mean()) < 0.01 and abs(z.std() - 1.0) < 0.01
    assert stats.kstest(z[:20_000], "norm").pvalue > 0.01
    assert exact.standard_normal(np.random.default_rng(3), (2, 3), np.float32).dtype == np.float32


def test_gaussian_filter_matches_scipy() -> None:
    image = RNG.uniform(0, 50, (40, 60))
    for sigma in (0.8, 1.5, 3.0):
        ours = exact.gaussian_filter(image, sigma)
        assert np.allclose(ours, ndimage.gaussian_filter(image, sigma, mode="nearest"), atol=1e-12)
    with pytest.raises(ValueError, match="sigma"):
        exact.gaussian_kernel(0.0)
