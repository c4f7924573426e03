"""Depth image to point cloud, and the voxel-grid down-sampling (seed 000, 5.2, 5.4).

Pure functions: vectorised, or loops compiled with numba.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numba
import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


@dataclass(frozen=True, eq=False)
class PointCloud:
    """Valid depth pixels as optical-frame points.

    ``points`` is ``(N, 3)``; ``pixels`` holds each point's flat index into the
    depth image (row-major), so image-space operations can go back to pixels.
    """

    points: FloatArray
    pixels: IntArray


@dataclass(frozen=True, eq=False)
class VoxelGrid:
    """A down-sampled cloud: one point (the centroid of its members) per occupied voxel.

    ``point_voxel[i]`` is the voxel (row of ``centroids``) of input point ``i``.
    """

    centroids: FloatArray
    point_voxel: IntArray
    counts: IntArray


def depth_to_cloud(depth: NDArray[np.floating], rays: FloatArray, max_depth: float) -> PointCloud:
    """Back-project a depth image with precomputed unit-depth ``rays`` (``(H, W, 3)``).

    Invalid pixels (NaN, non-positive), pixels without a ray (NaN, see
    :meth:`rgbd_eval.types.CameraModel.rays`) and points deeper than ``max_depth``
    along the optical axis are dropped, like the thesis' pass-through filter (5.4).
    """
    if rays.shape[:2] != depth.shape:
        raise ValueError(f"rays {rays.shape[:2]} do not match depth image {depth.shape}")
    flat = np.ascontiguousarray(depth).reshape(-1)
    points, pixels = _cloud_kernel(flat, np.ascontiguousarray(rays).reshape(-1, 3), max_depth)
    return PointCloud(points=points, pixels=pixels)


def _back_project(
    depth: NDArray[np.floating], rays: FloatArray, max_depth: float
) -> tuple[FloatArray, IntArray]:
    """:func:`depth_to_cloud` over the flat depth image and ``(H * W, 3)`` rays."""
    n = 0
    for i in range(depth.shape[0]):
        if depth[i] > 0.0 and depth[i] <= max_depth and rays[i, 2] > 0.0:  # NaN fails all
            n += 1
    points = np.empty((n, 3))
    pixels = np.empty(n, dtype=np.int64)
    j = 0
    for i in range(depth.shape[0]):
        d = depth[i]
        if d > 0.0 and d <= max_depth and rays[i, 2] > 0.0:
            z = np.float64(d)
            pixels[j] = i
            for k in range(3):
                points[j, k] = rays[i, k] * z
            j += 1
    return points, pixels


_cloud_kernel: Callable[[NDArray[np.floating], FloatArray, float], tuple[FloatArray, IntArray]] = (
    numba.njit(cache=True)(_back_project)
)


def voxel_grid(points: FloatArray, voxel_size: float) -> VoxelGrid:
    """Down-sample to the centroid of the points in each occupied cube of side ``voxel_size``.

    The grid is anchored at the origin (cell ``floor(p / voxel_size)``), as PCL's
    ``VoxelGrid`` filter the thesis uses (5.4).
    """
    if not voxel_size > 0:
        raise ValueError(f"voxel_size must be positive, got {voxel_size}")
    n = points.shape[0]
    if n == 0:
        return VoxelGrid(np.zeros((0, 3)), np.zeros(0, np.int64), np.zeros(0, np.int64))
    points = np.ascontiguousarray(points, dtype=np.float64)
    cells, lo_hi = _cells_kernel(points, float(voxel_size))
    lo = [int(v) for v in lo_hi[0]]
    dims = [int(lo_hi[1, k]) - lo[k] + 1 for k in range(3)]
    key_count = dims[0] * dims[1] * dims[2]
    if key_count <= min(DENSE_VOXEL_KEYS, DENSE_CELLS_PER_POINT * n):
        # Compiled passes over a table of every cell of the bounding box.
        centroids, point_voxel, counts = _dense_kernel(points, cells, lo_hi[0], np.array(dims))
        return VoxelGrid(centroids=centroids, point_voxel=point_voxel, counts=counts)
    c0, c1, c2 = (cells[:, k] - lo[k] for k in range(3))
    keys = (c0 * dims[1] + c1) * dims[2] + c2
    # Voxels numbered in key order, as np.unique would, from one stable sort of the keys.
    order = stable_argsort(keys, dims[0] * dims[1] * dims[2])
    sorted_keys = keys[order]
    first = np.empty(n, dtype=bool)
    first[0] = True
    np.not_equal(sorted_keys[1:], sorted_keys[:-1], out=first[1:])
    point_voxel = np.empty(n, dtype=np.int64)
    point_voxel[order] = np.cumsum(first) - 1
    counts = np.diff(np.append(np.flatnonzero(first), n))
    m = counts.shape[0]
    sums = np.stack(
        [np.bincount(point_voxel, weights=points[:, k], minlength=m) for k in range(3)], axis=1
    )
    centroids = sums / counts[:, None]
    return VoxelGrid(centroids=centroids, point_voxel=point_voxel, counts=counts)


#: Largest bounding box (in cells) voxelised through a dense table (4 bytes a cell):
#: a 640x480 frame to 6.5 m at 0.06 m spans about 1.2 million.
DENSE_VOXEL_KEYS = 1 << 23
#: ... and only while the table is at most this many cells per point: a 160x120
#: frame (19200 points) over the same box sorts faster than it fills the table.
DENSE_CELLS_PER_POINT = 16


def _voxel_cells(points: FloatArray, voxel_size: float) -> tuple[IntArray, IntArray]:
    """``floor(points / voxel_size)`` as integers, and its per-column minima and maxima."""
    n = points.shape[0]
    cells = np.empty((n, 3), dtype=np.int64)
    lo_hi = np.empty((2, 3), dtype=np.int64)
    for k in range(3):
        lo_hi[0, k] = 2**62
        lo_hi[1, k] = -(2**62)
    for i in range(n):
        for k in range(3):
            c = np.int64(np.floor(points[i, k] / voxel_size))
            cells[i, k] = c
            lo_hi[0, k] = min(lo_hi[0, k], c)
            lo_hi[1, k] = max(lo_hi[1, k], c)
    return cells, lo_hi


_cells_kernel: Callable[[FloatArray, float], tuple[IntArray, IntArray]] = numba.njit(cache=True)(
    _voxel_cells
)


def _dense_voxels(
    points: FloatArray, cells: IntArray, lo: IntArray, dims: IntArray
) -> tuple[FloatArray, IntArray, IntArray]:
    """:func:`voxel_grid` through a table over the cells' bounding box.

    Voxels are numbered in key order (as ``np.unique``) and each centroid sums its
    points in input order (as ``np.bincount``), so the results are the same bits.
    """
    n = points.shape[0]
    table = np.full(dims[0] * dims[1] * dims[2], -1, dtype=np.int32)
    keys = np.empty(n, dtype=np.int64)
    occupied = np.empty(n, dtype=np.int64)
    m = 0
    for i in range(n):
        key = (
            ((cells[i, 0] - lo[0]) * dims[1] + cells[i, 1] - lo[1]) * dims[2] + cells[i, 2] - lo[2]
        )
        keys[i] = key
        if table[key] < 0:
            table[key] = 0
            occupied[m] = key
            m += 1
    occupied = np.sort(occupied[:m])
    for v in range(m):
        table[occupied[v]] = v
    point_voxel = np.empty(n, dtype=np.int64)
    counts = np.zeros(m, dtype=np.int64)
    sums = np.zeros((m, 3))
    for i in range(n):
        v = table[keys[i]]
        point_voxel[i] = v
        counts[v] += 1
        for k in range(3):
            sums[v, k] += points[i, k]
    for v in range(m):
        for k in range(3):
            sums[v, k] /= counts[v]
    return sums, point_voxel, counts


_dense_kernel: Callable[
    [FloatArray, IntArray, IntArray, IntArray], tuple[FloatArray, IntArray, IntArray]
] = numba.njit(cache=True)(_dense_voxels)


def _counting_argsort(keys: IntArray, key_count: int) -> IntArray:
    """The stable order of ``keys`` in ``[0, key_count)`` by counting sort."""
    starts = np.zeros(key_count + 1, dtype=np.int64)
    for key in keys:
        starts[key + 1] += 1
    for key in range(key_count):
        starts[key + 1] += starts[key]
    order = np.empty(keys.shape[0], dtype=np.int64)
    for i in range(keys.shape[0]):
        order[starts[keys[i]]] = i
        starts[keys[i]] += 1
    return order


_counting_kernel: Callable[[IntArray, int], IntArray] = numba.njit(cache=True)(_counting_argsort)

#: Largest key range sorted by counting (a table of this many counters).
COUNTING_SORT_KEYS = 1 << 20


def stable_argsort(keys: IntArray, key_count: int) -> IntArray:
    """``np.argsort(keys, kind="stable")`` for keys in ``[0, key_count)``.

    Up to :data:`COUNTING_SORT_KEYS` keys, and at most about four per element: a
    compiled counting sort, linear in elements plus keys. Otherwise small keys are sorted with their index packed in the
    low 32 bits: a plain (SIMD) sort of the packed values gives the stable order,
    two to three times faster than the stable argsort.
    """
    n = keys.shape[0]
    if key_count <= COUNTING_SORT_KEYS and key_count <= 4 * n + 1024:
        return _counting_kernel(np.ascontiguousarray(keys, dtype=np.int64), int(key_count))
    if key_count > 2**31 or n > 2**32:
        return np.argsort(keys, kind="stable")
    packed = np.sort((keys.astype(np.int64, copy=False) << 32) | np.arange(n, dtype=np.int64))
    order: IntArray = packed & 0xFFFFFFFF
    return order
