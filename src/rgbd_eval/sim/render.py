"""Ray casting with Open3D: depth, object ids and shaded colour in one pass per camera.

Rays have unit z in the camera's optical frame, so the hit distance ``t_hit``
is directly the depth z. Shading is Lambertian with a hemispheric ambient
term, smooth (barycentric) vertex normals and a tiled floor.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
import open3d as o3d
from numpy.typing import NDArray

from rgbd_eval.sim.meshes import MAT_FLOOR, Mesh
from rgbd_eval.sim.world import NO_HIT
from rgbd_eval.types import CameraModel, Pose

F64 = NDArray[np.float64]
I32 = NDArray[np.int32]

BACKGROUND = 25.0
_INVALID = np.uint32(0xFFFFFFFF)


@dataclass(frozen=True)
class Hits:
    """What one camera sees: depth z (NaN: nothing), triangle index (-1: nothing), ray data."""

    depth: NDArray[np.float32]  # (H, W)
    triangle: I32  # (H, W)
    uv: NDArray[np.float32]  # (H, W, 2) barycentric coordinates
    face_normals: NDArray[np.float32]  # (H, W, 3) geometric normals of the hit triangles
    origin: F64  # (3,) world ray origin
    directions: NDArray[np.float32]  # (H, W, 3) world ray directions (unit optical z)

    def points(self) -> NDArray[np.float32]:
        """World hit points (H, W, 3), NaN where nothing was hit."""
        o = self.origin.astype(np.float32)
        out: NDArray[np.float32] = o + self.directions * self.depth[..., None]
        return out


def camera_rays(
    camera: CameraModel, pose: Pose, pixels: F64 | None = None
) -> tuple[F64, NDArray[np.floating[Any]]]:
    """World ray origin (3,) and directions (..., 3) through pixel centres (or ``pixels`` (N, 2))."""
    if pixels is None:
        d = _optical_rays(camera.width, camera.height, camera.fx, camera.fy, camera.cx, camera.cy)
    else:
        d = np.stack(
            [
                (pixels[:, 0] - camera.cx) / camera.fx,
                (pixels[:, 1] - camera.cy) / camera.fy,
                np.ones(len(pixels)),
            ],
            axis=1,
        )
    R = pose.rotation_matrix().astype(d.dtype)
    return np.asarray(pose.translation, dtype=np.float64), d @ R.T


@lru_cache(maxsize=8)
def _optical_rays(
    w: int, h: int, fx: float, fy: float, cx: float, cy: float
) -> NDArray[np.float32]:
    rays = CameraModel(w, h, fx, fy, cx, cy).rays().astype(np.float32)
    rays.setflags(write=False)
    return rays


def make_scene(mesh: Mesh) -> o3d.t.geometry.RaycastingScene:
    """An Open3D ray-casting scene holding ``mesh`` as one geometry."""
    scene = o3d.t.geometry.RaycastingScene()
    if mesh.n_triangles:
        scene.add_triangles(
            o3d.core.Tensor.from_numpy(np.ascontiguousarray(mesh.vertices, dtype=np.float32)),
            o3d.core.Tensor.from_numpy(np.ascontiguousarray(mesh.triangles, dtype=np.uint32)),
        )
    return scene


def cast(
    scene: o3d.t.geometry.RaycastingScene, origin: F64, directions: NDArray[np.floating[Any]]
) -> tuple[NDArray[np.float32], I32, NDArray[np.float32], NDArray[np.float32]]:
    """Cast rays: (t_hit, NaN for misses; triangle index or -1; barycentric uv; face normal)."""
    shape = directions.shape[:-1]
    flat = directions.reshape(-1, 3)
    rays = np.empty((flat.shape[0], 6), dtype=np.float32)
    rays[:, :3] = origin
    rays[:, 3:] = flat
    out = scene.cast_rays(o3d.core.Tensor.from_numpy(rays), nthreads=1)
    t = out["t_hit"].numpy()
    t[~np.isfinite(t)] = np.nan  # misses come back as +inf
    tri = out["primitive_ids"].numpy().view(np.int32)  # the invalid id 0xFFFFFFFF is -1
    uv = out["primitive_uvs"].numpy()
    fn = out["primitive_normals"].numpy()
    return t.reshape(shape), tri.reshape(shape), uv.reshape(*shape, 2), fn.reshape(*shape, 3)


def render_hits(scene: o3d.t.geometry.RaycastingScene, camera: CameraModel, pose: Pose) -> Hits:
    """Cast one ray per pixel of ``camera`` placed at ``pose`` (world_T_optical)."""
    origin, dirs = camera_rays(camera, pose)
    depth, tri, uv, fn = cast(scene, origin, dirs)
    return Hits(depth, tri, uv, fn, origin, dirs.astype(np.float32))


def overlay_hits(
    base: Hits,
    scene: o3d.t.geometry.RaycastingScene,
    window: tuple[int, int, int, int],
    triangle_offset: int,
) -> Hits:
    """``base`` with the nearer hits of a second scene cast inside ``window`` (u0, v0, u1, v1).

    Casting the same rays against two scenes and keeping the nearer hit equals one
    cast against their union; the second scene's triangle indices are shifted by
    ``triangle_offset`` (its place in the concatenated mesh). Rendering the static
    scene once and only the people's image region per frame is what keeps a
    static camera fast.
    """
    u0, v0, u1, v1 = window
    H, W = base.triangle.shape
    if not (0 <= u0 <= u1 <= W and 0 <= v0 <= v1 <= H):
        raise ValueError(f"window={window} must lie inside the {W}x{H} image")
    depth, tri, uv, fn = (
        base.depth.copy(),
        base.triangle.copy(),
        base.uv.copy(),
        base.face_normals.copy(),
    )
    if u1 > u0 and v1 > v0:
        dirs = base.directions[v0:v1, u0:u1]
        t, t_tri, t_uv, t_fn = cast(scene, base.origin, dirs)
        old = depth[v0:v1, u0:u1]
        nearer = (t_tri >= 0) & ~(t >= old)  # also where the base saw nothing (NaN)
        depth[v0:v1, u0:u1] = np.where(nearer, t, old)
        tri[v0:v1, u0:u1] = np.where(nearer, t_tri + triangle_offset, tri[v0:v1, u0:u1])
        uv[v0:v1, u0:u1] = np.where(nearer[..., None], t_uv, uv[v0:v1, u0:u1])
        fn[v0:v1, u0:u1] = np.where(nearer[..., None], t_fn, fn[v0:v1, u0:u1])
    return Hits(depth, tri, uv, fn, base.origin, base.directions)


def occluded_towards(
    scenes: list[o3d.t.geometry.RaycastingScene], points: NDArray[np.float32], target: F64
) -> NDArray[np.bool_]:
    """For world points (N, 3): is the segment to ``target`` blocked in any of ``scenes``?

    Each segment starts 1 cm off its point, so a surface does not shadow itself
    unless it faces away from the target.
    """
    if len(points) == 0:
        return np.zeros(0, dtype=bool)
    p = points.astype(np.float64)
    d = target - p
    length = np.linalg.norm(d, axis=1, keepdims=True)
    start = p + d * (np.minimum(0.01, 0.5 * length) / np.maximum(length, 1e-9))
    rays = np.empty((len(p), 6), dtype=np.float32)
    rays[:, :3] = start
    rays[:, 3:] = target - start
    tensor = o3d.core.Tensor.from_numpy(rays)
    blocked = np.zeros(len(p), dtype=bool)
    for scene in scenes:
        blocked |= scene.test_occlusions(tensor, tfar=1.0, nthreads=1).numpy().astype(bool)
    return blocked


def object_ids(mesh: Mesh, hits: Hits) -> I32:
    """Per-pixel object id (``NO_HIT`` where nothing was hit)."""
    tri = hits.triangle
    ids: I32 = np.where(tri >= 0, mesh.object_ids[np.maximum(tri, 0)], NO_HIT).astype(np.int32)
    return ids


def light_direction(azimuth_deg: float, elevation_deg: float) -> F64:
    """Unit vector towards the light (world, z up)."""
    az, el = math.radians(azimuth_deg), math.radians(elevation_deg)
    return np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])


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
    sign = np.where(np.einsum("ij,ij->i", n, d) > 0, np.float32(-1.0), np.float32(1.0))
    n *= (sign / np.maximum(np.sqrt(np.einsum("ij,ij->i", n, n)), np.float32(1e-6)))[:, None]
    lambert = np.clip(n @ light.astype(np.float32), 0.0, None)
    intensity = np.float32(0.38) + np.float32(0.12) * n[:, 2] + np.float32(0.62) * lambert
    out = colour * intensity[:, None]
    out[~hit] = BACKGROUND
    return out.reshape(H, W, 3)


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
    us = np.arange(u0, u1, step, dtype=np.float64)
    vs = np.arange(v0, v1, step, dtype=np.float64)
    uu, vv = np.meshgrid(us, vs)
    pixels = np.stack([uu.ravel(), vv.ravel()], axis=1)
    origin, dirs = camera_rays(camera, pose, pixels)
    _, tri, _, _ = cast(make_scene(mesh), origin, dirs)
    return float(np.count_nonzero(tri >= 0) * step * step)
