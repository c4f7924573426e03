"""Where people and the robot are at time t: piecewise timelines, pure functions.

A person's path becomes a list of :class:`Segment` (walk, wait, sit); the
state at time t is found by bisection. Walking speed is constant per segment;
the gait phase follows the distance walked, so the legs never slide.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass

from rgbd_eval import exact
from rgbd_eval.sim.scenario import Follow, Person, Robot

#: Time to sit down or to stand up (s).
SIT_TRANSITION_S = 0.8
#: Stride (two steps) as a fraction of body height: about 0.8 H at normal walking speed
#: (anthropometric rule of thumb, 1.4 m for a 1.75 m person).
STRIDE_PER_HEIGHT = 0.8


@dataclass(frozen=True)
class Segment:
    """One piece of a timeline from ``t0`` to ``t1``: move from ``p0`` to ``p1``."""

    t0: float
    t1: float
    kind: str  # "walk", "wait", "sit"
    p0: tuple[float, float]
    p1: tuple[float, float]
    heading: float  # radians, world frame
    s0: float  # distance walked at t0 (m)


@dataclass(frozen=True)
class PersonState:
    """A person at one instant."""

    present: bool
    x: float
    y: float
    heading: float  # radians
    speed: float  # m/s
    distance: float  # walked so far (m), drives the gait phase
    sit: float  # 0 standing ... 1 seated


def person_timeline(person: Person) -> list[Segment]:
    """The segments of a person's path, from ``start_s`` to the end of the last waypoint."""
    segs: list[Segment] = []
    t = person.start_s
    s = 0.0
    first = person.path[0]
    pos = (first.x, first.y)
    heading = 0.0
    if len(person.path) > 1:
        nxt = person.path[1]
        heading = exact.atan2(nxt.y - first.y, nxt.x - first.x)
    for i, wp in enumerate(person.path):
        target = (wp.x, wp.y)
        if i > 0:
            length = exact.hypot(target[0] - pos[0], target[1] - pos[1])
            if length > 1e-9:
                heading = exact.atan2(target[1] - pos[1], target[0] - pos[0])
                dt = length / wp.speed
                segs.append(Segment(t, t + dt, "walk", pos, target, heading, s))
                t += dt
                s += length
            pos = target
        if wp.face_deg is not None:
            heading = math.radians(wp.face_deg)
        if wp.wait_s > 0:
            segs.append(Segment(t, t + wp.wait_s, "wait", pos, pos, heading, s))
            t += wp.wait_s
        if wp.sit_s > 0:
            segs.append(Segment(t, t + wp.sit_s, "sit", pos, pos, heading, s))
            t += wp.sit_s
    if not segs:
        segs.append(Segment(t, t, "wait", pos, pos, heading, s))
    return segs


def person_state(person: Person, segments: list[Segment], t: float) -> PersonState:
    """The state of ``person`` at time ``t`` (absent before ``start_s`` and after a vanish)."""
    end = segments[-1]
    if t < segments[0].t0 or (t > end.t1 and person.leave == "vanish"):
        return PersonState(False, end.p1[0], end.p1[1], end.heading, 0.0, end.s0, 0.0)
    if t >= end.t1:
        s_end = end.s0 + (math.dist(end.p0, end.p1) if end.kind == "walk" else 0.0)
        return PersonState(True, end.p1[0], end.p1[1], end.heading, 0.0, s_end, 0.0)
    i = max(0, bisect.bisect_right([g.t0 for g in segments], t) - 1)
    g = segments[i]
    span = max(g.t1 - g.t0, 1e-9)
    a = min(1.0, max(0.0, (t - g.t0) / span))
    if g.kind == "walk":
        length = math.dist(g.p0, g.p1)
        x = g.p0[0] + a * (g.p1[0] - g.p0[0])
        y = g.p0[1] + a * (g.p1[1] - g.p0[1])
        return PersonState(True, x, y, g.heading, length / span, g.s0 + a * length, 0.0)
    sit = 0.0
    if g.kind == "sit":
        ramp = min(SIT_TRANSITION_S, span / 2.0)
        sit = min(1.0, (t - g.t0) / ramp, (g.t1 - t) / ramp)
    return PersonState(True, g.p0[0], g.p0[1], g.heading, 0.0, g.s0, max(0.0, sit))


