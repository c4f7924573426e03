"""UKF maths: hand-computed steps, agreement with the linear Kalman filter, missed frames."""

from __future__ import annotations

import functools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rgbd_eval.track import kalman, ukf
from rgbd_eval.track.motion import (
    H,
    apply_measurement,
    apply_transition,
    measurement_variance,
    process_noise,
    transition_matrix,
)

W = ukf.sigma_weights(4)


def test_weights_sum_to_one_and_julier_default() -> None:
    # Julier-Uhlmann: kappa = 3 - n = -1, so n + kappa = 3 and W0 = kappa / 3 = -1/3, Wi = 1/6
    assert W.scale == pytest.approx(3.0)
    assert W.Wm[0] == pytest.approx(-1.0 / 3.0)
    assert np.allclose(W.Wm[1:], 1.0 / 6.0)
    assert W.Wm.sum() == pytest.approx(1.0)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [({"n": 0}, "n=0"), ({"n": 4, "alpha": 0.0}, "alpha=0.0"), ({"n": 4, "kappa": -4.0}, "lambda")],
)
def test_bad_weights_raise(kwargs: dict[str, float], match: str) -> None:
    with pytest.raises(ValueError, match=match):
        ukf.sigma_weights(**kwargs)  # type: ignore[arg-type]


def test_sigma_points_reproduce_mean_and_covariance() -> None:
    x = np.array([1.0, 2.0, 0.5, -0.5])
    P = np.diag([1.0, 2.0, 3.0, 4.0]) + 0.1
    X = ukf.sigma_points(x, P, W)
    assert X.shape == (9, 4)
    m, C = ukf.unscented_transform(X, W)
    assert np.allclose(m, x) and np.allclose(C, P)


def test_predict_by_hand() -> None:
    # x = (0, 0, 1, 0), P = I, dt = 0.5, sigma_a^2 = 4
    # F P F^T: pos var 1 + dt^2 = 1.25, pos-vel cov dt = 0.5, vel var 1
    # Q = 4 * [[dt^4/4, dt^3/2], [dt^3/2, dt^2]] = [[0.0625, 0.25], [0.25, 1.0]] per axis
    dt = 0.5
    x, P = ukf.predict(
        np.array([0.0, 0.0, 1.0, 0.0]),
        np.eye(4),
        lambda X: apply_transition(X, dt),
        process_noise(dt, 4.0),
        W,
    )
    assert np.allclose(x, [0.5, 0.0, 1.0, 0.0])
    expected = np.array(
        [
            [1.3125, 0.0, 0.75, 0.0],
            [0.0, 1.3125, 0.0, 0.75],
            [0.75, 0.0, 2.0, 0.0],
            [0.0, 0.75, 0.0, 2.0],
        ]
    )
    assert np.allclose(P, expected)


def test_update_by_hand() -> None:
    # prior N(0, I), z = (1, 0), R = I: S = 2 I, K = [[.5, 0], [0, .5], [0, 0], [0, 0]]
    # x = K z = (0.5, 0, 0, 0); P = I - K S K^T = diag(0.5, 0.5, 1, 1)
    x, P = ukf.update(np.zeros(4), np.eye(4), np.array([1.0, 0.0]), apply_measurement, np.eye(2), W)
    assert np.allclose(x, [0.5, 0.0, 0.0, 0.0])
    assert np.allclose(P, np.diag([0.5, 0.5, 1.0, 1.0]))


def test_motion_model_matrices_by_hand() -> None:
    # (6.4) and (6.6) with dt = 0.1, sigma_a^2 = 4: dt^4/4 = 2.5e-5, dt^3/2 = 5e-4, dt^2 = 0.01
    F = transition_matrix(0.1)
    assert np.allclose(F[:2, 2:], 0.1 * np.eye(2))
    Q = process_noise(0.1, 4.0)
    assert Q[0, 0] == pytest.approx(4 * 2.5e-5)
    assert Q[0, 2] == pytest.approx(4 * 5e-4)
    assert Q[2, 2] == pytest.approx(4 * 0.01)
    assert Q[0, 1] == 0.0 and Q[0, 3] == 0.0
    # (6.8): 0.06^2 / 12 = 3e-4; Figure 6.1: (0.001425 * 4^2)^2 = 0.0228^2 = 5.1984e-4
    assert measurement_variance(0.06, 4.0, 0.001425) == pytest.approx(3e-4 + 5.1984e-4)
    with pytest.raises(ValueError, match="acceleration_variance=-1"):
        process_noise(0.1, -1.0)


