"""Our own ray caster: the nearest triangle along each ray, the same to the last bit on every CPU.

Rays leave one origin (a camera's centre, or a projector's) and are given in a frame
whose z axis points forward; a ray's cell is where its direction ``(x/z, y/z)`` falls
on a pinhole grid (``u = fx x/z + cx``). For a camera image the cell is the pixel and
each cell holds the ray through that pixel's centre. Each triangle is projected onto
the grid (clipped to ``z >= near``) and tested against the rays of the cells its
bounding box covers, with the Moller-Trumbore test in float64: the hit distance
``t`` along the ray and the barycentric ``(u, v)`` of the hit (weights
``1 - u - v, u, v`` of the triangle's vertices). The nearest hit wins; on equal
distances the triangle listed first.

Why not Embree (Open3D's ``RaycastingScene``): it divides with the CPU's approximate
reciprocal instructions, which differ between AMD and Intel and between its SSE, AVX2
and AVX-512 kernels, so its distances and barycentrics change in the last bits from
machine to machine. Here every operation is an IEEE add, multiply or divide in a fixed
order; numba compiles without fast-math, so nothing is fused or reordered.
"""

from __future__ import annotations

from collections.abc import Callable

import numba
import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]
I32 = NDArray[np.int32]
I64 = NDArray[np.int64]

#: Hits closer to the origin than this (metres along a unit-z ray) are not seen.
NEAR = 1e-3


@numba.njit(cache=True)
def _polygon(
    a: F64,
    b: F64,
    c: F64,
    projected: F64,
    corners: tuple[int, int, int],
    grid: F64,
    out: F64,
) -> int:
    """The grid coordinates of a triangle's part in front of ``z = near``, a convex polygon
    of up to four corners, into ``out`` (4, 2); returns the number of corners (0: none).

    Corners ahead are taken from ``projected``; where an edge crosses the plane, the
    crossing point is projected.
    """
    fx, fy, cx, cy, near = grid[0], grid[1], grid[2], grid[3], grid[4]
    n = 0
    for i in range(3):
        p = a if i == 0 else b if i == 1 else c
        q = b if i == 0 else c if i == 1 else a
        if p[2] >= near:
            out[n, 0] = projected[corners[i], 0]
            out[n, 1] = projected[corners[i], 1]
            n += 1
        if (p[2] >= near) != (q[2] >= near):  # the edge crosses the plane: its crossing point
            s = (near - p[2]) / (q[2] - p[2])
            x = p[0] + s * (q[0] - p[0])
            y = p[1] + s * (q[1] - p[1])
            out[n, 0] = fx * (x / near) + cx
            out[n, 1] = fy * (y / near) + cy
            n += 1
    return n


@numba.njit(cache=True)
def _row_span(poly: F64, n: int, lo: float, hi: float) -> tuple[float, float, bool]:
    """The u extent of the convex polygon ``poly[:n]`` within the band ``lo <= v <= hi``;
    False if it does not reach into the band.

    The band's part of a convex polygon is convex; its corners are the polygon's corners
    inside the band and the edges' crossings of the band's two lines.
    """
    u0 = np.inf
    u1 = -np.inf
    for e in range(n):
        pu, pv = poly[e, 0], poly[e, 1]
        qu, qv = poly[(e + 1) % n, 0], poly[(e + 1) % n, 1]
        if lo <= pv <= hi:
            u0, u1 = min(u0, pu), max(u1, pu)
        for line in (lo, hi):
            if (pv < line < qv) or (qv < line < pv):
                s = min(max((line - pv) / (qv - pv), 0.0), 1.0)
                u = pu + s * (qu - pu)
                u0, u1 = min(u0, u), max(u1, u)
    return u0, u1, u0 <= u1


