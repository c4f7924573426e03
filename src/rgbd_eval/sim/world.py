"""The static scene: floor, walls and obstacles as one mesh.

Object ids: :data:`ROOM_ID` for floor and walls, ``OBSTACLE_ID_BASE + i`` for
obstacle ``i``; people use their own ids (1..10000); :data:`NO_HIT` is empty space.
"""

from __future__ import annotations

import math

import numpy as np

from rgbd_eval import exact
from rgbd_eval.sim.meshes import (
    F64,
    MAT_FLOOR,
    MAT_MATTE,
    MAT_SHINY,
    MAT_WALL,
    Mesh,
    MeshBuilder,
    rotation_x,
    rotation_z,
)
from rgbd_eval.sim.people import CLOTH_COLOURS
from rgbd_eval.sim.scenario import Colour, Obstacle, ObstacleKind, Room

ROOM_ID = 0
OBSTACLE_ID_BASE = 1_000_000
NO_HIT = -1


def _f(c: tuple[int, int, int], k: float = 1.0) -> tuple[float, float, float]:
    return (c[0] * k, c[1] * k, c[2] * k)


def room_mesh(room: Room, b: MeshBuilder) -> None:
    """Floor slab, four walls and a dark skirting board."""
    cx, cy = (room.x_min + room.x_max) / 2, (room.y_min + room.y_max) / 2
    lx, ly = room.x_max - room.x_min, room.y_max - room.y_min
    b.box((cx, cy, -0.01), (lx, ly, 0.02), np.eye(3), _f(room.floor_colour), ROOM_ID, MAT_FLOOR)
    if not room.walls:
        return
    h = room.wall_height
    if room.ceiling:
        b.box((cx, cy, h + 0.01), (lx, ly, 0.02), np.eye(3), _f(room.wall_colour, 1.05), ROOM_ID)
    wall = _f(room.wall_colour)
    skirt = _f(room.wall_colour, 0.45)
    t = 0.1
    for centre, size in (
        ((room.x_min - t / 2, cy, h / 2), (t, ly + 2 * t, h)),
        ((room.x_max + t / 2, cy, h / 2), (t, ly + 2 * t, h)),
        ((cx, room.y_min - t / 2, h / 2), (lx, t, h)),
        ((cx, room.y_max + t / 2, h / 2), (lx, t, h)),
    ):
        b.box(centre, size, np.eye(3), wall, ROOM_ID, MAT_WALL)
        # skirting: a 8 cm strip standing 1 cm proud of the wall
        sc = (centre[0], centre[1], 0.04)
        ss = (size[0] + 0.02, size[1] + 0.02, 0.08)
        b.box(sc, ss, np.eye(3), skirt, ROOM_ID)


