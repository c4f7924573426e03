"""Per-seed variation of a scenario's paths: other seeds, other walks through the same room.

A scenario's seed draws its people's bodies and clothes (:mod:`rgbd_eval.sim.people`) and
the sensor noise. With ``vary_paths_m`` > 0 it also moves every waypoint of every person
who walks a path (followers keep their offset to their leader) by up to that far, and with
``vary_speed`` > 0 it scales the walking speed of every segment by up to that share. A
claim judged over several seeds is then judged over other paths, not only other noise
(issue 31).

The layout's intent is kept:
- a waypoint where the person sits stays on its seat, and a moved waypoint never lands
  inside the room's margin or on an obstacle (footprint plus a body's half width);
- a moved segment does not cross an obstacle footprint its written segment did not cross;
- a waypoint outside the room (people walking in through a door) moves, but not further out.

A waypoint that finds no such place in :data:`TRIES` draws keeps its written position.
Each draw comes from ``(seed, STREAM, person id, waypoint)``, with no transcendental
function (a square draw kept if inside the disc): the same seed moves the same waypoints
to the same bits on every CPU, and adding a person to a scene changes no one else's path.
"""

from __future__ import annotations

import math

import numpy as np

from rgbd_eval import exact
from rgbd_eval.sim.scenario import Obstacle, Person, Room, Scenario, Waypoint

#: The random stream of path variation (apart from the simulator's noise streams).
STREAM = 31
#: Draws per waypoint before it keeps its written position.
TRIES = 32
#: Kept clear of obstacle footprints and the walls (m): about half a body's width.
CLEARANCE_M = 0.3
#: Obstacles whose base is at least this high (pictures on a wall) do not block walking.
_HANGING_Z = 1.0

_Footprint = tuple[float, float, float, float, float, float]  # x, y, cos, sin, half x, half y


def _footprints(obstacles: list[Obstacle]) -> list[_Footprint]:
    out: list[_Footprint] = []
    for ob in obstacles:
        if ob.z >= _HANGING_Z:
            continue
        s, c = exact.sincos(math.radians(ob.yaw_deg))
        sx, sy, _ = ob.extent
        out.append((ob.x, ob.y, c, s, sx / 2 + CLEARANCE_M, sy / 2 + CLEARANCE_M))
    return out


def _inside(fp: _Footprint, x: float, y: float) -> bool:
    ox, oy, c, s, hx, hy = fp
    dx, dy = x - ox, y - oy
    return abs(c * dx + s * dy) <= hx and abs(-s * dx + c * dy) <= hy


def _crosses(fp: _Footprint, a: tuple[float, float], b: tuple[float, float]) -> bool:
    """Whether segment ``a``-``b`` touches the footprint (sampled every 5 cm)."""
    n = max(1, math.ceil(exact.hypot(b[0] - a[0], b[1] - a[1]) / 0.05))
    return any(
        _inside(fp, a[0] + (b[0] - a[0]) * k / n, a[1] + (b[1] - a[1]) * k / n)
        for k in range(n + 1)
    )


def _outside_by(room: Room, x: float, y: float) -> float:
    """How far (m) a point lies outside the room shrunk by the clearance (0 inside)."""
    return max(
        room.x_min + CLEARANCE_M - x,
        x - (room.x_max - CLEARANCE_M),
        room.y_min + CLEARANCE_M - y,
        y - (room.y_max - CLEARANCE_M),
        0.0,
    )


def _offset(rng: np.random.Generator, radius: float) -> tuple[float, float]:
    """A uniform draw in the disc of ``radius``: a square draw kept when inside the disc."""
    while True:
        dx, dy = (float(v) for v in rng.uniform(-radius, radius, size=2))
        if dx * dx + dy * dy <= radius * radius:
            return dx, dy


def _vary_path(scenario: Scenario, person: Person, seed: int, fps: list[_Footprint]) -> Person:
    radius, share = scenario.vary_paths_m, scenario.vary_speed
    path: list[Waypoint] = []
    prev_written: tuple[float, float] | None = None
    for i, wp in enumerate(person.path):
        rng = np.random.default_rng([seed, STREAM, person.id, i])
        written = (wp.x, wp.y)
        prev = None if not path else (path[-1].x, path[-1].y)
        blocked_before = {
            k
            for k, fp in enumerate(fps)
            if prev_written is not None and _crosses(fp, prev_written, written)
        }
        place = written
        if radius > 0.0 and wp.sit_s == 0.0:
            limit = _outside_by(scenario.room, *written)
            for _ in range(TRIES):
                dx, dy = _offset(rng, radius)
                cand = (round(wp.x + dx, 4), round(wp.y + dy, 4))
                if _outside_by(scenario.room, *cand) > limit:
                    continue
                if any(_inside(fp, *cand) for fp in fps):
                    continue
                if prev is not None and any(
                    _crosses(fp, prev, cand) for k, fp in enumerate(fps) if k not in blocked_before
                ):
                    continue
                place = cand
                break
        speed = wp.speed
        if share > 0.0 and i > 0:
            factor = float(rng.uniform(1.0 - share, 1.0 + share))
            speed = min(3.0, max(0.06, round(wp.speed * factor, 4)))
        path.append(wp.model_copy(update={"x": place[0], "y": place[1], "speed": speed}))
        prev_written = written
    return person.model_copy(update={"path": path})


def vary_paths(scenario: Scenario, seed: int) -> Scenario:
    """``scenario`` with its people's paths as seed ``seed`` varies them (unchanged at 0, 0)."""
    if scenario.vary_paths_m == 0.0 and scenario.vary_speed == 0.0:
        return scenario
    fps = _footprints(scenario.obstacles)
    people = [
        p if p.follow is not None else _vary_path(scenario, p, seed, fps) for p in scenario.people
    ]
    return scenario.model_copy(update={"people": people})