def _cast_into(
    vertices: F64,
    projected: F64,
    triangles: I32,
    triangle_offset: int,
    directions: F64,
    cell_start: I64,
    cell_rays: I64,
    grid: F64,
    grid_size: I64,
    t_max: F64,
    best_t: F64,
    best_tri: I32,
    best_u: F64,
    best_v: F64,
) -> None:
    """Update the nearest hits of the rays with the triangles (all in the rays' frame).

    ``projected`` (V, 2) holds each vertex's grid coordinates (for vertices at ``z >= near``).
    ``grid`` is (fx, fy, cx, cy, near) and ``grid_size`` (width, height) of the cell grid;
    the rays of cell ``k = row * width + col`` are ``cell_rays[cell_start[k]:cell_start[k+1]]``.
    A hit counts when ``near_t < t < t_max[ray]`` (``near_t`` = ``grid[4]`` times the ray's z).
    """
    near = grid[4]
    gw, gh = grid_size[0], grid_size[1]
    poly = np.empty((4, 2))
    for k in range(triangles.shape[0]):
        ia, ib, ic = triangles[k, 0], triangles[k, 1], triangles[k, 2]
        a = vertices[ia]
        b = vertices[ib]
        c = vertices[ic]
        in_a, in_b, in_c = a[2] >= near, b[2] >= near, c[2] >= near
        if not (in_a or in_b or in_c):
            continue
        whole = in_a and in_b and in_c
        if whole:  # wholly ahead: the corners' projections bound it
            n = 3
            bu0 = min(projected[ia, 0], projected[ib, 0], projected[ic, 0])
            bu1 = max(projected[ia, 0], projected[ib, 0], projected[ic, 0])
            bv0 = min(projected[ia, 1], projected[ib, 1], projected[ic, 1])
            bv1 = max(projected[ia, 1], projected[ib, 1], projected[ic, 1])
        else:
            n = _polygon(a, b, c, projected, (ia, ib, ic), grid, poly)
            bu0 = min(poly[0, 0], poly[1, 0], poly[2, 0], poly[n - 1, 0])
            bu1 = max(poly[0, 0], poly[1, 0], poly[2, 0], poly[n - 1, 0])
            bv0 = min(poly[0, 1], poly[1, 1], poly[2, 1], poly[n - 1, 1])
            bv1 = max(poly[0, 1], poly[1, 1], poly[2, 1], poly[n - 1, 1])
        # the cells [i - 1/2, i + 1/2) the box touches (a pixel's ray lies at its cell's
        # centre); 1e-6 of a cell more on each side for the rounding of the projections
        if bu1 < -1.0 or bv1 < -1.0 or bu0 > gw or bv0 > gh:
            continue
        i0 = max(int(np.floor(bu0 + 0.5 - 1e-6)), 0)
        j0 = max(int(np.floor(bv0 + 0.5 - 1e-6)), 0)
        i1 = min(int(np.floor(bu1 + 0.5 + 1e-6)), gw - 1)
        j1 = min(int(np.floor(bv1 + 0.5 + 1e-6)), gh - 1)
        if i0 > i1 or j0 > j1:
            continue
        # a large box: test only the cells each row of the triangle reaches (not worth it
        # for the few cells of a small one)
        wide = (i1 - i0 + 1) * (j1 - j0 + 1) > 32 and j1 > j0
        if wide and whole:
            for m, corner in enumerate((ia, ib, ic)):
                poly[m, 0] = projected[corner, 0]
                poly[m, 1] = projected[corner, 1]
        e1x, e1y, e1z = b[0] - a[0], b[1] - a[1], b[2] - a[2]
        e2x, e2y, e2z = c[0] - a[0], c[1] - a[1], c[2] - a[2]
        # the ray origin is the frame's origin: tvec = -a
        tx, ty, tz = -a[0], -a[1], -a[2]
        qx = ty * e1z - tz * e1y
        qy = tz * e1x - tx * e1z
        qz = tx * e1y - ty * e1x
        t_num = e2x * qx + e2y * qy + e2z * qz
        for j in range(j0, j1 + 1):
            row = j * gw
            r0, r1 = i0, i1
            if wide:  # only the cells of this row the triangle reaches
                su0, su1, inside = _row_span(poly, n, j - 0.5 - 1e-6, j + 0.5 + 1e-6)
                if not inside:
                    continue
                r0 = max(int(np.floor(su0 + 0.5 - 1e-6)), i0)
                r1 = min(int(np.floor(su1 + 0.5 + 1e-6)), i1)
            for i in range(r0, r1 + 1):
                cell = row + i
                for r in range(cell_start[cell], cell_start[cell + 1]):
                    ray = cell_rays[r]
                    dx, dy, dz = directions[ray, 0], directions[ray, 1], directions[ray, 2]
                    px = dy * e2z - dz * e2y
                    py = dz * e2x - dx * e2z
                    pz = dx * e2y - dy * e2x
                    det = e1x * px + e1y * py + e1z * pz
                    if det == 0.0:
                        continue
                    inv = 1.0 / det
                    u = (tx * px + ty * py + tz * pz) * inv
                    if u < 0.0 or u > 1.0:
                        continue
                    v = (dx * qx + dy * qy + dz * qz) * inv
                    if v < 0.0 or u + v > 1.0:
                        continue
                    t = t_num * inv
                    if t <= near * dz or t >= t_max[ray] or t >= best_t[ray]:
                        continue
                    best_t[ray] = t
                    best_tri[ray] = k + triangle_offset
                    best_u[ray] = u
                    best_v[ray] = v


_cast_kernel: Callable[..., None] = numba.njit(cache=True)(_cast_into)


