"""satake2009 EKF (seed 002, 2.3): hand-computed motions, the closed form, F by finite differences."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rgbd_eval.methods.satake2009 import ekf as ekf


def _truth_in_robot_frame(
    p0: np.ndarray, vel: np.ndarray, v_L: float, v_R: float, d: float, t: float
) -> np.ndarray:
    """A person walking at constant ground velocity, seen from a robot that started at the
    origin facing +X and drives an arc (closed form: rho = v/omega, pose on the circle)."""
    v, omega = 0.5 * (v_R + v_L), (v_R - v_L) / (2 * d)
    th = omega * t
    if omega == 0:
        r = np.array([v * t, 0.0])
    else:
        rho = v / omega
        r = np.array([rho * math.sin(th), rho * (1 - math.cos(th))])
    c, s = math.cos(th), math.sin(th)
    Rt = np.array([[c, s], [-s, c]])  # world -> robot rotation R(-theta)
    p = p0[:2] + vel * t
    return np.concatenate([Rt @ (p - r), [p0[2]], Rt @ vel])


def test_pure_rotation_turns_the_person_to_the_right() -> None:
    # v_L = -0.1, v_R = 0.1, d = 0.2: v = 0, omega = 0.2 / 0.4 = 0.5 rad/s; dt = pi gives
    # d_theta = pi/2 and d_L = 0. A person 2 m ahead is then 2 m to the right: (0, -2).
    m = ekf.robot_motion(-0.1, 0.1, 0.2, math.pi)
    assert (m.v, m.omega, m.d_theta) == (0.0, 0.5, pytest.approx(math.pi / 2))
    assert m.d_L == 0.0
    x = ekf.f(np.array([2.0, 0.0, 1.6, 0.0, 0.0]), m, math.pi)
    np.testing.assert_allclose(x, [0.0, -2.0, 1.6, 0.0, 0.0], atol=1e-12)


def test_pure_translation_ground_model_and_the_seeds_double_count() -> None:
    # v_L = v_R = 0.5 m/s, dt = 0.1 s: d_theta = 0, d_L = d_X = 0.05 m, d_Y = 0.
    m = ekf.robot_motion(0.5, 0.5, 0.2, 0.1)
    assert (m.d_theta, m.d_X, m.d_Y) == (0.0, pytest.approx(0.05), 0.0)
    x0 = np.array([3.0, 1.0, 1.7, 0.0, 0.0])  # a static person
    # ground model: 3 - 0.05 = 2.95, then 2.90; the velocity stays 0.
    x1 = ekf.f(x0, m, 0.1)
    x2 = ekf.f(x1, m, 0.1)
    np.testing.assert_allclose(x1, [2.95, 1.0, 1.7, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(x2, [2.90, 1.0, 1.7, 0.0, 0.0], atol=1e-12)
    # eq. (3) as printed: x1 = 2.95 with Xdot = -0.5; x2 = 2.95 + 0.1 * (-0.5) - 0.05 = 2.85,
    # 5 cm short of the truth: the robot's motion counted twice.
    s1 = ekf.f(x0, m, 0.1, velocity="seed")
    s2 = ekf.f(s1, m, 0.1, velocity="seed")
    np.testing.assert_allclose(s1, [2.95, 1.0, 1.7, -0.5, 0.0], atol=1e-12)
    np.testing.assert_allclose(s2[0], 2.85, atol=1e-12)


def test_wheel_kinematics_match_the_closed_form_arc() -> None:
    # v_L = 0.3, v_R = 0.5, d = 0.2: v = 0.4, omega = 0.2 / 0.4 = 0.5, rho = 0.2 * 0.8 / 0.2
    # = 0.8 = v / omega. Over dt = 1: d_theta = 0.5, and the robot ends on the circle at
    # (rho sin 0.5, rho (1 - cos 0.5)) = (0.383541, 0.097934).
    m = ekf.robot_motion(0.3, 0.5, 0.2, 1.0)
    assert (m.v, m.omega) == (pytest.approx(0.4), pytest.approx(0.5))
    assert m.d_X == pytest.approx(0.8 * math.sin(0.5), abs=1e-12)
    assert m.d_Y == pytest.approx(0.8 * (1 - math.cos(0.5)), abs=1e-12)
    assert m.d_X == pytest.approx(0.383541, abs=1e-6)
    assert m.d_Y == pytest.approx(0.097934, abs=1e-6)
    # each wheel travels its own arc: (rho - d) d_theta = 0.6 * 0.5 = 0.3 = v_L dt.
    assert (0.8 - 0.2) * m.d_theta == pytest.approx(0.3)
    assert ekf.wheel_speeds(m.v, m.omega, 0.2) == (pytest.approx(0.3), pytest.approx(0.5))


def test_straight_limit_is_continuous() -> None:
    # omega -> 0: d_L = 2 rho sin(d_theta/2) -> v dt (rho is infinite at omega = 0).
    straight = ekf.robot_motion(0.7, 0.7, 0.25, 0.05)
    nearly = ekf.robot_motion(0.7, 0.7 + 1e-9, 0.25, 0.05)
    assert straight.d_L == pytest.approx(0.035, abs=1e-15)
    assert nearly.d_L == pytest.approx(straight.d_L, abs=1e-10)


@pytest.mark.parametrize("v_L,v_R", [(0.3, 0.5), (-0.2, 0.4), (0.6, 0.1), (0.4, 0.4)])
def test_repeated_prediction_follows_a_walking_person(v_L: float, v_R: float) -> None:
    # 40 steps of 0.05 s with constant wheel speeds against the closed form of 2 s of
    # driving: a person walking at (0.3, -0.2) m/s from (3, 0.5) stays exact (ground model).
    d, dt, n = 0.2, 0.05, 40
    p0, vel = np.array([3.0, 0.5, 1.7]), np.array([0.3, -0.2])
    x = np.concatenate([p0, vel])
    m = ekf.robot_motion(v_L, v_R, d, dt)
    for _ in range(n):
        x = ekf.f(x, m, dt)
    np.testing.assert_allclose(x, _truth_in_robot_frame(p0, vel, v_L, v_R, d, n * dt), atol=1e-9)


def test_jacobian_matches_finite_differences() -> None:
    rng = np.random.default_rng(7)
    for _ in range(5):
        x = rng.normal(size=5) * [3, 3, 1, 1, 1]
        dt = float(rng.uniform(0.02, 0.3))
        m = ekf.robot_motion(float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1)), 0.2, dt)
        for velocity in ("ground", "seed"):
            num = np.empty((5, 5))
            h = 1e-6
            for j in range(5):
                e = np.zeros(5)
                e[j] = h
                num[:, j] = (ekf.f(x + e, m, dt, velocity) - ekf.f(x - e, m, dt, velocity)) / (
                    2 * h
                )
            np.testing.assert_allclose(ekf.F(m, dt), num, atol=1e-8)


def test_predict_covariance_and_update_by_hand() -> None:
    # Static robot (d_theta = 0, F = [[I, dt I], [0, I]] on X,Y), P = I, dt = 1, sigma_w = 1:
    # P_XX = 1 + dt^2 * 1 = 2, P_XXdot = 1, P_XdotXdot = 1 + dt^2 sigma_w^2 = 2, P_ZZ = 1.
    m = ekf.robot_motion(0.0, 0.0, 0.2, 1.0)
    x, P = ekf.predict(np.zeros(5), np.eye(5), m, 1.0, sigma_w=1.0)
    np.testing.assert_allclose(x, 0.0)
    assert (P[0, 0], P[0, 3], P[3, 3], P[2, 2]) == (2.0, 1.0, 2.0, 1.0)
    # Update with y = (3, 0, 0), sigma_v = 1: S_XX = 2 + 1 = 3, K_X = 2/3, K_Xdot = 1/3:
    # X = 2, Xdot = 1; P_XX = 2 - 2 * 2/3 = 2/3, P_XdotXdot = 2 - 1 * 1/3 = 5/3.
    x, P = ekf.update(x, P, np.array([3.0, 0.0, 0.0]), sigma_v=1.0)
    np.testing.assert_allclose(x, [2.0, 0.0, 0.0, 1.0, 0.0], atol=1e-12)
    assert P[0, 0] == pytest.approx(2 / 3)
    assert P[3, 3] == pytest.approx(5 / 3)
    np.testing.assert_allclose(P, P.T)


def test_bad_kinematics_raise() -> None:
    with pytest.raises(ValueError, match="d=0"):
        ekf.robot_motion(0.1, 0.2, 0.0, 0.1)
    with pytest.raises(ValueError, match=r"dt=-0\.1"):
        ekf.robot_motion(0.1, 0.2, 0.2, -0.1)


@pytest.mark.parametrize("v_L,v_R", [(0.3, 0.5), (-0.2, 0.4), (0.4, 0.4)])
def test_motion_from_odometry_poses_equals_the_wheel_motion(v_L: float, v_R: float) -> None:
    # The robot at (1, 2) heading 30 deg drives an arc for 0.5 s; its end pose (closed form)
    # gives back the wheel-speed motion of 2.3.1.
    d, dt, yaw = 0.2, 0.5, math.radians(30)
    m = ekf.robot_motion(v_L, v_R, d, dt)
    c, s = math.cos(yaw), math.sin(yaw)
    after = (1 + c * m.d_X - s * m.d_Y, 2 + s * m.d_X + c * m.d_Y, yaw + m.d_theta)
    got = ekf.motion_from_poses((1.0, 2.0, yaw), after, dt)
    for name in ("v", "omega", "d_theta", "d_L", "d_X", "d_Y"):
        assert getattr(got, name) == pytest.approx(getattr(m, name), abs=1e-12), name
