"""The EKF of satake2009 (seed 002, 2.3) as pure functions with the paper's names.

State ``x = (X, Y, Z, Xdot, Ydot)`` of one person in the robot frame at time t (X
forward, Y left, Z up: a positive turn ``omega = (v_R - v_L) / 2d`` is to the left,
as the signs of 2.3.1 imply). The robot moves with wheel speeds ``u = (v_L, v_R)``;
the wheel separation is ``2d``.

Velocity model. Eq. (3) as printed keeps ``- v`` in the new ``Xdot`` *and* subtracts
the robot displacement ``dX`` from the position. That counts the robot's motion twice
from the second step on (a static person seen from a robot driving at v would be
predicted to approach at 2v; ``tests/track/test_track_satake2009_ekf.py`` shows it).
``velocity="ground"`` (the default) reads ``(Xdot, Ydot)`` as the person's ground
velocity expressed in the robot frame, which needs no ``- v``; ``velocity="seed"``
is eq. (3) letter for letter. The Jacobian F of 2.3.3 is the same for both (``- v``
does not depend on x).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from rgbd_eval.track import kalman

Array = NDArray[np.float64]
VelocityModel = Literal["ground", "seed"]

#: Observation matrix of eq. (4): the filter observes (X, Y, Z).
H = np.hstack([np.eye(3), np.zeros((3, 2))])


@dataclass(frozen=True)
class RobotMotion:
    """The robot's motion during one step, seen from its pose at time t (2.3.1)."""

    v: float
    omega: float
    d_theta: float
    d_L: float  # noqa: N815 - the paper's names (2.3.1)
    d_X: float  # noqa: N815
    d_Y: float  # noqa: N815


def robot_motion(v_L: float, v_R: float, d: float, dt: float) -> RobotMotion:
    """Motion of a differential-drive robot with wheel speeds ``v_L, v_R`` (m/s) over ``dt``.

    ``v = (v_R + v_L)/2``, ``omega = (v_R - v_L)/2d``, ``d_theta = omega dt``,
    ``d_L = 2 rho sin(d_theta/2)`` with ``rho = v/omega``, written as
    ``v dt sinc(d_theta/2)`` so that straight driving (``rho`` infinite) is exact.
    """
    if not d > 0:
        raise ValueError(f"half wheel separation d={d} must be > 0")
    if not dt >= 0:
        raise ValueError(f"time step dt={dt} must be >= 0")
    v = 0.5 * (v_R + v_L)
    omega = (v_R - v_L) / (2.0 * d)
    d_theta = omega * dt
    d_L = v * dt * float(np.sinc(d_theta / (2.0 * np.pi)))  # np.sinc(x) = sin(pi x)/(pi x)
    return RobotMotion(
        v=v,
        omega=omega,
        d_theta=d_theta,
        d_L=d_L,
        d_X=d_L * float(np.cos(d_theta / 2.0)),
        d_Y=d_L * float(np.sin(d_theta / 2.0)),
    )


def wheel_speeds(v: float, omega: float, d: float) -> tuple[float, float]:
    """``(v_L, v_R)`` from a body twist ``(v, omega)``: the inverse of 2.3.1."""
    return v - omega * d, v + omega * d


def f(x: Array, m: RobotMotion, dt: float, velocity: VelocityModel = "ground") -> Array:
    """The motion model ``f_t(x_t, u_t)`` of eq. (3) (see the module note on ``velocity``)."""
    c, s = np.cos(m.d_theta), np.sin(m.d_theta)
    px = x[0] + dt * x[3] - m.d_X
    py = x[1] + dt * x[4] - m.d_Y
    vx = c * x[3] + s * x[4] - (m.v if velocity == "seed" else 0.0)
    vy = -s * x[3] + c * x[4]
    return np.array([c * px + s * py, -s * px + c * py, x[2], vx, vy])


def F(m: RobotMotion, dt: float) -> Array:  # noqa: N802 - the paper's name
    """The Jacobian ``df/dx`` of 2.3.3."""
    c, s = np.cos(m.d_theta), np.sin(m.d_theta)
    return np.array(
        [
            [c, s, 0.0, dt * c, dt * s],
            [-s, c, 0.0, -dt * s, dt * c],
            [0.0, 0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 0.0, c, s],
            [0.0, 0.0, 0.0, -s, c],
        ]
    )


def G(dt: float) -> Array:  # noqa: N802 - the paper's name
    """Noise gain of eq. (2): the acceleration noise ``w`` drives the velocities."""
    out = np.zeros((5, 2))
    out[3, 0] = out[4, 1] = dt
    return out


def predict(
    x: Array,
    P: Array,
    m: RobotMotion,
    dt: float,
    sigma_w: float,
    velocity: VelocityModel = "ground",
) -> tuple[Array, Array]:
    """Prior of eqs. (5)-(6): ``x = f(x, u)``, ``P = F P F^T + G Q G^T``, ``Q = sigma_w^2 I``."""
    Fm = F(m, dt)
    Gm = G(dt)
    P_prior = Fm @ P @ Fm.T + (sigma_w * sigma_w) * (Gm @ Gm.T)
    return f(x, m, dt, velocity), 0.5 * (P_prior + P_prior.T)


def update(x: Array, P: Array, y: Array, sigma_v: float) -> tuple[Array, Array]:
    """Posterior of eqs. (7)-(9) for an observation ``y = (X_r, Y_r, Z_r)``, ``R = sigma_v^2 I``.

    Eq. (9) is computed in Joseph form (:func:`rgbd_eval.track.kalman.update`), equal to
    ``P - K H P`` for the optimal gain of eq. (7) and symmetric in floating point.
    """
    return kalman.update(x, P, y, H, (sigma_v * sigma_v) * np.eye(3))


def innovation_covariance(P: Array, sigma_v: float) -> Array:
    """``S = H P H^T + R``: the gate of an association (Mahalanobis distance)."""
    return H @ P @ H.T + (sigma_v * sigma_v) * np.eye(3)


def motion_from_poses(
    before: tuple[float, float, float], after: tuple[float, float, float], dt: float
) -> RobotMotion:
    """The motion between two planar robot poses ``(x, y, yaw)`` (from odometry) over ``dt``.

    ``d_X, d_Y`` are the displacement seen from ``before``; ``v`` and ``omega`` are those of
    the circular arc through both poses (2.3.1 inverted: ``d_L = 2 rho sin(d_theta/2)``), so
    odometry gives the same ``u`` the wheel speeds would.
    """
    if not dt > 0:
        raise ValueError(f"time step dt={dt} must be > 0")
    x0, y0, a0 = before
    c, s = math.cos(a0), math.sin(a0)
    dx, dy = after[0] - x0, after[1] - y0
    d_X, d_Y = c * dx + s * dy, -s * dx + c * dy
    d_theta = math.remainder(after[2] - a0, math.tau)
    d_L = math.hypot(d_X, d_Y) * (1.0 if d_X >= 0 else -1.0)
    sinc = float(np.sinc(d_theta / (2.0 * np.pi)))
    return RobotMotion(
        v=d_L / (dt * sinc), omega=d_theta / dt, d_theta=d_theta, d_L=d_L, d_X=d_X, d_Y=d_Y
    )