class RayBundle:
    """Rays from one origin, binned on a pinhole grid, with their nearest hits so far."""

    def __init__(
        self,
        directions: F64,
        cells: I64,
        grid: tuple[float, float, float, float],
        size: tuple[int, int],
        t_max: F64 | None = None,
    ) -> None:
        """``directions`` (N, 3) with z > 0, ``cells`` (N,) their cell indices on the
        ``size`` = (width, height) grid of intrinsics ``grid`` = (fx, fy, cx, cy)."""
        n = directions.shape[0]
        self.directions = np.ascontiguousarray(directions, dtype=np.float64)
        w, h = size
        if w <= 0 or h <= 0:
            raise ValueError(f"grid size {size} must be positive")
        order = np.argsort(cells, kind="stable").astype(np.int64)
        counts = np.bincount(cells, minlength=w * h).astype(np.int64)
        self._cell_start = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
        self._cell_rays = order
        self._grid = np.array([*grid, NEAR], dtype=np.float64)
        self._size = np.array([w, h], dtype=np.int64)
        self.t_max = (
            np.full(n, np.inf) if t_max is None else np.ascontiguousarray(t_max, dtype=np.float64)
        )
        self.t = np.full(n, np.inf)
        self.triangle = np.full(n, -1, dtype=np.int32)
        self.u = np.zeros(n)
        self.v = np.zeros(n)

    def copy(self) -> RayBundle:
        """The same rays and hits, to be updated independently."""
        out = object.__new__(RayBundle)
        out.__dict__.update(self.__dict__)
        out.t, out.triangle, out.u, out.v = (
            self.t.copy(),
            self.triangle.copy(),
            self.u.copy(),
            self.v.copy(),
        )
        return out

    def cast(self, vertices: F64, triangles: I32, triangle_offset: int = 0) -> None:
        """Keep the nearer hits of these triangles (vertices in the rays' frame)."""
        if triangles.shape[0] == 0:
            return
        v = np.ascontiguousarray(vertices, dtype=np.float64)
        fx, fy, cx, cy, near = self._grid
        z = np.where(v[:, 2] >= near, v[:, 2], 1.0)  # the others are never read
        projected = np.empty((len(v), 2))
        projected[:, 0] = fx * (v[:, 0] / z) + cx
        projected[:, 1] = fy * (v[:, 1] / z) + cy
        _cast_kernel(
            v,
            projected,
            np.ascontiguousarray(triangles, dtype=np.int32),
            int(triangle_offset),
            self.directions,
            self._cell_start,
            self._cell_rays,
            self._grid,
            self._size,
            self.t_max,
            self.t,
            self.triangle,
            self.u,
            self.v,
        )


def pixel_rays(
    width: int, height: int, fx: float, fy: float, cx: float, cy: float
) -> tuple[F64, I64]:
    """Rays through pixel centres (row-major) with unit z, and their cells (the pixels)."""
    u = (np.arange(width, dtype=np.float64) - cx) / fx
    v = (np.arange(height, dtype=np.float64) - cy) / fy
    d = np.empty((height, width, 3))
    d[..., 0] = u[None, :]
    d[..., 1] = v[:, None]
    d[..., 2] = 1.0
    return d.reshape(-1, 3), np.arange(width * height, dtype=np.int64)


def binned_rays(
    directions: F64, cell: float = 1.0 / 256.0, max_cells: int = 1 << 20
) -> tuple[I64, tuple[float, float, float, float], tuple[int, int]]:
    """Cells of arbitrary forward rays (z > 0) on a grid of ``cell`` radians (about) a side.

    Returns the cell index of each ray, the grid's (fx, fy, cx, cy) and its (width, height);
    the grid is coarsened until it has at most ``max_cells`` cells.
    """
    if directions.shape[0] == 0:
        return np.zeros(0, dtype=np.int64), (1.0, 1.0, 0.0, 0.0), (1, 1)
    if not np.all(directions[:, 2] > 0):
        raise ValueError("every ray must point forward (z > 0) in its frame")
    x = directions[:, 0] / directions[:, 2]
    y = directions[:, 1] / directions[:, 2]
    x0, x1, y0, y1 = float(x.min()), float(x.max()), float(y.min()), float(y.max())
    f = 1.0 / cell
    while True:
        w = int(np.floor((x1 - x0) * f)) + 1
        h = int(np.floor((y1 - y0) * f)) + 1
        if w * h <= max_cells:
            break
        f *= 0.5
    # cell (i, j) is centred on u = i, v = j: u = f x + cx with cx = -f x0
    cx, cy = -f * x0, -f * y0
    i = np.clip(np.floor(f * x + cx + 0.5), 0, w - 1).astype(np.int64)
    j = np.clip(np.floor(f * y + cy + 0.5), 0, h - 1).astype(np.int64)
    return j * w + i, (f, f, cx, cy), (w, h)