def follower_state(leader: PersonState, follow: Follow) -> PersonState:
    """A follower's state: the leader's, shifted right/behind in the leader's frame."""
    c, s = exact.cos(leader.heading), exact.sin(leader.heading)
    fwd, left = -follow.behind_m, -follow.right_m
    return PersonState(
        leader.present,
        leader.x + c * fwd - s * left,
        leader.y + s * fwd + c * left,
        leader.heading,
        leader.speed,
        leader.distance,
        leader.sit,
    )


def gait_amplitude(person: Person, segments: list[Segment], t: float) -> float:
    """Gait amplitude in [0, 1]: walking speed relative to 1.2 m/s, smoothed over +-0.25 s.

    The smoothing lets the legs come to rest over a few frames instead of snapping.
    """
    total = 0.0
    offsets = (-0.25, -0.125, 0.0, 0.125, 0.25)
    for dt in offsets:
        total += min(1.0, person_state(person, segments, t + dt).speed / 1.2)
    return total / len(offsets)


def clothes_at(person: Person, t: float) -> tuple[tuple[int, int, int], tuple[int, int, int]]:
    """(shirt, trousers) worn at time t."""
    shirt, trousers = person.shirt, person.trousers
    for change in person.clothes:
        if t >= change.at_s:
            shirt, trousers = change.shirt, change.trousers
    return shirt, trousers


# ----------------------------------------------------------------------------- robot


@dataclass(frozen=True)
class RobotSegment:
    """Robot timeline piece: turn in place, drive straight, or wait."""

    t0: float
    t1: float
    kind: str  # "turn", "drive", "wait"
    p0: tuple[float, float]
    p1: tuple[float, float]
    yaw0: float
    yaw1: float


def _wrap(a: float) -> float:
    return (a + math.pi) % (2.0 * math.pi) - math.pi


def robot_timeline(robot: Robot) -> list[RobotSegment]:
    """Turn towards each waypoint at ``turn_rate_deg_s``, then drive to it at its speed."""
    segs: list[RobotSegment] = []
    t = robot.start_s
    pos = (robot.x, robot.y)
    yaw = math.radians(robot.yaw_deg)
    rate = math.radians(robot.turn_rate_deg_s)
    for wp in robot.path:
        target = (wp.x, wp.y)
        length = math.dist(pos, target)
        if length > 1e-9:
            want = exact.atan2(target[1] - pos[1], target[0] - pos[0])
            dyaw = _wrap(want - yaw)
            if abs(dyaw) > 1e-9:
                dt = abs(dyaw) / rate
                segs.append(RobotSegment(t, t + dt, "turn", pos, pos, yaw, yaw + dyaw))
                t += dt
                yaw = yaw + dyaw
            dt = length / wp.speed
            segs.append(RobotSegment(t, t + dt, "drive", pos, target, yaw, yaw))
            t += dt
            pos = target
        if wp.wait_s > 0:
            segs.append(RobotSegment(t, t + wp.wait_s, "wait", pos, pos, yaw, yaw))
            t += wp.wait_s
    return segs


def robot_pose(robot: Robot, segments: list[RobotSegment], t: float) -> tuple[float, float, float]:
    """The true (x, y, yaw) of base_link in the world at time t."""
    if not segments or t <= segments[0].t0:
        return (robot.x, robot.y, math.radians(robot.yaw_deg))
    end = segments[-1]
    if t >= end.t1:
        return (end.p1[0], end.p1[1], end.yaw1)
    i = max(0, bisect.bisect_right([g.t0 for g in segments], t) - 1)
    g = segments[i]
    a = min(1.0, max(0.0, (t - g.t0) / max(g.t1 - g.t0, 1e-9)))
    return (
        g.p0[0] + a * (g.p1[0] - g.p0[0]),
        g.p0[1] + a * (g.p1[1] - g.p0[1]),
        g.yaw0 + a * (g.yaw1 - g.yaw0),
    )
