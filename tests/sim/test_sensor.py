"""The Kinect model's noise statistics against the formulas, and its invalid pixels."""

from __future__ import annotations

import numpy as np
import pytest

from rgbd_eval.sim.scenario import Sensor
from rgbd_eval.sim.sensor import (
    depth_edges,
    depth_sigma,
    dropout_probability,
    exposure_gain,
    frame_noise,
    noise_bank,
    noisy_depth,
    noisy_rgb,
    quantisation_step,
)

F = 589.37  # fx of the 57 degree, 640 px camera


def flat(z: float, n: int = 300) -> np.ndarray:
    return np.full((n, n), z, dtype=np.float32)


def test_depth_sigma_grows_with_the_square_of_the_distance() -> None:
    # seed 000, Figure 6.1: sigma = k z^2 with k = 0.001425 -> 5 m: 0.001425 * 25 = 0.035625 m
    assert depth_sigma(5.0, 0.001425) == pytest.approx(0.035625)
    assert depth_sigma(2.0, 0.001425) * 4 == pytest.approx(depth_sigma(4.0, 0.001425))
    # step = z^2 / (b f q) = 16 / (0.075 * 589.37 * 8) = 0.04525 m at 4 m
    assert quantisation_step(4.0, 0.075, F, 8) == pytest.approx(0.04525, rel=1e-3)


@pytest.mark.parametrize("z", [1.0, 3.0, 6.0])
def test_measured_noise_matches_k_z_squared(z: float) -> None:
    sensor = Sensor(quantise=False, max_range_m=10.0)
    out = noisy_depth(flat(z), flat(0.0), sensor, F, np.random.default_rng(1))
    err = out.astype(np.float64) - z
    assert np.isfinite(out).all()
    # 90000 samples: the std estimate is within ~0.5 % of sigma
    assert err.std() == pytest.approx(0.001425 * z * z, rel=0.03)
    assert abs(err.mean()) < 0.05 * 0.001425 * z * z + 1e-4


def test_quantised_depth_lies_on_the_disparity_grid() -> None:
    sensor = Sensor()
    z = np.linspace(0.6, 7.9, 90000, dtype=np.float32).reshape(300, 300)
    out = noisy_depth(z, np.zeros_like(z), sensor, F, np.random.default_rng(2))
    bf = 0.075 * F
    steps = bf / out.astype(np.float64) * 8  # disparity in 1/8 px
    assert np.allclose(steps, np.round(steps), atol=1e-3)
    # around 6 m the depth only takes values z^2 / (b f q) apart: 36 / (0.075 * 589.37 * 8)
    # = 0.1018 m at 6 m, so between adjacent values a, b: b - a = step((a + b) / 2) to 1st order
    near6 = np.unique(out[np.abs(z - 6.0) < 0.02]).astype(np.float64)
    assert len(near6) >= 3
    mid = (near6[1:] + near6[:-1]) / 2
    assert np.diff(near6) == pytest.approx(quantisation_step(mid, 0.075, F, 8), rel=0.01)


def test_range_limits_and_dropout_rate() -> None:
    sensor = Sensor()
    z = np.array([[0.3, 0.5, 8.0, 8.5, np.nan]], dtype=np.float32)
    out = noisy_depth(
        z, np.zeros_like(z), Sensor(quantise=False, depth_noise_k=0.0), F, np.random.default_rng(0)
    )
    assert (
        np.isnan(out[0, 0]) and np.isnan(out[0, 3]) and np.isnan(out[0, 4])
    )  # 0.3 m, 8.5 m, nothing
    assert out[0, 1] == pytest.approx(0.5) and out[0, 2] == pytest.approx(8.0)
    drop = noisy_depth(flat(3.0), flat(0.3), sensor, F, np.random.default_rng(3))
    assert np.isnan(drop).mean() == pytest.approx(0.3, abs=0.01)


def test_same_generator_state_same_depth() -> None:
    s = Sensor()
    a = noisy_depth(flat(2.0, 50), flat(0.2, 50), s, F, np.random.default_rng(9))
    b = noisy_depth(flat(2.0, 50), flat(0.2, 50), s, F, np.random.default_rng(9))
    assert np.array_equal(a, b, equal_nan=True)


def test_depth_edges_mark_both_sides_of_a_jump() -> None:
    z = np.full((5, 8), 2.0, dtype=np.float32)
    z[:, 4:] = 4.0  # a 2 m jump between columns 3 and 4
    z[0, 0] = 2.05  # a 2.5 % bump, below the 5 % threshold
    edges = depth_edges(z, 0.05)
    assert edges[:, 3].all() and edges[:, 4].all()
    assert not edges[:, [0, 1, 2, 5, 6, 7]].any()
    nothing = np.full((3, 3), np.nan, dtype=np.float32)
    nothing[1, 1] = 3.0
    assert depth_edges(nothing, 0.05).all()  # an object against empty space


def test_dropout_causes_combine_independently() -> None:
    s = Sensor(edge_dropout=0.6, dark_dropout=0.25, shiny_dropout=0.5)
    t, f = np.array([[True]]), np.array([[False]])
    # 1 - (1 - 0.6)(1 - 0.25) = 0.7 ; 1 - 0.4 * 0.75 * 0.5 = 0.85
    assert dropout_probability(t, t, f, s)[0, 0] == pytest.approx(0.7)
    assert dropout_probability(t, t, t, s)[0, 0] == pytest.approx(0.85)
    assert dropout_probability(f, f, f, s)[0, 0] == 0.0


def test_exposure_and_rgb_noise() -> None:
    assert exposure_gain(3.0, 0.0, 10.0) == 1.0
    gains = [exposure_gain(t, 0.1, 10.0) for t in np.linspace(0, 100, 1001)]
    assert 0.9 <= min(gains) < 0.97 and 1.03 < max(gains) <= 1.1
    rng = np.random.default_rng(0)
    bank = noise_bank((200, 200, 3), 2, rng)
    noise = frame_noise(bank, rng)
    assert noise.std() == pytest.approx(1.0, rel=0.02)
    clean = np.full((200, 200, 3), 100.0, dtype=np.float32)
    img = noisy_rgb(clean, 1.1, 3.0, noise)
    # gain 1.1 -> mean 110, noise std 3 (rounding adds 1/12 variance)
    assert img.mean() == pytest.approx(110.0, abs=0.1)
    assert img.std() == pytest.approx(np.sqrt(9 + 1 / 12), rel=0.05)
    bright = noisy_rgb(np.full((200, 200, 3), 254.0, dtype=np.float32), 1.0, 3.0, noise)
    assert bright.max() == 255 and bright.dtype == np.uint8


def test_bad_arguments() -> None:
    with pytest.raises(ValueError, match="jump=0"):
        depth_edges(flat(1.0, 3), 0.0)
    with pytest.raises(ValueError, match="dropout shape"):
        noisy_depth(flat(1.0, 3), flat(0.0, 4), Sensor(), F, np.random.default_rng(0))
    with pytest.raises(ValueError, match="period_s"):
        exposure_gain(0.0, 0.1, 0.0)
    with pytest.raises(ValueError, match="noise shape"):
        noisy_rgb(np.zeros((2, 2, 3), np.float32), 1.0, 1.0, np.zeros((3, 3, 3), np.float32))
