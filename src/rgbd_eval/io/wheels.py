"""Wheel odometry from ``sensor_msgs/JointState``: the robot's pose from its wheel speeds.

A differential-drive robot (satake2009, seed 002, 2.3.1) reports its two wheel joints'
angular velocities (rad/s); with the wheel radius they are the wheel speeds
``v_L, v_R`` (m/s). Integrated message to message -- each speed held until the next
message, the robot driving the circular arc of 2.3.1 meanwhile:
``v = (v_R + v_L)/2``, ``omega = (v_R - v_L)/2d``, ``d_theta = omega dt``,
``d_L = 2 rho sin(d_theta/2) = v dt sinc(d_theta/2)``, and the displacement
``(d_L cos(d_theta/2), d_L sin(d_theta/2))`` in the robot frame -- they give the
``odom -> base`` transform the reader adds to its tf tree, as a ``nav_msgs/Odometry``
topic would. The robot starts at the ``odom`` origin.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from rgbd_eval.types import Pose

#: The message type read.
JOINT_STATE_TYPE = "sensor_msgs/msg/JointState"


@dataclass(frozen=True)
class PlanarPose:
    """``(x, y, yaw)`` of the robot base in the odometry frame."""

    x: float = 0.0
    y: float = 0.0
    yaw: float = 0.0

    def pose(self) -> Pose:
        """As a 3D pose (base on the ground plane, yaw about z)."""
        return Pose(
            (self.x, self.y, 0.0), (0.0, 0.0, math.sin(self.yaw / 2), math.cos(self.yaw / 2))
        )


def drive(p: PlanarPose, v_L: float, v_R: float, d: float, dt: float) -> PlanarPose:
    """``p`` after driving ``dt`` seconds at wheel speeds ``v_L, v_R`` (half separation ``d``)."""
    v = 0.5 * (v_R + v_L)
    d_theta = (v_R - v_L) / (2.0 * d) * dt
    half = 0.5 * d_theta
    d_L = v * dt * (math.sin(half) / half if half else 1.0)
    heading = p.yaw + half
    return PlanarPose(p.x + d_L * math.cos(heading), p.y + d_L * math.sin(heading), p.yaw + d_theta)


def wheel_speeds(msg: Any, left: str, right: str, radius: float) -> tuple[float, float]:
    """``(v_L, v_R)`` in m/s from a JointState's velocities of the joints named ``left``/``right``.

    Raises ValueError naming what is missing.
    """
    names = [str(n) for n in msg.name]
    velocity = list(msg.velocity)
    out = []
    for joint in (left, right):
        if joint not in names:
            raise ValueError(f"no wheel joint {joint!r} in JointState (joints: {', '.join(names)})")
        k = names.index(joint)
        if k >= len(velocity):
            raise ValueError(f"JointState has no velocity for wheel joint {joint!r}")
        out.append(float(velocity[k]) * radius)
    return out[0], out[1]


class WheelOdometry:
    """Integrates wheel speeds message by message into the base's planar pose."""

    def __init__(self, half_separation: float) -> None:
        if not half_separation > 0:
            raise ValueError(f"wheel half separation d={half_separation} must be > 0")
        self.d = half_separation
        self.pose = PlanarPose()
        self._last: tuple[int, float, float] | None = None

    def add(self, stamp_ns: int, v_L: float, v_R: float) -> PlanarPose:
        """The pose at ``stamp_ns``, having driven at the previous speeds since the last message."""
        if self._last is not None:
            t0, l0, r0 = self._last
            if stamp_ns < t0:
                raise ValueError(f"JointState stamps go back: {t0} then {stamp_ns} ns")
            self.pose = drive(self.pose, l0, r0, self.d, (stamp_ns - t0) * 1e-9)
        self._last = (stamp_ns, v_L, v_R)
        return self.pose