def obstacle_mesh(ob: Obstacle, object_id: int, b: MeshBuilder) -> None:
    """One obstacle; shapes are simple assemblies of boxes, cylinders and ellipsoids."""
    R = rotation_z(math.radians(ob.yaw_deg))
    sx, sy, sz = ob.extent
    col = _f(ob.rgb)
    mat = MAT_SHINY if ob.shiny else MAT_MATTE
    o = np.array([ob.x, ob.y, ob.z])

    def at(dx: float, dy: float, dz: float) -> F64:
        out: F64 = o + exact.matmul(R, np.array([[dx], [dy], [dz]]))[:, 0]
        return out

    kind = ob.kind
    if kind in (ObstacleKind.BOX, ObstacleKind.PICTURE):
        b.box(at(0, 0, sz / 2), (sx, sy, sz), R, col, object_id, mat)
        if kind is ObstacleKind.PICTURE:  # a lighter canvas inside the frame
            b.box(at(0.01, 0, sz / 2), (sx, sy * 0.85, sz * 0.8), R, _f(ob.rgb, 1.6), object_id)
    elif kind is ObstacleKind.PILLAR:
        b.cylinder(o, sx / 2, sz, col, object_id, mat)
    elif kind is ObstacleKind.TABLE:
        top = 0.04
        b.box(at(0, 0, sz - top / 2), (sx, sy, top), R, col, object_id, mat)
        for ix in (-1, 1):
            for iy in (-1, 1):
                leg = at(ix * (sx / 2 - 0.05), iy * (sy / 2 - 0.05), (sz - top) / 2)
                b.box(leg, (0.05, 0.05, sz - top), R, _f(ob.rgb, 0.7), object_id, mat)
    elif kind is ObstacleKind.CHAIR:
        seat = 0.46
        b.box(at(0, 0, seat - 0.02), (sx, sy, 0.04), R, col, object_id, mat)
        for ix in (-1, 1):
            for iy in (-1, 1):
                leg = at(ix * (sx / 2 - 0.03), iy * (sy / 2 - 0.03), (seat - 0.04) / 2)
                b.box(leg, (0.035, 0.035, seat - 0.04), R, _f(ob.rgb, 0.6), object_id, MAT_SHINY)
        back_h = sz - seat
        b.box(at(-sx / 2 + 0.02, 0, seat + back_h / 2), (0.04, sy, back_h), R, col, object_id, mat)
    elif kind is ObstacleKind.SOFA:
        base = 0.42
        b.box(at(0, 0, base / 2), (sx, sy, base), R, col, object_id, mat)
        b.box(at(-sx / 2 + 0.1, 0, sz / 2), (0.2, sy, sz), R, _f(ob.rgb, 0.9), object_id, mat)
        for iy in (-1, 1):
            arm = at(0, iy * (sy / 2 - 0.1), 0.6 / 2)
            b.box(arm, (sx, 0.2, 0.6), R, _f(ob.rgb, 0.95), object_id, mat)
    elif kind is ObstacleKind.COAT_STAND:
        # tripod feet, a thin pole, hooks at the top and three coats hanging from them:
        # person-sized and person-coloured, but with no legs or shoulders
        dark = _f(ob.rgb, 0.8)
        for k in range(3):
            a = 2.0 * math.pi * k / 3.0
            foot = at(0.17 * exact.cos(a), 0.17 * exact.sin(a), 0.02)
            b.box(foot, (0.34, 0.04, 0.04), exact.matmul(R, rotation_z(a)), dark, object_id, mat)
        b.cylinder(o, 0.022, sz, col, object_id, mat)
        coats = ((70, 70, 85), (120, 90, 60), (40, 60, 45))
        for k, coat in enumerate(coats):
            a = 2.0 * math.pi * k / 3.0 + 0.4
            ca, sa = exact.cos(a), exact.sin(a)
            b.box(
                at(0.08 * ca, 0.08 * sa, sz - 0.06),
                (0.16, 0.02, 0.02),
                exact.matmul(R, rotation_z(a)),
                col,
                object_id,
            )
            centre = at(0.13 * ca, 0.13 * sa, sz - 0.36)
            b.sphere(
                centre,
                (0.1, 0.16 + 0.03 * k, 0.3),
                exact.matmul(R, rotation_z(a)),
                _f(coat),
                object_id,
            )
        b.sphere(at(0, 0, sz), (0.05, 0.05, 0.03), R, col, object_id)
    elif kind is ObstacleKind.PLANT:
        # a pot and many small leaf clusters in a wide, irregular crown
        pot_h = 0.35
        b.cylinder(o, min(sx / 3, 0.22), pot_h, (150, 75, 50), object_id, mat)
        b.cylinder(at(0, 0, pot_h), 0.02, sz * 0.6, (90, 70, 40), object_id, mat)
        seed = int(abs(ob.x * 1000.0) + abs(ob.y * 7919.0)) % (2**31)
        rng = np.random.default_rng(seed)
        n = 40
        for _ in range(n):
            f = exact.power(
                float(rng.uniform(0.1, 1.0)), 0.7
            )  # denser towards the top: a bushy crown
            zc = pot_h + f * (sz - pot_h - 0.08)
            # leaves (up to 0.14 m) stay inside the declared footprint
            r = max(sx / 2 - 0.14, 0.05) * (0.5 + 0.5 * exact.sin(math.pi * min(f, 0.9)))
            ang = rng.uniform(0.0, 2.0 * math.pi)
            rad = r * math.sqrt(rng.uniform(0.2, 1.0))
            size = tuple(float(v) for v in rng.uniform(0.06, 0.14, 3))
            leaf_R = exact.matmul(
                exact.matmul(R, rotation_z(float(rng.uniform(0, math.pi)))),
                rotation_x(float(rng.uniform(-1.0, 1.0))),
            )
            shade = 0.6 + 0.6 * rng.random()
            centre = at(rad * exact.cos(ang), rad * exact.sin(ang), zc)
            b.sphere(centre, (size[0], size[1], size[2]), leaf_R, _f(ob.rgb, shade), object_id)
    elif kind is ObstacleKind.CABINET:
        b.box(at(0, 0, sz / 2), (sx, sy, sz), R, col, object_id, mat)
        for iy in (-1, 1):  # two doors with handles
            door = at(sx / 2 + 0.005, iy * sy / 4, sz / 2 + 0.05)
            b.box(door, (0.01, sy / 2 - 0.03, sz - 0.25), R, _f(ob.rgb, 0.9), object_id, mat)
            handle = at(sx / 2 + 0.02, iy * 0.05, sz / 2 + 0.05)
            b.box(handle, (0.02, 0.015, 0.15), R, (60, 60, 60), object_id, MAT_SHINY)
    elif kind is ObstacleKind.MANNEQUIN:
        # a shop dummy: a person's body (no hair, no face, no clothes) in one plastic colour,
        # standing on a round base plate
        b.extend(mannequin_mesh(sz, ob.x, ob.y, ob.z, math.radians(ob.yaw_deg), ob.rgb, object_id))
        b.cylinder(o, min(sx, sy) / 2 - 0.02, 0.02, _f(ob.rgb, 0.5), object_id, MAT_SHINY)
    elif kind is ObstacleKind.DOOR:
        frame = _f(ob.rgb, 0.7)
        b.box(at(0, 0, sz / 2), (sx, sy - 0.1, sz - 0.05), R, col, object_id, mat)  # the leaf
        for iy in (-1, 1):  # the frame: two jambs and a head
            b.box(
                at(0.01, iy * (sy / 2 - 0.025), sz / 2), (sx + 0.02, 0.05, sz), R, frame, object_id
            )
        b.box(at(0.01, 0, sz - 0.025), (sx + 0.02, sy, 0.05), R, frame, object_id)
        b.box(
            at(sx / 2 + 0.02, sy / 2 - 0.14, 1.0),
            (0.03, 0.12, 0.02),
            R,
            (170, 170, 175),
            object_id,
            MAT_SHINY,
        )
    elif kind is ObstacleKind.SHELF:
        side = _f(ob.rgb, 0.85)
        for iy in (-1, 1):
            b.box(at(0, iy * (sy / 2 - 0.01), sz / 2), (sx, 0.02, sz), R, side, object_id, mat)
        b.box(at(-sx / 2 + 0.005, 0, sz / 2), (0.01, sy, sz), R, side, object_id, mat)
        levels = 5
        rng = np.random.default_rng(int(abs(ob.x * 1000.0) + abs(ob.y * 7919.0)) % (2**31))
        for k in range(levels + 1):
            z0 = 0.05 + k * (sz - 0.07) / levels
            b.box(at(0, 0, z0), (sx, sy - 0.04, 0.02), R, col, object_id, mat)
            if k == levels:
                break
            y = -sy / 2 + 0.03
            room = (sz - 0.07) / levels - 0.04
            while y < sy / 2 - 0.06:  # books of assorted sizes and colours
                w = float(rng.uniform(0.02, 0.05))
                h = room * float(rng.uniform(0.6, 0.95))
                d = sx * float(rng.uniform(0.6, 0.9))
                colour = _f(CLOTH_COLOURS[int(rng.integers(len(CLOTH_COLOURS)))])
                b.box(
                    at(-sx / 2 + d / 2 + 0.01, y + w / 2, z0 + 0.01 + h / 2),
                    (d, w, h),
                    R,
                    colour,
                    object_id,
                    mat,
                )
                y += w + float(rng.uniform(0.0, 0.01))
    else:  # pragma: no cover - exhaustive over ObstacleKind
        raise ValueError(f"unknown obstacle kind {kind}")


