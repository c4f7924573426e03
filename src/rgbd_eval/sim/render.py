"""Rendering: depth, triangle ids and shaded colour of what each camera pixel sees.

Rays go through pixel centres with unit z in the camera's optical frame, so the hit
distance is directly the depth z. The ray casting is our own (:mod:`rgbd_eval.sim.raster`)
and every step after it uses :mod:`rgbd_eval.exact`, so a scenario renders to the same
bytes on every CPU. Shading is Lambertian with a hemispheric ambient term, smooth
(barycentric) vertex normals and a tiled floor.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import lru_cache

import numba
import numpy as np
from numpy.typing import NDArray

from rgbd_eval import exact
from rgbd_eval.sim.meshes import (
    MAT_FLOOR,
    MAT_WALL,
    PATTERN_CHECK,
    PATTERN_DOTS,
    PATTERN_NONE,
    PATTERN_STRIPES,
    PATTERN_WEAVE,
    Mesh,
    Surface,
)
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


def _gather(
    triangle: I32,
    t: F64,
    u: F64,
    v: F64,
    face_normals: F32,
    depth: F32,
    uv: F32,
    normals: F32,
) -> None:
    """Per ray: depth (NaN: no hit), barycentrics and the hit triangle's normal (0: none),
    as float32 (each value rounded once, as numpy's casts do)."""
    for i in range(triangle.shape[0]):
        k = triangle[i]
        uv[i, 0] = u[i]
        uv[i, 1] = v[i]
        if k >= 0:
            depth[i] = t[i]
            normals[i, 0] = face_normals[k, 0]
            normals[i, 1] = face_normals[k, 1]
            normals[i, 2] = face_normals[k, 2]
        else:
            depth[i] = np.nan
            normals[i, 0] = 0.0
            normals[i, 1] = 0.0
            normals[i, 2] = 0.0


_gather_kernel: Callable[..., None] = numba.njit(cache=True)(_gather)


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
        n = len(b.triangle)
        depth = np.empty(n, dtype=np.float32)
        uv = np.empty((n, 2), dtype=np.float32)
        normals = np.empty((n, 3), dtype=np.float32)
        _gather_kernel(
            b.triangle, b.t, b.u, b.v, np.ascontiguousarray(face_normals), depth, uv, normals
        )
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


def _hash01(i: NDArray[np.int64], j: NDArray[np.int64]) -> F64:
    """A fixed pseudo-random value in [0, 1) per integer cell (integer arithmetic only)."""
    h = (i * 73856093) ^ (j * 19349663) ^ 0x5BD1E995
    h = (h ^ (h >> 13)) * 1274126177
    out: F64 = ((h ^ (h >> 16)) & 0xFFFF).astype(np.float64) / 65536.0
    return out


def pattern_mask(kind: NDArray[np.int32], uv: F64, scale: F64) -> F64:
    """How much of the second colour shows (0..1) at texture coordinates ``uv`` (N, 2)."""
    su, sv = uv[:, 0] * scale, uv[:, 1] * scale
    fu, fv = su - np.floor(su), sv - np.floor(sv)
    iu, iv = np.floor(su).astype(np.int64), np.floor(sv).astype(np.int64)
    stripes = (fv < 0.45).astype(np.float64)
    check = 0.5 * (fu < 0.3) + 0.5 * (fv < 0.3)
    du = fu - (0.3 + 0.4 * _hash01(iu, iv))
    dv = fv - (0.3 + 0.4 * _hash01(iv + 7, iu + 3))
    dots = ((du * du + dv * dv) < 0.04).astype(np.float64)
    weave = 0.22 * _hash01(iu, iv)
    out: F64 = np.select(
        [
            kind == PATTERN_STRIPES,
            kind == PATTERN_CHECK,
            kind == PATTERN_DOTS,
            kind == PATTERN_WEAVE,
        ],
        [stripes, check, dots, weave],
        0.0,
    )
    return out


def surface_colours(surface: Surface, tri: I32, bary: NDArray[np.float32], flat: F64) -> F64:
    """Albedo (N, 3) at hits on triangles ``tri`` with barycentrics ``bary`` (N, 2); ``flat``
    (N, 3) is the triangles' flat colour, kept where the surface has no detail."""
    colour: F64 = np.array(flat, dtype=np.float64)
    kind = surface.pattern[tri]
    sel = np.flatnonzero(surface.detailed()[tri])
    if sel.size == 0:
        return colour
    t = tri[sel]
    u = bary[sel, 0:1].astype(np.float64)
    v = bary[sel, 1:2].astype(np.float64)
    w = 1.0 - u - v
    cc = surface.corner_colours[t]
    colour[sel] = cc[:, 0] * w + cc[:, 1] * u + cc[:, 2] * v
    patterned = np.flatnonzero(kind[sel] != PATTERN_NONE)
    if patterned.size:
        at = sel[patterned]
        tp = t[patterned]
        tuv = surface.uv[tp]
        wp, up, vp = w[patterned], u[patterned], v[patterned]
        uv = tuv[:, 0] * wp + tuv[:, 1] * up + tuv[:, 2] * vp
        m = pattern_mask(kind[at], uv, surface.scale[tp])[:, None]
        colour[at] = colour[at] * (1.0 - m) + surface.colour2[tp] * m
    return colour


def wall_pattern(points: NDArray[np.float32]) -> F64:
    """Brightness factor of painted plaster at world points (N, 3): a faint mottle (+-3 %)
    over 3 cm cells, and a coarser one (+-2 %) over 25 cm."""
    p = points.astype(np.float64)
    along = p[:, 0] + p[:, 1]  # walls run along x or y
    fine = _hash01(
        np.floor(along / 0.03).astype(np.int64), np.floor(p[:, 2] / 0.03).astype(np.int64)
    )
    coarse = _hash01(
        np.floor(along / 0.25).astype(np.int64) + 11, np.floor(p[:, 2] / 0.25).astype(np.int64)
    )
    out: F64 = 1.0 + 0.06 * (fine - 0.5) + 0.04 * (coarse - 0.5)
    return out


def contact_shadow(
    points: NDArray[np.float32], casters: Sequence[tuple[float, float, float]]
) -> F64:
    """Brightness factor (N,) of floor points under soft shadows of ``casters`` (x, y, radius):
    darkest (0.55) under each, fading over its radius (ambient light blocked by a body)."""
    k = np.ones(len(points))
    p = points.astype(np.float64)
    for x, y, r in casters:
        dx, dy = p[:, 0] - x, p[:, 1] - y
        k = k * (1.0 - 0.45 * exact.exp(-(dx * dx + dy * dy) / (2.0 * r * r)))
    return k


def _lookup(flags: NDArray[np.bool_], tri: I32) -> NDArray[np.bool_]:
    """Per pixel: ``flags`` of its triangle (False where nothing was hit)."""
    out: NDArray[np.bool_] = np.concatenate([flags, [False]])[tri]  # tri -1 reads the False
    return out


def _albedo(tri: I32, colours: NDArray[np.float32], out: NDArray[np.float32]) -> None:
    """Per pixel: its triangle's flat colour (anything where nothing was hit)."""
    for p in range(tri.shape[0]):
        t = max(tri[p], 0)
        for k in range(3):
            out[p, k] = colours[t, k]


_albedo_kernel: Callable[..., None] = numba.njit(cache=True)(_albedo)


def _light(
    tri: I32,
    bary: NDArray[np.float32],
    face_normals: NDArray[np.float32],
    directions: NDArray[np.float32],
    triangles: I32,
    normals: NDArray[np.float32],
    smooth: NDArray[np.bool_],
    albedo: NDArray[np.float32],
    light: NDArray[np.float32],
    out: NDArray[np.float32],
) -> None:
    """Per pixel: the normal (blended from the vertex normals on smooth triangles, the face
    normal on flat ones, turned towards the camera), Lambert plus hemispheric ambient light
    on the albedo; the background where nothing was hit. float32, a fixed order."""
    one = np.float32(1.0)
    for p in range(tri.shape[0]):
        t = tri[p]
        if t < 0:
            for k in range(3):
                out[p, k] = np.float32(BACKGROUND)
            continue
        if smooth[t]:
            u, v = bary[p, 0], bary[p, 1]
            w = one - u - v
            a, b, c = triangles[t, 0], triangles[t, 1], triangles[t, 2]
            nx = normals[a, 0] * w + normals[b, 0] * u + normals[c, 0] * v
            ny = normals[a, 1] * w + normals[b, 1] * u + normals[c, 1] * v
            nz = normals[a, 2] * w + normals[b, 2] * u + normals[c, 2] * v
        else:
            nx, ny, nz = face_normals[p, 0], face_normals[p, 1], face_normals[p, 2]
        facing = nx * directions[p, 0] + ny * directions[p, 1] + nz * directions[p, 2]
        length = np.sqrt(nx * nx + ny * ny + nz * nz)
        scale = (-one if facing > 0 else one) / max(length, np.float32(1e-6))
        nx, ny, nz = nx * scale, ny * scale, nz * scale
        lambert = max(nx * light[0] + ny * light[1] + nz * light[2], np.float32(0.0))
        intensity = np.float32(0.38) + np.float32(0.12) * nz + np.float32(0.62) * lambert
        for k in range(3):
            out[p, k] = albedo[p, k] * intensity


_light_kernel: Callable[..., None] = numba.njit(cache=True)(_light)


def shade(
    mesh: Mesh,
    hits: Hits,
    light: F64,
    floor_tile: float,
    casters: Sequence[tuple[float, float, float]] = (),
) -> NDArray[np.float32]:
    """Lit colour image ((H, W, 3) float32, 0..255): Lambert plus hemispheric ambient.

    Textured surfaces (:class:`~rgbd_eval.sim.meshes.Surface`) are drawn per pixel; the
    floor gets its tiles and the soft contact shadows of ``casters`` (x, y, radius).
    """
    H, W = hits.triangle.shape
    tri = hits.triangle.reshape(-1)
    colour = np.empty((len(tri), 3), dtype=np.float32)
    _albedo_kernel(tri, mesh.colours.astype(np.float32), colour)
    bary = hits.uv.reshape(-1, 2)
    if mesh.surface is not None:
        detailed = np.flatnonzero(_lookup(mesh.surface.detailed(), tri))
        if detailed.size:
            t = tri[detailed]
            colour[detailed] = surface_colours(
                mesh.surface, t, bary[detailed], colour[detailed].astype(np.float64)
            )
    wall = np.flatnonzero(_lookup(mesh.materials == MAT_WALL, tri))
    if wall.size:
        d_wall = hits.directions.reshape(-1, 3)[wall]
        pts = hits.origin.astype(np.float32) + d_wall * hits.depth.reshape(-1)[wall, None]
        colour[wall] *= wall_pattern(pts).astype(np.float32)[:, None]
    floor = np.flatnonzero(_lookup(mesh.materials == MAT_FLOOR, tri))
    if floor.size:
        d_floor = hits.directions.reshape(-1, 3)[floor]
        pts = hits.origin.astype(np.float32) + d_floor * hits.depth.reshape(-1)[floor, None]
        k = floor_pattern(pts, floor_tile).astype(np.float64)
        if casters:
            k = k * contact_shadow(pts, casters)
        colour[floor] *= k.astype(np.float32)[:, None]
    out = np.empty_like(colour)
    _light_kernel(
        tri,
        np.ascontiguousarray(hits.uv.reshape(-1, 2)),
        np.ascontiguousarray(hits.face_normals.reshape(-1, 3)),
        np.ascontiguousarray(hits.directions.reshape(-1, 3)),
        mesh.triangles,
        np.ascontiguousarray(mesh.normals, dtype=np.float32),
        mesh.smooth_triangles(),
        colour,
        np.asarray(light, dtype=np.float32),
        out,
    )
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
