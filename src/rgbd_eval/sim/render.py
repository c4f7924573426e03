"""Rendering: depth, triangle ids and shaded colour of what each camera pixel sees.

Rays go through pixel centres with unit z in the camera's optical frame, so the hit
distance is directly the depth z. The ray casting is our own (:mod:`rgbd_eval.sim.raster`)
and every step after it uses :mod:`rgbd_eval.exact`, so a scenario renders to the same
bytes on every CPU. Shading is Lambertian with a hemispheric ambient term, smooth
(barycentric) vertex normals and a tiled floor.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from rgbd_eval import exact
from rgbd_eval.sim.meshes import MAT_FLOOR, Mesh
from rgbd_eval.sim.raster import RayBundle, binned_rays, pixel_rays
from rgbd_eval.sim.world import NO_HIT
from rgbd_eval.types import CameraModel, Pose

F64 = NDArray[np.float64]
F32 = NDArray[np.float32]
I32 = NDArray[np.int32]

BACKGROUND = 25.0


@dataclass(frozen=True)
class Hits:
    """What one camera sees: depth z (NaN: nothing), triangle index (-1: nothing), ray data."""

    depth: F32  # (H, W)
    triangle: I32  # (H, W)
    uv: F32  # (H, W, 2) barycentric coordinates
    face_normals: F32  # (H, W, 3) unit geometric normals of the hit triangles
    origin: F64  # (3,) world ray origin
    directions: F32  # (H, W, 3) world ray directions (unit optical z)

    def points(self) -> F32:
        """World hit points (H, W, 3), NaN where nothing was hit."""
        o = self.origin.astype(np.float32)
        out: F32 = o + self.directions * self.depth[..., None]
        return out


@dataclass(frozen=True, eq=False)
class Scene:
    """Triangles to cast rays against: world vertices and per-triangle unit normals."""

    vertices: F64  # (V, 3)
    triangles: I32  # (T, 3)
    face_normals: F32  # (T, 3)

    @property
    def n_triangles(self) -> int:
        return int(self.triangles.shape[0])


def make_scene(mesh: Mesh) -> Scene:
    """The ray-casting scene of ``mesh``."""
    v = np.ascontiguousarray(mesh.vertices, dtype=np.float64)
    t = np.ascontiguousarray(mesh.triangles, dtype=np.int32)
    if len(t):
        a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
        n = exact.cross(b - a, c - a)
        n = n / np.maximum(exact.norm(n), 1e-300)[:, None]
    else:
        n = np.zeros((0, 3))
    return Scene(v, t, n.astype(np.float32))


def to_frame(points: F64, pose: Pose) -> F64:
    """World points (N, 3) in the frame of ``pose`` (world_T_frame): R^T (p - t)."""
    R = pose.rotation_matrix()
    return exact.matmul(np.asarray(points, dtype=np.float64) - np.asarray(pose.translation), R)


@lru_cache(maxsize=16)
def _camera_rays(
    width: int, height: int, fx: float, fy: float, cx: float, cy: float
) -> tuple[F64, NDArray[np.int64]]:
    d, cells = pixel_rays(width, height, fx, fy, cx, cy)
    d.setflags(write=False)
    cells.setflags(write=False)
    return d, cells


class CameraCast:
    """One camera's pixel rays from a pose, with the nearest hits cast so far."""

    def __init__(self, camera: CameraModel, pose: Pose) -> None:
        self.camera = camera
        self.pose = pose
        c = camera
        d, cells = _camera_rays(c.width, c.height, c.fx, c.fy, c.cx, c.cy)
        self._bundle = RayBundle(d, cells, (c.fx, c.fy, c.cx, c.cy), (c.width, c.height))
        R = pose.rotation_matrix()
        world = exact.matmul(d, R.T).astype(np.float32).reshape(c.height, c.width, 3)
        world.setflags(write=False)
        #: World ray directions (H, W, 3), shared by the copies.
        self.directions = world

    def copy(self) -> CameraCast:
        """The same rays and hits, to be cast into independently."""
        out = object.__new__(CameraCast)
        out.__dict__.update(self.__dict__)
        out._bundle = self._bundle.copy()
        return out

    def cast(self, scene: Scene, triangle_offset: int = 0) -> None:
        """Keep the nearer hits of ``scene``; its triangle ids are shifted by ``triangle_offset``."""
        self._bundle.cast(to_frame(scene.vertices, self.pose), scene.triangles, triangle_offset)

    def hits(self, face_normals: F32) -> Hits:
        """The hits so far; ``face_normals`` (T, 3) of every triangle id that was cast."""
        b = self._bundle
        h, w = self.camera.height, self.camera.width
        hit = b.triangle >= 0
        depth = np.where(hit, b.t, np.nan).astype(np.float32)
        uv = np.stack([b.u, b.v], axis=1).astype(np.float32)
        normals = np.zeros((len(hit), 3), dtype=np.float32)
        normals[hit] = face_normals[b.triangle[hit]]
        return Hits(
            depth.reshape(h, w),
            b.triangle.reshape(h, w),
            uv.reshape(h, w, 2),
            normals.reshape(h, w, 3),
            np.asarray(self.pose.translation, dtype=np.float64),
            self.directions,
        )


