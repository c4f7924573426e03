"""DMT-BS background models on the Z image (seed 003, 3.1): hand-computed pixels."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rgbd_eval.detect.background import Mog2Background, RunningAverageBackground

NAN = np.nan
# dt = 0.1 s with tau = 0.1 / ln 2 makes the weight a = 1 - exp(-dt / tau) = 1/2.
HALF_TAU = 0.1 / math.log(2.0)


def _row(*values: float) -> np.ndarray:
    return np.array([values], dtype=np.float32)


def test_running_average_rules_pixel_by_pixel() -> None:
    bg = RunningAverageBackground(init_frames=2, time_constant_s=HALF_TAU, margin_m=0.1)
    # Initialisation: p0 mean(2.0, 2.2) = 2.1; p1 never valid -> infinitely far;
    # p2 mean of its one valid sample = 3.0; p3 = 1.0. No foreground while initialising.
    assert not bg.apply(_row(2.0, NAN, 3.0, 1.0), 0.1).any()
    assert not bg.apply(_row(2.2, NAN, NAN, 1.0), 0.1).any()
    assert bg.background is not None
    np.testing.assert_allclose(bg.background, _row(2.1, np.inf, 3.0, 1.0), rtol=1e-6)
    fg = bg.apply(_row(1.9, 2.5, NAN, 1.5), 0.1)
    # p0: 2.1 - 1.9 = 0.2 > 0.1 -> foreground; B = 2.1 + (1.9 - 2.1) / 2 = 2.0.
    # p1: infinitely far background -> foreground; seen once (adopted after 2 in a row).
    # p2: invalid -> not foreground, B kept at 3.0.
    # p3: 1.5 is farther: average 1.25, and 1.5 - 1.25 = 0.25 > 0.1, farther once (of 2).
    np.testing.assert_array_equal(fg, [[True, True, False, False]])
    np.testing.assert_allclose(bg.background, _row(2.0, np.inf, 3.0, 1.25), rtol=1e-6)
    fg = bg.apply(_row(2.0, 2.5, 3.0, 1.5), 0.1)
    # p1 valid for the second frame in a row: still foreground now, then adopted as 2.5.
    # p3: average 1.25 + (1.5 - 1.25) / 2 = 1.375, 1.5 - 1.375 = 0.125 > 0.1, farther for
    # the second frame in a row -> revealed, B = 1.5.
    np.testing.assert_array_equal(fg, [[False, True, False, False]])
    np.testing.assert_allclose(bg.background, _row(2.0, 2.5, 3.0, 1.5), rtol=1e-6)
    assert not bg.apply(_row(2.0, 2.5, 3.0, 1.5), 0.1).any()


def test_one_far_noise_sample_does_not_move_the_background() -> None:
    bg = RunningAverageBackground(init_frames=3, time_constant_s=HALF_TAU, margin_m=0.1)
    for _ in range(3):
        bg.apply(_row(2.0), 0.1)
    # One sample 0.3 m too far (noise): average 2.15, farther by 0.15 once (of 3): B = 2.15,
    # not 2.3 -> the next ordinary sample (2.0) is 0.15 nearer: foreground this once, and
    # B averages back to 2.075, the one after that is background again (0.075 < 0.1).
    assert not bg.apply(_row(2.3), 0.1).any()
    assert bg.background is not None and float(bg.background[0, 0]) == pytest.approx(2.15)
    assert bg.apply(_row(2.0), 0.1).all()
    assert not bg.apply(_row(2.0), 0.1).any()
    # Had B jumped to 2.3 (adopting single far samples), 2.0 would have been foreground for
    # two frames (2.3 -> 2.15 -> 2.075), and every far sample would start that again.


def test_weight_follows_the_time_step() -> None:
    bg = RunningAverageBackground(init_frames=1, time_constant_s=HALF_TAU, margin_m=0.5)
    bg.apply(_row(2.0), 0.1)
    # dt = 0.2 s: a = 1 - 2^-2 = 3/4 -> B = 2.0 + 0.75 * (1.8 - 2.0) = 1.85
    bg.apply(_row(1.8), 0.2)
    assert bg.background is not None
    assert float(bg.background[0, 0]) == pytest.approx(1.85, rel=1e-6)


def test_stationary_object_fades_into_the_background_and_leaves_no_ghost() -> None:
    # Background 3 m; an object at 2 m from frame 1 on. Before update j the gap is
    # B - z = exp(-0.1 (j - 1)) (tau = 1 s, dt = 0.1 s), so it is foreground while
    # exp(-0.1 (j - 1)) > 0.1, i.e. j - 1 < 10 ln 10 = 23.03: frames 1..24.
    bg = RunningAverageBackground(init_frames=1, time_constant_s=1.0, margin_m=0.1)
    bg.apply(_row(3.0), 0.1)
    flags = [bool(bg.apply(_row(2.0), 0.1)[0, 0]) for _ in range(40)]
    assert flags == [True] * 24 + [False] * 16
    # The object leaves: 3 m is farther than the background by > margin -> adopted at once.
    assert not bg.apply(_row(3.0), 0.1).any()
    assert bg.background is not None and float(bg.background[0, 0]) == 3.0


def test_running_average_refuses_bad_parameters_and_shapes() -> None:
    with pytest.raises(ValueError, match="init_frames"):
        RunningAverageBackground(0, 1.0, 0.1)
    with pytest.raises(ValueError, match="margin_m"):
        RunningAverageBackground(1, 1.0, 0.0)
    bg = RunningAverageBackground(1, 1.0, 0.1)
    bg.apply(_row(1.0, 1.0), 0.1)
    with pytest.raises(ValueError, match="background model"):
        bg.apply(_row(1.0), 0.1)


def test_mog2_finds_a_near_object_on_a_noisy_background() -> None:
    rng = np.random.default_rng(3)
    bg = Mog2Background(10, 3.0, 16.0, 0.05**2, 0.01**2, 0.2**2)
    h, w = 60, 80
    for _ in range(40):
        z = (3.0 + 0.01 * rng.standard_normal((h, w))).astype(np.float32)
        z[:5] = np.nan  # a band of invalid pixels
        fg = bg.apply(z, 1 / 30)
    assert fg.mean() < 0.01
    z = (3.0 + 0.01 * rng.standard_normal((h, w))).astype(np.float32)
    z[:5] = np.nan
    z[20:40, 30:50] = 2.0  # 1 m nearer, 100 sigma
    fg = bg.apply(z, 1 / 30)
    assert fg[20:40, 30:50].all()
    outside = fg.copy()
    outside[20:40, 30:50] = False
    assert outside.mean() < 0.01
    assert not fg[:5].any()


def test_mog2_reports_nothing_while_initialising_and_checks_variances() -> None:
    bg = Mog2Background(3, 1.0, 16.0, 0.05**2, 0.01**2, 0.2**2)
    z = np.full((4, 4), 2.0, dtype=np.float32)
    assert not any(bg.apply(z, 0.1).any() for _ in range(3))
    with pytest.raises(ValueError, match="variances"):
        Mog2Background(3, 1.0, 16.0, 0.001, 0.01, 0.2)


def test_mog2_does_not_flag_a_revealed_farther_surface() -> None:
    # An object at 2 m stands in front of a 3 m wall while MOG2 learns; when it leaves,
    # the wall (farther than the learnt background) is no foreground; a new object is.
    rng = np.random.default_rng(5)
    bg = Mog2Background(10, 3.0, 16.0, 0.05**2, 0.01**2, 0.2**2)
    for _ in range(20):
        z = (3.0 + 0.01 * rng.standard_normal((40, 40))).astype(np.float32)
        z[10:20, 10:20] = 2.0
        bg.apply(z, 1 / 30)
    z = (3.0 + 0.01 * rng.standard_normal((40, 40))).astype(np.float32)
    z[25:35, 25:35] = 1.5
    fg = bg.apply(z, 1 / 30)
    assert not fg[10:20, 10:20].any()
    assert fg[25:35, 25:35].all()


def test_mog2_finds_an_object_in_front_of_pixels_that_never_return() -> None:
    # The top rows never return (the void above a floor's far edge); an object appears there.
    # They must count as infinitely far: had they entered as 0 m, the object (2 m) would lie
    # farther than that background and never be foreground.
    rng = np.random.default_rng(7)
    bg = Mog2Background(10, 3.0, 16.0, 0.05**2, 0.01**2, 0.2**2)
    for _ in range(20):
        z = (3.0 + 0.01 * rng.standard_normal((40, 40))).astype(np.float32)
        z[:10] = np.nan
        assert not bg.apply(z, 1 / 30).any()
    z = (3.0 + 0.01 * rng.standard_normal((40, 40))).astype(np.float32)
    z[:10] = np.nan
    z[2:8, 15:25] = 2.0
    fg = bg.apply(z, 1 / 30)
    assert fg[2:8, 15:25].all()
    fg[2:8, 15:25] = False
    assert not fg.any()


def test_mog2_keeps_the_background_of_pixels_with_dropouts() -> None:
    # Two frames in three the left half drops out (flying pixels, dark material). The dropouts
    # must not take one of MOG2's two modes: when an object passes (frames 40-49) and leaves,
    # the wall (3 m) must still be the background, not foreground.
    rng = np.random.default_rng(11)
    bg = Mog2Background(10, 3.0, 16.0, 0.05**2, 0.01**2, 0.2**2)

    def wall(k: int) -> np.ndarray:
        z = (3.0 + 0.005 * rng.standard_normal((20, 20))).astype(np.float32)
        if k % 3 != 0:
            z[:, :10] = np.nan
        return z

    for k in range(40):
        bg.apply(wall(k), 1 / 30)
    for k in range(40, 50):
        z = wall(k)
        z[5:15, 5:15] = 1.8 + 0.02 * (k - 40)  # an object walking through, 1.8-2.0 m
        bg.apply(z, 1 / 30)
    for k in range(50, 60):
        fg = bg.apply(wall(k), 1 / 30)
        assert not fg.any()


def test_no_return_for_init_frames_in_a_row_makes_the_background_infinitely_far() -> None:
    bg = RunningAverageBackground(init_frames=2, time_constant_s=HALF_TAU, margin_m=0.1)
    # Initialisation: a person walks through a pixel that otherwise sees nothing (sky):
    # p0 mean of its one valid sample = 4.4, a phantom. p1 the same, for the interrupted case.
    bg.apply(_row(4.4, 4.4), 0.1)
    bg.apply(_row(NAN, NAN), 0.1)
    assert bg.background is not None
    np.testing.assert_allclose(bg.background, _row(4.4, 4.4), rtol=1e-6)
    # p0: no return once (of 2); p1: no return once, then a return at the phantom's depth
    # (not farther than 4.4 by > 0.1: the streak ends), then no return once again.
    assert not bg.apply(_row(NAN, NAN), 0.1).any()
    assert not bg.apply(_row(NAN, 4.4), 0.1).any()
    np.testing.assert_allclose(bg.background, _row(np.inf, 4.4), rtol=1e-6)  # p0: 2 in a row
    assert not bg.apply(_row(NAN, NAN), 0.1).any()
    np.testing.assert_allclose(bg.background, _row(np.inf, 4.4), rtol=1e-6)  # p1: 1 of 2
    # A person passing behind the old phantom (5.9 m > 4.4 m) is now foreground at p0; at p1
    # it is still hidden behind the phantom (farther: background, the revealed-surface count).
    np.testing.assert_array_equal(bg.apply(_row(5.9, 5.9), 0.1), [[True, False]])
