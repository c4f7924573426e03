"""Odometry drift: none when standing, scale error exact, random walk growing with sqrt(distance)."""

from __future__ import annotations

import numpy as np
import pytest

from rgbd_eval.sim.odometry import integrate_odometry, relative_motion
from rgbd_eval.sim.scenario import Odometry


def straight(n: int, length: float) -> np.ndarray:
    poses = np.zeros((n, 3))
    poses[:, 0] = np.linspace(0.0, length, n)
    return poses


def test_standing_robot_does_not_drift() -> None:
    true = np.tile([1.0, 2.0, 0.3], (50, 1))
    odom = integrate_odometry(true, Odometry(), np.random.default_rng(0))
    assert np.array_equal(odom, true)


def test_scale_error_without_noise() -> None:
    model = Odometry(scale_error=0.1, translation_noise=0.0, rotation_noise_deg=0.0)
    odom = integrate_odometry(straight(11, 5.0), model, np.random.default_rng(0))
    # every 0.5 m step is read as 0.55 m: 5 m become 5.5 m
    assert odom[-1] == pytest.approx([5.5, 0.0, 0.0])


def test_relative_motion_in_the_robot_frame() -> None:
    # robot at the origin facing +y; moving to (0, 1) is 1 m forward
    fwd, lat, dyaw = relative_motion(np.array([0.0, 0.0, np.pi / 2]), np.array([0.0, 1.0, np.pi]))
    assert (fwd, lat, dyaw) == pytest.approx((1.0, 0.0, np.pi / 2))


def test_translation_noise_is_a_random_walk_in_distance() -> None:
    model = Odometry(scale_error=0.0, translation_noise=0.02, rotation_noise_deg=0.0)
    true = straight(101, 9.0)
    finals = np.array(
        [integrate_odometry(true, model, np.random.default_rng(k))[-1, :2] for k in range(300)]
    )
    # variance sigma^2 * sum(step) = 0.02^2 * 9 -> std 0.06 m along and across
    std = finals.std(axis=0)
    assert std == pytest.approx([0.06, 0.06], rel=0.15)
    assert np.abs(finals.mean(axis=0) - [9.0, 0.0]).max() < 0.02


def test_bad_shape() -> None:
    with pytest.raises(ValueError, match=r"\(N, 3\)"):
        integrate_odometry(np.zeros((4, 2)), Odometry(), np.random.default_rng(0))