def render_hits(scene: Scene, camera: CameraModel, pose: Pose) -> Hits:
    """Cast one ray per pixel of ``camera`` placed at ``pose`` (world_T_optical)."""
    cast = CameraCast(camera, pose)
    cast.cast(scene)
    return cast.hits(scene.face_normals)


def occluded_towards(
    scenes: list[Scene], points: F32 | F64, target: F64, rotation: F64
) -> NDArray[np.bool_]:
    """For world points (N, 3): is the segment to ``target`` blocked in any of ``scenes``?

    Each segment ends 1 cm off its point, so a surface does not shadow itself unless it
    faces away from the target. ``rotation`` (world_R_frame) orients a frame at
    ``target`` in which the points lie ahead (z > 0); points that do not are reported
    as not blocked.
    """
    p = np.asarray(points, dtype=np.float64)
    blocked = np.zeros(len(p), dtype=bool)
    if len(p) == 0:
        return blocked
    tgt = np.asarray(target, dtype=np.float64)
    d = tgt - p
    length = exact.norm(d)
    end = p + d * (np.minimum(0.01, 0.5 * length) / np.maximum(length, 1e-9))[:, None]
    frame = Pose.from_matrix(_homogeneous(rotation, tgt))
    rays = to_frame(end, frame)
    ahead = np.flatnonzero(rays[:, 2] > 1e-9)
    if ahead.size == 0:
        return blocked
    cells, grid, size = binned_rays(rays[ahead])
    bundle = RayBundle(rays[ahead], cells, grid, size, t_max=np.ones(ahead.size))
    for scene in scenes:
        bundle.cast(to_frame(scene.vertices, frame), scene.triangles)
    blocked[ahead] = bundle.triangle >= 0
    return blocked


def _homogeneous(rotation: F64, translation: F64) -> F64:
    T = np.eye(4)
    T[:3, :3] = rotation
    T[:3, 3] = translation
    return T


def object_ids(mesh: Mesh, hits: Hits) -> I32:
    """Per-pixel object id (``NO_HIT`` where nothing was hit)."""
    tri = hits.triangle
    ids: I32 = np.where(tri >= 0, mesh.object_ids[np.maximum(tri, 0)], NO_HIT).astype(np.int32)
    return ids


def light_direction(azimuth_deg: float, elevation_deg: float) -> F64:
    """Unit vector towards the light (world, z up)."""
    sa, ca = exact.sincos(azimuth_deg * (exact.PI / 180.0))
    se, ce = exact.sincos(elevation_deg * (exact.PI / 180.0))
    return np.array([ce * ca, ce * sa, se])


def floor_pattern(points: NDArray[np.float32], tile: float) -> NDArray[np.float32]:
    """Brightness factor of a tiled floor at world points (N, 3): checker and dark grout."""
    fx = points[:, 0] / np.float32(tile)
    fy = points[:, 1] / np.float32(tile)
    checker = (np.floor(fx) + np.floor(fy)) % 2.0
    rx, ry = fx % 1.0, fy % 1.0
    grout = (np.minimum(rx, ry) < 0.03) | (np.maximum(rx, ry) > 0.97)
    k = np.where(grout, 0.7, np.where(checker > 0, 1.06, 0.94))
    return k.astype(np.float32)