@st.composite
def _filter_problem(draw: st.DrawFn) -> tuple[np.ndarray, np.ndarray, list[float], np.ndarray]:
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(4, 4))
    P = A @ A.T + 0.1 * np.eye(4)
    x = rng.normal(size=4)
    dts = [draw(st.floats(0.005, 0.5)) for _ in range(5)]
    zs = rng.normal(size=(5, 2)) * 3
    return x, P, dts, zs


@settings(max_examples=40, deadline=None)
@given(_filter_problem(), st.floats(0.1, 10.0), st.floats(1e-4, 1.0))
def test_ukf_equals_linear_kalman_on_linear_model(
    problem: tuple[np.ndarray, np.ndarray, list[float], np.ndarray], accel: float, r: float
) -> None:
    x0, P0, dts, zs = problem
    xu, Pu = x0.copy(), P0.copy()
    xk, Pk = x0.copy(), P0.copy()
    R = r * np.eye(2)
    for dt, z in zip(dts, zs, strict=True):
        Q = process_noise(dt, accel)
        xu, Pu = ukf.predict(xu, Pu, functools.partial(apply_transition, dt=dt), Q, W)
        xk, Pk = kalman.predict(xk, Pk, transition_matrix(dt), Q)
        assert np.allclose(xu, xk) and np.allclose(Pu, Pk)
        xu, Pu = ukf.update(xu, Pu, z, apply_measurement, R, W)
        xk, Pk = kalman.update(xk, Pk, z, H, R)
        assert np.allclose(xu, xk, atol=1e-9) and np.allclose(Pu, Pk, atol=1e-9)


def test_batched_equals_one_by_one() -> None:
    rng = np.random.default_rng(3)
    xs = rng.normal(size=(3, 4))
    Ps = np.stack([np.eye(4) * (i + 1) for i in range(3)])
    zs = rng.normal(size=(3, 2))
    Rs = np.stack([np.eye(2) * 0.1 * (i + 1) for i in range(3)])
    xb, Pb = ukf.update(xs, Ps, zs, apply_measurement, Rs, W)
    for i in range(3):
        xi, Pi = ukf.update(xs[i], Ps[i], zs[i], apply_measurement, Rs[i], W)
        assert np.allclose(xb[i], xi) and np.allclose(Pb[i], Pi)


def test_constant_velocity_target_through_20_missed_frames() -> None:
    # a target at 1 m/s along x, 0.5 m/s along y, measured at 30 Hz for 1 s, then 20 frames
    # without measurements: the prediction follows the line; the covariance grows.
    dt, r = 1.0 / 30.0, measurement_variance(0.06, 3.0, 0.001425)
    rng = np.random.default_rng(0)
    x, P = np.array([0.0, 0.0, 0.0, 0.0]), np.diag([r, r, 1.0, 1.0])
    Q = process_noise(dt, 4.0)

    def fx(X: np.ndarray) -> np.ndarray:
        return apply_transition(X, dt)

    for k in range(1, 31):
        x, P = ukf.predict(x, P, fx, Q, W)
        truth = np.array([1.0, 0.5]) * k * dt
        x, P = ukf.update(
            x, P, truth + rng.normal(0, np.sqrt(r), 2), apply_measurement, r * np.eye(2), W
        )
    var_seen = P[0, 0]
    for _ in range(20):
        x, P = ukf.predict(x, P, fx, Q, W)
    truth = np.array([1.0, 0.5]) * 50 * dt
    # 20 frames = 0.667 s: the target walked |(1, 0.5)| * 0.667 = 0.745 m since it was last
    # seen; the constant-velocity prediction stays within a quarter of that
    assert np.linalg.norm(x[:2] - truth) < 0.25 * 0.745
    assert np.allclose(x[2:], [1.0, 0.5], atol=0.3)
    assert P[0, 0] > 10 * var_seen
    # the true position is well inside the 0.999 gate of the grown innovation covariance
    S = P[:2, :2] + r * np.eye(2)
    d = x[:2] - truth
    assert float(d @ np.linalg.solve(S, d)) < 13.8155