def mannequin_mesh(
    height: float, x: float, y: float, z: float, yaw: float, colour: Colour, object_id: int
) -> Mesh:
    """A standing MakeHuman body of ``height`` (clamped to 1.5-1.95 m) in one colour."""
    from rgbd_eval.sim.body import BodyModel, BodyShape, stand_pose, vertex_normals

    model = BodyModel.load()
    body = model.shaped(BodyShape(sex=0.5, age_years=30.0, height_m=min(max(height, 1.5), 1.95)))
    skin = model.face_group == 0
    faces = model.faces[skin].astype(np.int32)
    v = body.posed(stand_pose(body))
    v[:, 2] += 0.02 - float(v[:, 2].min())  # on the 2 cm base plate
    s, c = exact.sincos(yaw)
    world = np.stack(
        [c * v[:, 0] - s * v[:, 1] + x, s * v[:, 0] + c * v[:, 1] + y, v[:, 2] + z], axis=1
    )
    n = len(faces)
    return Mesh(
        world,
        vertex_normals(world, faces),
        faces,
        np.tile(np.asarray(colour, dtype=np.float64), (n, 1)),
        np.full(n, object_id, dtype=np.int32),
        np.full(n, MAT_MATTE, dtype=np.int32),
    )


def static_mesh(room: Room, obstacles: list[Obstacle]) -> Mesh:
    """The room and all obstacles as one mesh."""
    b = MeshBuilder()
    room_mesh(room, b)
    for i, ob in enumerate(obstacles):
        obstacle_mesh(ob, OBSTACLE_ID_BASE + i, b)
    return b.build()
