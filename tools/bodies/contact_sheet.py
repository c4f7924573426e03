"""Render a few shaped and posed MakeHuman bodies to a PNG, for a person to look at.

Usage::

    PYTHONPATH=src python tools/bodies/contact_sheet.py [-o /tmp/bodies.png]

Rows: varied people in the rest pose seen from the front; the same people standing; one
person walking at 1.2 m/s seen from the side at eight phases of the gait cycle, and a
person sitting (on no chair); the six people walking at 1.2 m/s from the front, each at
another phase. Flat colours per body part (a shirt, trousers, skin), shaded by the
project's renderer (:mod:`rgbd_eval.sim.render`).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import cv2
import numpy as np
from numpy.typing import NDArray

from rgbd_eval.sim.body import (
    BodyModel,
    BodyShape,
    Pose,
    RestBody,
    natural_stride,
    sit_pose,
    stand_pose,
    vertex_normals,
    walk_pose,
)
from rgbd_eval.sim.meshes import MAT_FLOOR, MAT_MATTE, Mesh
from rgbd_eval.sim.render import light_direction, make_scene, render_hits, shade
from rgbd_eval.types import CameraModel
from rgbd_eval.types import Pose as Frame

PART_COLOURS = {
    "head": (205, 160, 130),
    "neck": (205, 160, 130),
    "torso": (70, 110, 170),
    "pelvis": (60, 60, 70),
    "upper_arm": (90, 130, 190),
    "forearm": (205, 160, 130),
    "hand": (215, 170, 140),
    "thigh": (70, 70, 85),
    "shin": (80, 80, 95),
    "foot": (40, 35, 30),
}
PEOPLE = (
    BodyShape(sex=0.0, age_years=25, weight=0.4, height_m=1.62),
    BodyShape(sex=1.0, age_years=35, muscle=0.7, height_m=1.82),
    BodyShape(sex=0.0, age_years=70, weight=0.85, height_m=1.55, proportions=0.2),
    BodyShape(sex=1.0, age_years=60, weight=0.9, muscle=0.3, height_m=1.74),
    BodyShape(sex=0.3, age_years=20, weight=0.2, height_m=1.70, proportions=0.9),
    BodyShape(sex=1.0, age_years=28, weight=0.5, height_m=1.95),
)


def body_mesh(body: RestBody, vertices: NDArray[np.float64], object_id: int) -> Mesh:
    """The skin (group ``body``) of a posed body, coloured by body part."""
    model = body.model
    keep = model.face_group == 0
    faces = model.faces[keep]
    label = model.vertex_label[faces[:, 0]]
    names = model.label_names
    colours = np.asarray([PART_COLOURS[names[k]] for k in label], dtype=np.float64)
    return Mesh(
        vertices=vertices,
        normals=vertex_normals(vertices, model.faces)[: len(vertices)],
        triangles=faces.astype(np.int32),
        colours=colours,
        object_ids=np.full(len(faces), object_id, dtype=np.int32),
        materials=np.full(len(faces), MAT_MATTE, dtype=np.int32),
    )


def floor_mesh(x0: float, x1: float, y0: float, y1: float) -> Mesh:
    v = np.array([[x0, y0, 0.0], [x1, y0, 0.0], [x1, y1, 0.0], [x0, y1, 0.0]])
    return Mesh(
        vertices=v,
        normals=np.tile([0.0, 0.0, 1.0], (4, 1)),
        triangles=np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int32),
        colours=np.full((2, 3), 150.0),
        object_ids=np.zeros(2, dtype=np.int32),
        materials=np.full(2, MAT_FLOOR, dtype=np.int32),
    )


def merge(meshes: list[Mesh]) -> Mesh:
    offsets = np.cumsum([0] + [len(m.vertices) for m in meshes[:-1]])
    return Mesh(
        vertices=np.concatenate([m.vertices for m in meshes]),
        normals=np.concatenate([m.normals for m in meshes]),
        triangles=np.concatenate(
            [m.triangles + o for m, o in zip(meshes, offsets, strict=True)]
        ).astype(np.int32),
        colours=np.concatenate([m.colours for m in meshes]),
        object_ids=np.concatenate([m.object_ids for m in meshes]),
        materials=np.concatenate([m.materials for m in meshes]),
    )


def camera_frame(
    position: tuple[float, float, float], forward: tuple[float, float, float]
) -> Frame:
    """world_T_optical for a level camera at ``position`` looking along ``forward``."""
    f = np.asarray(forward, dtype=np.float64)
    f = f / np.sqrt(f @ f)
    right = np.array([f[1], -f[0], 0.0])
    right = right / np.sqrt(right @ right)
    down = np.cross(f, right)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = right, down, f, position
    return Frame.from_matrix(T)


def render_row(
    meshes: list[Mesh], centre: tuple[float, float, float], frame: Frame, size: tuple[int, int]
) -> NDArray[np.uint8]:
    w, h = size
    camera = CameraModel(width=w, height=h, fx=2.2 * h, fy=2.2 * h, cx=w / 2, cy=h / 2)
    cx, cy, _ = centre
    mesh = merge([*meshes, floor_mesh(cx - 6, cx + 6, cy - 6, cy + 6)])
    hits = render_hits(make_scene(mesh), camera, frame)
    image = shade(mesh, hits, light_direction(200.0, 50.0), 0.5)
    return np.clip(image, 0, 255).astype(np.uint8)


def sheet(out: Path) -> None:
    model = BodyModel.load()
    bodies = [model.shaped(s) for s in PEOPLE]
    n = len(bodies)
    gap = 0.9
    ys = [(i - (n - 1) / 2) * gap for i in range(n)]
    rows = []
    # 1. rest pose, front; 2. standing, front (camera at +x looking -x; people face +x)
    for make in (lambda b: Pose(), stand_pose):
        meshes = [
            body_mesh(b, b.posed(make(b).placed((0.0, y, 0.0), 0.0)), i + 1)
            for i, (b, y) in enumerate(zip(bodies, ys, strict=True))
        ]
        rows.append(
            render_row(meshes, (0, 0, 0), camera_frame((7.0, 0.0, 0.95), (-1, 0, 0)), (1400, 360))
        )
    # 3. walking, side view: a body frame moving at constant speed, 8 phases; and sitting
    walker = bodies[1]
    stride = natural_stride(walker, 1.2)
    meshes = []
    for k in range(8):
        phase = k / 8
        x0 = -3.2 + k * 0.8
        pose = walk_pose(walker, phase, stride_m=stride)
        meshes.append(body_mesh(walker, walker.posed(pose.placed((x0, 0.0, 0.0), 0.0)), k + 1))
    sitter = bodies[0]
    meshes.append(body_mesh(sitter, sitter.posed(sit_pose(sitter).placed((3.6, 0.0, 0.0), 0.0)), 9))
    rows.append(
        render_row(meshes, (0, 0, 0), camera_frame((0.2, -7.5, 0.9), (0, 1, 0)), (1400, 360))
    )
    # 4. walking, front view
    meshes = []
    for k in range(6):
        pose = walk_pose(bodies[k], k / 6, stride_m=natural_stride(bodies[k], 1.2))
        meshes.append(
            body_mesh(bodies[k], bodies[k].posed(pose.placed((0.0, ys[k], 0.0), 0.0)), k + 1)
        )
    rows.append(
        render_row(meshes, (0, 0, 0), camera_frame((7.0, 0.0, 0.95), (-1, 0, 0)), (1400, 360))
    )
    image = np.concatenate(rows, axis=0)
    out.parent.mkdir(parents=True, exist_ok=True)
    cv2.imwrite(str(out), cv2.cvtColor(image, cv2.COLOR_RGB2BGR))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("-o", "--out", type=Path, default=Path("/tmp/bodies.png"))
    args = parser.parse_args()
    sheet(args.out)
    print(args.out)


if __name__ == "__main__":
    main()