def shade(mesh: Mesh, hits: Hits, light: F64, floor_tile: float) -> NDArray[np.float32]:
    """Lit colour image ((H, W, 3) float32, 0..255): Lambert plus hemispheric ambient."""
    H, W = hits.triangle.shape
    tri = hits.triangle.reshape(-1)
    hit = tri >= 0
    safe = np.maximum(tri, 0)
    colour = mesh.colours.astype(np.float32)[safe]
    floor = np.flatnonzero(hit & (mesh.materials[safe] == MAT_FLOOR))
    if floor.size:
        d_floor = hits.directions.reshape(-1, 3)[floor]
        pts = hits.origin.astype(np.float32) + d_floor * hits.depth.reshape(-1)[floor, None]
        colour[floor] *= floor_pattern(pts, floor_tile)[:, None]
    # smooth normals on curved parts (vertex normals differ): barycentric blend;
    # flat faces keep the ray caster's face normal
    n = hits.face_normals.reshape(-1, 3).copy()
    corner_normals = mesh.normals.astype(np.float32)[mesh.triangles]  # (T, 3, 3)
    curved_tri = np.abs(corner_normals - corner_normals[:, :1]).max(axis=(1, 2)) > 1e-4
    curved = np.flatnonzero(hit & curved_tri[safe])
    if curved.size:
        c = corner_normals[tri[curved]]
        uv = hits.uv.reshape(-1, 2)[curved]
        u, v = uv[:, 0:1], uv[:, 1:2]
        n[curved] = c[:, 0] * (1.0 - u - v) + c[:, 1] * u + c[:, 2] * v
    d = hits.directions.reshape(-1, 3)
    # unit length, turned towards the camera (shade the side that is seen)
    facing = n[:, 0] * d[:, 0] + n[:, 1] * d[:, 1] + n[:, 2] * d[:, 2]
    sign = np.where(facing > 0, np.float32(-1.0), np.float32(1.0))
    length = np.sqrt(n[:, 0] * n[:, 0] + n[:, 1] * n[:, 1] + n[:, 2] * n[:, 2])
    n *= (sign / np.maximum(length, np.float32(1e-6)))[:, None]
    lx, ly, lz = (np.float32(c) for c in light)
    lambert = np.clip(n[:, 0] * lx + n[:, 1] * ly + n[:, 2] * lz, 0.0, None)
    intensity = np.float32(0.38) + np.float32(0.12) * n[:, 2] + np.float32(0.62) * lambert
    out = colour * intensity[:, None]
    out[~hit] = BACKGROUND
    image: NDArray[np.float32] = out.reshape(H, W, 3)
    return image


def count_hits(
    mesh: Mesh, camera: CameraModel, pose: Pose, box: tuple[int, int, int, int]
) -> float:
    """Pixels of ``camera`` covered by ``mesh`` alone inside integer box (u0, v0, u1, v1).

    The box may extend beyond the image; large boxes are sampled on a coarser grid
    and the count scaled, keeping the cost near 8000 rays.
    """
    u0, v0, u1, v1 = box
    area = max(0, u1 - u0) * max(0, v1 - v0)
    if area == 0 or mesh.n_triangles == 0:
        return 0.0
    step = max(1, math.ceil(math.sqrt(area / 8000.0)))
    # a grid whose cell (i, j) is the image pixel (u0 + i step, v0 + j step)
    nw, nh = len(range(u0, u1, step)), len(range(v0, v1, step))
    grid = (camera.fx / step, camera.fy / step, (camera.cx - u0) / step, (camera.cy - v0) / step)
    us = (np.arange(u0, u1, step, dtype=np.float64) - camera.cx) / camera.fx
    vs = (np.arange(v0, v1, step, dtype=np.float64) - camera.cy) / camera.fy
    d = np.empty((nh, nw, 3))
    d[..., 0], d[..., 1], d[..., 2] = us[None, :], vs[:, None], 1.0
    bundle = RayBundle(d.reshape(-1, 3), np.arange(nw * nh, dtype=np.int64), grid, (nw, nh))
    bundle.cast(to_frame(mesh.vertices, pose), mesh.triangles)
    return float(np.count_nonzero(bundle.triangle >= 0) * step * step)
