"""Synthetic RGB-D frames by ray casting simple geometry (Open3D ``RaycastingScene``).

A floor, person-like figures (legs, torso, arms, neck, head) and boxes, seen by a
Kinect-like camera (640x480 RGB, depth at 640x480/320x240/160x120, the same
optical centre). World is z-up; the camera pose is ``world_T_depth_optical``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import open3d as o3d
from numpy.typing import NDArray

from rgbd_eval.types import OPTICAL_TO_BODY, CameraModel, Frame, Pose

RGB_CAMERA = CameraModel(640, 480, 525.0, 525.0, 319.5, 239.5, frame_id="rgb")
#: Kinect depth noise: sigma = k d^2 (seed 000, Figure 6.1; k of Khoshelham & Elberink).
DEPTH_NOISE_K = 0.001425


@dataclass(frozen=True)
class Person:
    """An upright figure standing at world ``(x, y)``, facing ``yaw`` (rad), ``height`` m tall."""

    x: float
    y: float
    height: float = 1.75
    yaw: float = 0.0
    shirt: tuple[int, int, int] = (200, 40, 40)
    trousers: tuple[int, int, int] = (30, 40, 120)


@dataclass(frozen=True)
class Block:
    """An axis-aligned box resting on the floor: centre ``(x, y)``, size ``(sx, sy, sz)``."""

    x: float
    y: float
    size: tuple[float, float, float]
    colour: tuple[int, int, int] = (150, 120, 90)


@dataclass
class Scene:
    people: list[Person] = field(default_factory=list)
    blocks: list[Block] = field(default_factory=list)
    floor_colour: tuple[int, int, int] = (170, 170, 160)
    wall_x: float | None = 9.0
    #: A side wall at world y = side_wall_y (the plane x-z), 2.6 m tall.
    side_wall_y: float | None = None
    #: A ceiling at this height over the whole floor.
    ceiling: float | None = None


def camera_pose(
    x: float = 0.0,
    y: float = 0.0,
    height: float = 1.0,
    pitch_deg: float = 0.0,
    yaw_deg: float = 0.0,
    roll_deg: float = 0.0,
) -> Pose:
    """``world_T_optical`` of a camera at ``(x, y, height)`` looking along yaw, pitched down."""
    cy, sy = np.cos(np.radians(yaw_deg)), np.sin(np.radians(yaw_deg))
    cp, sp = np.cos(np.radians(pitch_deg)), np.sin(np.radians(pitch_deg))
    cr, sr = np.cos(np.radians(roll_deg)), np.sin(np.radians(roll_deg))
    Rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    Ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])  # positive pitch looks down
    Rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    T = np.eye(4)
    T[:3, :3] = Rz @ Ry @ Rx
    T[:3, 3] = (x, y, height)
    return Pose.from_matrix(T).compose(OPTICAL_TO_BODY)


def _mesh(legacy: o3d.geometry.TriangleMesh) -> o3d.t.geometry.TriangleMesh:
    return o3d.t.geometry.TriangleMesh.from_legacy(legacy)


def _cylinder(radius: float, z0: float, z1: float, x: float, y: float) -> o3d.geometry.TriangleMesh:
    m = o3d.geometry.TriangleMesh.create_cylinder(radius, z1 - z0, resolution=24)
    m.translate((x, y, 0.5 * (z0 + z1)))
    return m


def _box(
    cx: float, cy: float, z0: float, sx: float, sy: float, sz: float
) -> o3d.geometry.TriangleMesh:
    m = o3d.geometry.TriangleMesh.create_box(sx, sy, sz)
    m.translate((cx - sx / 2, cy - sy / 2, z0))
    return m


def person_parts(p: Person) -> list[tuple[o3d.geometry.TriangleMesh, tuple[int, int, int]]]:
    """Primitive meshes of one figure (proportions of an adult, about eight heads tall)."""
    h = p.height
    head_r = h / 16.0
    shoulder = 0.82 * h
    hip = 0.5 * h
    c, s = np.cos(p.yaw), np.sin(p.yaw)

    def at(lat: float) -> tuple[float, float]:  # a point `lat` metres to the figure's left
        return (p.x - s * lat, p.y + c * lat)

    skin = (220, 180, 150)
    parts: list[tuple[o3d.geometry.TriangleMesh, tuple[int, int, int]]] = []
    for side in (-1.0, 1.0):
        lx, ly = at(side * 0.09 * h / 1.75)
        parts.append((_cylinder(0.07 * h / 1.75, 0.0, hip, lx, ly), p.trousers))
        ax, ay = at(side * 0.225 * h / 1.75)
        parts.append((_cylinder(0.045 * h / 1.75, 0.45 * h, shoulder, ax, ay), p.shirt))
    torso = o3d.geometry.TriangleMesh.create_box(0.22 * h / 1.75, 0.36 * h / 1.75, shoulder - hip)
    torso.translate((-0.11 * h / 1.75, -0.18 * h / 1.75, 0.0))
    torso.rotate(np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]), center=(0, 0, 0))
    torso.translate((p.x, p.y, hip))
    parts.append((torso, p.shirt))
    parts.append(
        (_cylinder(0.055 * h / 1.75, shoulder - 0.01, h - 2 * head_r + 0.02, p.x, p.y), skin)
    )
    head = o3d.geometry.TriangleMesh.create_sphere(head_r, resolution=20)
    head.translate((p.x, p.y, h - head_r))
    parts.append((head, (60, 40, 30)))
    return parts


def render(
    scene: Scene,
    pose: Pose,
    depth_size: tuple[int, int] = (160, 120),
    noise_seed: int | None = 0,
    index: int = 0,
    has_odometry: bool = True,
) -> Frame:
    """Ray-cast one frame: RGB at 640x480, depth at ``depth_size`` (NaN where nothing is hit)."""
    rc = o3d.t.geometry.RaycastingScene()
    colours: dict[int, tuple[int, int, int]] = {}
    floor = _box(0.0, 0.0, -0.1, 60.0, 60.0, 0.1)
    floor_id = rc.add_triangles(_mesh(floor))
    colours[floor_id] = scene.floor_colour
    if scene.wall_x is not None:
        wall = _box(scene.wall_x + 0.05, 0.0, 0.0, 0.1, 60.0, 3.0)
        colours[rc.add_triangles(_mesh(wall))] = (200, 200, 210)
    if scene.side_wall_y is not None:
        side = _box(0.0, scene.side_wall_y + np.sign(scene.side_wall_y) * 0.05, 0.0, 60.0, 0.1, 2.6)
        colours[rc.add_triangles(_mesh(side))] = (190, 200, 190)
    if scene.ceiling is not None:
        colours[rc.add_triangles(_mesh(_box(0.0, 0.0, scene.ceiling, 60.0, 60.0, 0.1)))] = (
            230,
            230,
            230,
        )
    for p in scene.people:
        for mesh, colour in person_parts(p):
            colours[rc.add_triangles(_mesh(mesh))] = colour
    for b in scene.blocks:
        colours[rc.add_triangles(_mesh(_box(b.x, b.y, 0.0, *b.size)))] = b.colour

    depth_camera = RGB_CAMERA.scaled(*depth_size)
    depth = _cast_depth(rc, pose, depth_camera)
    if noise_seed is not None:
        rng = np.random.default_rng(noise_seed + index)
        depth = depth + rng.normal(0.0, 1.0, depth.shape) * DEPTH_NOISE_K * depth**2
    rgb = _cast_rgb(rc, pose, RGB_CAMERA, colours, floor_id)
    return Frame.rgbd(
        index=index,
        stamp_ns=index * 33_333_333,
        rgb=rgb,
        depth=depth.astype(np.float32),
        rgb_camera=RGB_CAMERA,
        depth_camera=depth_camera,
        camera_pose=pose,
        world_frame="odom" if has_odometry else "camera",
        has_odometry=has_odometry,
    )


def _rays(pose: Pose, cam: CameraModel) -> NDArray[np.float32]:
    dirs = cam.rays().reshape(-1, 3) @ pose.rotation_matrix().T  # unit-depth rays in world
    origin = np.broadcast_to(np.asarray(pose.translation), dirs.shape)
    return np.hstack([origin, dirs]).astype(np.float32).reshape(cam.height, cam.width, 6)


def _cast_depth(
    rc: o3d.t.geometry.RaycastingScene, pose: Pose, cam: CameraModel
) -> NDArray[np.float64]:
    ans = rc.cast_rays(o3d.core.Tensor(_rays(pose, cam)))
    t = ans["t_hit"].numpy().astype(np.float64)  # unit-depth rays: t is the optical depth z
    t[~np.isfinite(t) | (t > 8.0)] = np.nan
    return t


def _cast_rgb(
    rc: o3d.t.geometry.RaycastingScene,
    pose: Pose,
    cam: CameraModel,
    colours: dict[int, tuple[int, int, int]],
    floor_id: int,
) -> NDArray[np.uint8]:
    rays = _rays(pose, cam)
    ans = rc.cast_rays(o3d.core.Tensor(rays))
    ids = ans["geometry_ids"].numpy().astype(np.int64)
    normals = ans["primitive_normals"].numpy()
    t = ans["t_hit"].numpy()
    table = np.zeros((max(colours) + 2, 3), dtype=np.float64)
    for k, col in colours.items():
        table[k] = col
    miss = ids >= len(table) - 1
    ids = np.where(miss, len(table) - 1, ids)
    base = table[ids]
    light = np.array([0.3, -0.4, 0.86])
    shade = 0.55 + 0.45 * np.abs(normals @ (light / np.linalg.norm(light)))
    img = base * shade[..., None]
    # A tiled floor (0.5 m tiles) gives the background some texture.
    hit = rays[..., :3] + rays[..., 3:] * np.where(np.isfinite(t), t, 0.0)[..., None]
    tiles = (np.floor(hit[..., 0] / 0.5) + np.floor(hit[..., 1] / 0.5)) % 2 == 0
    img[(ids == floor_id) & tiles] *= 0.8
    img[miss] = 0.0
    return np.clip(img, 0, 255).astype(np.uint8)


def ring_texture(width: int = 640, height: int = 480) -> NDArray[np.uint8]:
    """Concentric colour rings in integer arithmetic: edges of every orientation and spacing.

    Exactly reproducible anywhere (no floating point), so tests can rebuild it
    instead of storing it; channel ``c`` has rings about its own centre.
    """
    y, x = np.mgrid[0:height, 0:width].astype(np.int64)
    out = np.empty((height, width, 3), dtype=np.uint8)
    for c, (cx, cy, k) in enumerate(((150, 130, 37), (470, 300, 53), (330, 520, 71))):
        out[..., c] = (((x - cx) ** 2 + (y - cy) ** 2) // k * 7 % 256).astype(np.uint8)
    return out
