"""Euclidean clustering (seed 000, 5.2) and head-based sub-clustering.

Sub-clustering follows the improvement of the thesis' authors (Munaro, Basso and
Menegatti, "Tracking people within groups with RGB-D data", IROS 2012): clusters
whose ground projections are close are merged (a person cut in two by an
occluder), then a cluster holding several heads (people walking side by side)
is split between them, every point going to the nearest head on the ground.

Here the heads are found on a true 2D height map over the ground plane (cell =
one voxel), so that people side by side and one behind the other are both
separated. A head is a peak of the map within the person height range that is
at least ``min_head_distance`` (on the ground) from every higher head and cannot
reach any of them, nor anything taller than a person, without descending by
``min_head_prominence`` (its topographic prominence): between two people every
path dips to shoulder level, along the flat top edge of a cabinet none does.
Parts taller than a person that reach down to the floor (walls) are seeds of
their own, so a person touching a wall is cut from it; parts above the person
range that do not reach down (a ceiling seen above people) belong to no one.
Only person-sized pieces are merged, so a ceiling or a wall whose mean ground
position happens to fall among people does not swallow them.

Labels are integers per point, ``-1`` for "no cluster".
"""

from __future__ import annotations

from collections.abc import Callable
from functools import lru_cache

import cv2
import numba
import numpy as np
from numpy.typing import NDArray
from scipy import ndimage
from scipy.spatial import cKDTree

from rgbd_eval.detect.cloud import stable_argsort
from rgbd_eval.detect.plane import cross3

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: How far (m) from a peak its head region is followed. A head-and-shoulders bump
#: is far smaller; the limit keeps long structures (wall tops) cheap to examine.
HEAD_SEARCH_RADIUS = 1.0
#: Widest ground footprint (m) of a piece merged into a person (bounding-box
#: diagonal): a walking adult, arms swinging, stays well within it.
PERSON_MAX_WIDTH = 1.0
#: Largest vertical gap (m) within one ground cell's column of points that still
#: counts as one structure reaching down (three 6 cm voxels).
OVERHANG_GAP = 0.18


def euclidean_clusters(points: FloatArray, tolerance: float, min_points: int) -> IntArray:
    """Connected components of the graph linking points closer than ``tolerance``.

    Components smaller than ``min_points`` get label -1. Labels are renumbered
    0..K-1 in order of each component's first point (deterministic).

    The graph is that of ``cKDTree.query_pairs(tolerance)`` (p = 2): two points
    are linked when their squared distance, summed over x, y, z in that order, is
    ``<= tolerance * tolerance``, so points exactly ``tolerance`` apart are linked
    as there. Candidate pairs come from a uniform grid of cells a hair wider than
    ``tolerance`` (no rounding of the cell indices can then put two linked points
    two cells apart), see :func:`_grid_components`.
    """
    if not tolerance > 0:
        raise ValueError(f"tolerance must be positive, got {tolerance}")
    n = points.shape[0]
    if n == 0:
        return np.zeros(0, dtype=np.int64)
    columns = [points[:, d] for d in range(3)]  # column-wise: (N, 3).min(axis=0) is slow
    lo = np.array([float(column.min()) for column in columns])
    extent = max(float(column.max()) - low for column, low in zip(columns, lo, strict=True))
    # Wider cells only cost distance tests; at most 2**20 cells per axis keep the
    # cell keys below 2**63.
    cell = max(tolerance * (1.0 + 1e-6), extent / 2.0**20)
    idx = np.floor((points - lo) / cell).astype(np.int64) + 1  # >= 1: neighbours >= 0
    ny, nz = int(idx[:, 1].max()) + 2, int(idx[:, 2].max()) + 2
    # Cell keys in z-fastest order: a column's cells (dz = -1, 0, 1) have consecutive keys.
    keys = (idx[:, 0] * ny + idx[:, 1]) * nz + idx[:, 2]
    order = np.argsort(keys, kind="stable")
    labels = _grid_components_kernel(
        np.take(points, order, axis=0), keys[order], order, ny, nz, tolerance * tolerance
    )
    return _keep_sizes(labels, min_points, None)


def _grid_components(
    points: FloatArray, keys: IntArray, order: IntArray, ny: int, nz: int, r2: float
) -> IntArray:
    """Each point labelled with the smallest input index of its component.

    ``points`` ``(N, 3)`` are sorted by cell, ``keys`` their cell keys
    ``(ix * ny + iy) * nz + iz``, ``order`` their input indices; points are linked
    when their squared distance is ``<= r2``.
    """
    n = points.shape[0]
    # Cells: their keys and first positions (cell_start[n_cells] = n).
    cell_start = np.empty(n + 1, dtype=np.int64)
    n_cells = 0
    for s in range(n):
        if s == 0 or keys[s] != keys[s - 1]:
            cell_start[n_cells] = s
            n_cells += 1
    cell_start[n_cells] = n
    cell_keys = np.empty(n_cells, dtype=np.int64)
    for c in range(n_cells):
        cell_keys[c] = keys[cell_start[c]]
    # Each pair once: a cell with itself and with the cell above it (dz = 1), and
    # with the three cells (dz = -1..1) of each column ahead: (dx, dy) = (0, 1),
    # (1, -1), (1, 0), (1, 1). Their keys grow with the cell's key, so each
    # column ahead is found by a pointer moving forward through the sorted cells.
    ahead = np.array([nz, (ny - 1) * nz, ny * nz, (ny + 1) * nz])
    pointer = np.zeros(4, dtype=np.int64)
    first = np.empty(5, dtype=np.int64)  # the position ranges to test against
    last = np.empty(5, dtype=np.int64)
    parent = np.arange(n)  # union-find over positions in cell order
    for c in range(n_cells):
        key = cell_keys[c]
        above = c + 1 < n_cells and cell_keys[c + 1] == key + 1
        last[0] = cell_start[c + 2] if above else cell_start[c + 1]
        for col in range(4):
            centre = key + ahead[col]
            q = pointer[col]
            while q < n_cells and cell_keys[q] < centre - 1:
                q += 1
            pointer[col] = q
            r = q
            while r < n_cells and cell_keys[r] <= centre + 1:
                r += 1
            first[col + 1], last[col + 1] = cell_start[q], cell_start[r]
        for s in range(cell_start[c], cell_start[c + 1]):
            first[0] = s + 1  # pairs within the cell once
            for k in range(5):
                for t in range(first[k], last[k]):
                    e = points[s, 0] - points[t, 0]
                    d2 = e * e
                    e = points[s, 1] - points[t, 1]
                    d2 += e * e
                    e = points[s, 2] - points[t, 2]
                    d2 += e * e
                    if d2 <= r2:  # join the trees: the larger root under the smaller
                        a, b = _find_kernel(parent, s), _find_kernel(parent, t)
                        if a < b:
                            parent[b] = a
                        elif b < a:
                            parent[a] = b
    # Back to the input order, each component named by its smallest input index.
    smallest = np.zeros(n, dtype=np.int64) + n
    for s in range(n):
        root = _find_kernel(parent, s)
        smallest[root] = min(smallest[root], order[s])
    labels = np.empty(n, dtype=np.int64)
    for s in range(n):
        labels[order[s]] = smallest[parent[s]]
    return labels


def _find(parent: IntArray, i: int) -> int:
    """Root of ``i`` in the union-find forest, halving the path on the way."""
    while parent[i] != i:
        parent[i] = parent[parent[i]]
        i = parent[i]
    return i


#: Compiled on first use, cached on disk; no ``fastmath``: the distance test rounds
#: operation by operation, as scipy's.
_find_kernel: Callable[[IntArray, int], int] = numba.njit(cache=True)(_find)
_grid_components_kernel: Callable[[FloatArray, IntArray, IntArray, int, int, float], IntArray] = (
    numba.njit(cache=True)(_grid_components)
)


def connected_components(pairs: IntArray, n: int) -> IntArray:
    """Components of the undirected graph on nodes ``0..n-1`` with edges ``pairs`` ``(E, 2)``.

    Each node is labelled with the smallest node of its component. Union-find on
    whole arrays: every edge joining two trees hangs the larger root under the
    smaller (one edge wins where several compete), then pointer jumping makes
    every node point at its root again; edges inside one tree are dropped.
    Several times faster than ``scipy.sparse.csgraph`` on a few thousand nodes.
    """
    label = np.arange(n, dtype=np.int64)
    i, j = pairs[:, 0], pairs[:, 1]
    while True:
        li, lj = label[i], label[j]
        joining = li != lj
        if not joining.any():
            return label
        i, j, li, lj = i[joining], j[joining], li[joining], lj[joining]
        label[np.maximum(li, lj)] = np.minimum(li, lj)
        while True:
            jumped = label[label]
            if np.array_equal(jumped, label):
                break
            label = jumped


def _keep_sizes(labels: IntArray, min_points: int, max_points: int | None) -> IntArray:
    """Drop labels with too few/many points; renumber the rest by first occurrence."""
    most = np.iinfo(np.int64).max if max_points is None else max_points
    return _keep_sizes_kernel(
        np.ascontiguousarray(labels, dtype=np.int64), max(min_points, 1), most
    )


def _keep_sizes_loop(labels: IntArray, least: int, most: int) -> IntArray:
    """:func:`_keep_sizes` with ``least <= size <= most``, counting, then renumbering."""
    k = 0
    for label in labels:
        k = max(k, label + 1)
    counts = np.zeros(k, dtype=np.int64)
    for label in labels:
        if label >= 0:
            counts[label] += 1
    # -2: not met yet; -1: met, dropped; else the new label, in order of first meeting.
    lookup = np.zeros(k, dtype=np.int64) - 2
    kept = 0
    out = np.empty(labels.shape[0], dtype=np.int64)
    for i in range(labels.shape[0]):
        label = labels[i]
        if label < 0:
            out[i] = -1
            continue
        if lookup[label] == -2:
            if least <= counts[label] <= most:
                lookup[label] = kept
                kept += 1
            else:
                lookup[label] = -1
        out[i] = lookup[label]
    return out


#: Compiled on first use, cached on disk.
_keep_sizes_kernel: Callable[[IntArray, int, int], IntArray] = numba.njit(cache=True)(
    _keep_sizes_loop
)


def group_extrema(groups: IntArray, values: FloatArray, k: int) -> tuple[FloatArray, FloatArray]:
    """Per-group minimum and maximum of ``values`` (or of each column) for groups ``0..k-1``.

    Empty groups get ``+inf`` and ``-inf``. One compiled pass: the same values as
    ``np.minimum.at``/``np.maximum.at`` (minima and maxima do not depend on the
    order), whose speed depends on the data.
    """
    width = int(np.prod(values.shape[1:], dtype=np.int64))
    columns = np.ascontiguousarray(values, dtype=np.float64).reshape(values.shape[0], width)
    lo, hi = _extrema_kernel(np.ascontiguousarray(groups, dtype=np.int64), columns, int(k))
    shape = (k, *values.shape[1:])
    return lo.reshape(shape), hi.reshape(shape)


def _group_extrema(groups: IntArray, values: FloatArray, k: int) -> tuple[FloatArray, FloatArray]:
    lo = np.full((k, values.shape[1]), np.inf)
    hi = np.full((k, values.shape[1]), -np.inf)
    for i in range(groups.shape[0]):
        g = groups[i]
        for c in range(values.shape[1]):
            x = values[i, c]
            if x < lo[g, c]:
                lo[g, c] = x
            if x > hi[g, c]:
                hi[g, c] = x
    return lo, hi


_extrema_kernel: Callable[[IntArray, FloatArray, int], tuple[FloatArray, FloatArray]] = numba.njit(
    cache=True
)(_group_extrema)


def filter_cluster_sizes(labels: IntArray, min_points: int, max_points: int | None) -> IntArray:
    """Clusters with ``min_points <= size <= max_points`` kept and renumbered, others -1."""
    return _keep_sizes(labels, min_points, max_points)


def ground_basis(normal: FloatArray) -> FloatArray:
    """Two orthonormal vectors ``(2, 3)`` spanning the plane with the given normal."""
    n = normal / float(np.linalg.norm(normal))
    helper = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = cross3(n, helper)
    e1 /= float(np.linalg.norm(e1))
    e2 = cross3(n, e1)
    return np.stack([e1, e2])


def merge_close_clusters(
    ground_xy: FloatArray,
    labels: IntArray,
    distance: float,
    heights: FloatArray | None = None,
    max_height: float = np.inf,
) -> IntArray:
    """Merge person-sized clusters whose mean ground positions are closer than ``distance``.

    Only pieces that could be part of one person take part: no taller than
    ``max_height`` (needs ``heights``) and no wider on the ground than
    :data:`PERSON_MAX_WIDTH`. A ceiling or a wall, whose mean ground position
    may fall anywhere, would otherwise swallow the people near that point.
    Merging is transitive.
    """
    k = int(labels.max()) + 1 if labels.size else 0
    if k < 2:
        return labels
    valid = labels >= 0
    lab = labels[valid]
    xy = np.compress(valid, ground_xy, axis=0)  # ground_xy[valid], faster
    counts = np.bincount(lab, minlength=k).astype(np.float64)
    centres = (
        np.stack([np.bincount(lab, weights=xy[:, j], minlength=k) for j in (0, 1)], axis=1)
        / np.maximum(counts, 1.0)[:, None]
    )
    columns = xy if heights is None else np.column_stack([xy, heights[valid]])
    lo, hi = group_extrema(lab, columns, k)
    mergeable = np.hypot(*(hi[:, :2] - lo[:, :2]).T) <= PERSON_MAX_WIDTH
    if heights is not None:
        mergeable &= hi[:, 2] <= max_height
    candidates = np.flatnonzero(mergeable & (counts > 0))
    if candidates.shape[0] < 2:
        return labels
    pairs = candidates[cKDTree(centres[candidates]).query_pairs(distance, output_type="ndarray")]
    if pairs.shape[0] == 0:
        return labels
    merged = connected_components(pairs, k)
    out = labels.copy()
    out[valid] = merged[lab]
    return _keep_sizes(out, 1, None)


def _height_map(
    ground_xy: FloatArray, heights: FloatArray, cell: float, max_height: float
) -> tuple[FloatArray, IntArray, FloatArray, NDArray[np.bool_]]:
    """Highest point per ground cell, with overhangs taken out.

    Returns the map (one empty cell of border), each point's cell, the origin,
    and which points are overhangs: above ``max_height`` in a cell whose column
    does not continue down to the person range (a ceiling or a shelf above
    people, seen from below). A wall continues down, so it stays in the map,
    taller than any person.
    """
    if ground_xy.shape[0] == 0:
        raise ValueError("no points for a height map")
    return _height_map_kernel(
        np.ascontiguousarray(ground_xy, dtype=np.float64),
        np.ascontiguousarray(heights, dtype=np.float64),
        float(cell),
        float(max_height),
        OVERHANG_GAP,
    )


def _height_map_loop(
    ground_xy: FloatArray, heights: FloatArray, cell: float, max_height: float, gap: float
) -> tuple[FloatArray, IntArray, FloatArray, NDArray[np.bool_]]:
    """:func:`_height_map` with ``OVERHANG_GAP`` = ``gap``; every value as numpy computes it."""
    n = ground_xy.shape[0]
    origin = ground_xy[0].copy()
    for p in range(n):
        for d in range(2):
            if ground_xy[p, d] < origin[d]:
                origin[d] = ground_xy[p, d]
    ij = np.empty((n, 2), dtype=np.int64)
    rows, cols = 0, 0
    for p in range(n):
        for d in range(2):
            ij[p, d] = np.int64(np.floor((ground_xy[p, d] - origin[d]) / cell)) + 1
        rows, cols = max(rows, ij[p, 0] + 2), max(cols, ij[p, 1] + 2)
    hmap = np.zeros((rows, cols))
    lowest_high = np.full((rows, cols), np.inf)  # the points above max_height, per cell
    top_high = np.zeros((rows, cols))
    for p in range(n):
        i, j, h = ij[p, 0], ij[p, 1], heights[p]
        # Replaced only by a strictly higher (lower) value, as ``np.maximum.at`` does.
        if h > max_height:
            if h < lowest_high[i, j]:
                lowest_high[i, j] = h
            if h > top_high[i, j]:
                top_high[i, j] = h
        elif h > hmap[i, j]:
            hmap[i, j] = h
    # A column is continuous when no gap wider than ``gap`` separates its points
    # above max_height from those below (or from max_height itself).
    tall = np.zeros((rows, cols), dtype=np.bool_)
    for i in range(rows):
        for j in range(cols):
            floor_of_gap = max(hmap[i, j], max_height - gap)
            if np.isfinite(lowest_high[i, j]) and lowest_high[i, j] - floor_of_gap <= gap:
                tall[i, j] = True
                hmap[i, j] = top_high[i, j]
    overhang = np.zeros(n, dtype=np.bool_)
    for p in range(n):
        overhang[p] = heights[p] > max_height and not tall[ij[p, 0], ij[p, 1]]
    return hmap, ij, origin, overhang


#: Compiled on first use, cached on disk.
_height_map_kernel: Callable[
    [FloatArray, FloatArray, float, float, float],
    tuple[FloatArray, IntArray, FloatArray, NDArray[np.bool_]],
] = numba.njit(cache=True)(_height_map_loop)


def _head_seeds(
    hmap: FloatArray,
    cell: float,
    min_head_distance: float,
    min_head_prominence: float,
    head_heights: tuple[float, float],
) -> tuple[IntArray, FloatArray]:
    """Seed regions of the map (0 = none): the heads first (1..H), then tall structures.

    Returns the seed map and the head-region centres (cell coordinates), highest first.
    """
    lowest, highest = head_heights
    seeds = np.zeros(hmap.shape, dtype=np.int64)
    tall = hmap > highest
    # A head is the highest point within half the minimum head distance of itself.
    radius = max(1, int(np.floor(0.5 * min_head_distance / cell)))
    peaks = (hmap >= lowest) & ~tall & (hmap >= _maximum_filter(hmap, radius))
    pi, pj = np.nonzero(peaks)
    order = np.lexsort((pj, pi, -hmap[pi, pj]))  # highest first, then raster order
    # No hole bridging: between two heads 0.4 m apart only two or three cells of
    # shoulder separate their regions; a hole that splits one head's region leaves
    # a second peak closer than ``min_head_distance``, which is dropped anyway.
    half = max(1, int(np.ceil(HEAD_SEARCH_RADIUS / cell)))
    min_cells2 = (min_head_distance / cell) ** 2
    centres = np.empty((order.shape[0], 2))
    accepted = _grow_heads_kernel(
        hmap,
        pi[order],
        pj[order],
        half,
        min_cells2,
        float(min_head_prominence),
        float(highest),
        seeds,
        centres,
    )
    if tall.any():
        tall_regions, _ = ndimage.label(tall, structure=np.ones((3, 3), dtype=bool))
        seeds[tall] = tall_regions[tall] + accepted
    return seeds, centres[:accepted]


def _grow_heads(
    hmap: FloatArray,
    peak_i: IntArray,
    peak_j: IntArray,
    half: int,
    min_cells2: float,
    prominence: float,
    highest: float,
    seeds: IntArray,
    centres: FloatArray,
) -> int:
    """Accept the candidate peaks as heads in turn, growing their regions in ``seeds``.

    A peak is dropped when closer than ``sqrt(min_cells2)`` cells to an accepted
    head, or when its region (the cells 8-connected to it at or above its height
    minus ``prominence``, within ``half`` cells of it) holds another head's cell
    or a cell above ``highest``. Otherwise its region gets the next seed label
    and its mean cell goes to ``centres``. Returns the number of heads.
    """
    rows, cols = hmap.shape
    stamp = np.zeros((rows, cols), dtype=np.int64)  # 1 + the last candidate to visit a cell
    region = np.empty((rows * cols, 2), dtype=np.int64)  # a region's cells, in visiting order
    heads = np.empty((peak_i.shape[0], 2), dtype=np.int64)  # the accepted peaks
    accepted = 0
    for p in range(peak_i.shape[0]):
        i, j = peak_i[p], peak_j[p]
        near = False
        for a in range(accepted):
            di, dj = i - heads[a, 0], j - heads[a, 1]
            near |= di * di + dj * dj < min_cells2
        if near:
            continue
        # Breadth-first over the window around the peak: the visited cells are the
        # queue, the cells before ``done`` have had their neighbours looked at.
        i0, i1 = max(0, i - half), min(rows, i + half + 1)
        j0, j1 = max(0, j - half), min(cols, j + half + 1)
        floor = hmap[i, j] - prominence
        stamp[i, j] = p + 1
        region[0, 0], region[0, 1] = i, j
        count = 1
        done = 0
        while done < count:
            ci, cj = region[done, 0], region[done, 1]
            done += 1
            for ni in range(max(i0, ci - 1), min(i1, ci + 2)):
                for nj in range(max(j0, cj - 1), min(j1, cj + 2)):
                    if stamp[ni, nj] != p + 1 and hmap[ni, nj] >= floor:
                        stamp[ni, nj] = p + 1
                        region[count, 0], region[count, 1] = ni, nj
                        count += 1
        clash = False
        for k in range(count):
            ci, cj = region[k, 0], region[k, 1]
            clash |= seeds[ci, cj] > 0 or hmap[ci, cj] > highest
        if clash:
            continue
        heads[accepted, 0], heads[accepted, 1] = i, j
        accepted += 1
        sum_i = 0
        sum_j = 0
        for k in range(count):
            seeds[region[k, 0], region[k, 1]] = accepted
            sum_i += region[k, 0] - i0
            sum_j += region[k, 1] - j0
        # Exact integer sums: the values of ``rows.sum() / rows.size + i0`` in numpy.
        centres[accepted - 1, 0] = sum_i / count + i0
        centres[accepted - 1, 1] = sum_j / count + j0
    return accepted


#: Compiled on first use, cached on disk.
_grow_heads_kernel: Callable[
    [FloatArray, IntArray, IntArray, int, float, float, float, IntArray, FloatArray], int
] = numba.njit(cache=True)(_grow_heads)


@lru_cache(maxsize=8)
def _disk(radius: int) -> NDArray[np.uint8]:
    """A disk of cells (``x^2 + y^2 <= radius^2``) as an OpenCV structuring element."""
    yy, xx = np.mgrid[-radius : radius + 1, -radius : radius + 1]
    disk: NDArray[np.uint8] = (yy * yy + xx * xx <= radius * radius).astype(np.uint8)
    return disk


def _maximum_filter(image: FloatArray, radius: int) -> FloatArray:
    """Maximum over a disk around every cell, 0 outside the image.

    The same values as ``ndimage.maximum_filter(image, footprint=disk,
    mode="constant")``, several times faster on small maps.
    """
    out = cv2.dilate(image, _disk(radius), borderType=cv2.BORDER_CONSTANT, borderValue=0.0)
    return np.asarray(out, dtype=np.float64)


def find_heads(
    ground_xy: FloatArray,
    heights: FloatArray,
    cell: float,
    min_head_distance: float,
    min_head_prominence: float,
    head_heights: tuple[float, float] = (0.0, np.inf),
) -> FloatArray:
    """Ground positions ``(H, 2)`` of the heads of one cluster, highest first.

    ``ground_xy`` are the points' ground-plane coordinates, ``heights`` their
    heights above the floor; the height map keeps the highest point per cell.
    Only peaks within ``head_heights`` (the person height range) can be heads.
    """
    if ground_xy.shape[0] == 0:
        return np.zeros((0, 2))
    hmap, _, origin, _ = _height_map(ground_xy, heights, cell, head_heights[1])
    _, centres = _head_seeds(hmap, cell, min_head_distance, min_head_prominence, head_heights)
    heads: FloatArray = origin + (centres - 1 + 0.5) * cell
    return heads


def split_by_heads(
    ground_xy: FloatArray,
    heights: FloatArray,
    labels: IntArray,
    cell: float,
    min_head_distance: float,
    min_head_prominence: float,
    head_heights: tuple[float, float] = (0.0, np.inf),
) -> IntArray:
    """Split every cluster between its heads and taller structures.

    Each point goes to the seed region (a head's region, or a connected part of
    the cluster taller than any person) nearest to its cell on the ground.
    """
    out = np.full(labels.shape, -1, dtype=np.int64)
    next_label = 0
    k = int(labels.max()) + 1 if labels.size else 0
    members_sorted = stable_argsort(labels + 1, k + 1)  # -1 (no cluster) first
    bounds = np.searchsorted(labels[members_sorted], np.arange(k + 1))
    for c in range(k):
        members = members_sorted[bounds[c] : bounds[c + 1]]
        if not _may_hold_heads(heights[members], head_heights):
            out[members] = next_label
            next_label += 1
            continue
        hmap, ij, _, overhang = _height_map(
            np.take(ground_xy, members, axis=0), heights[members], cell, head_heights[1]
        )
        seeds, heads = _head_seeds(hmap, cell, min_head_distance, min_head_prominence, head_heights)
        n_seeds = int(seeds.max())
        if heads.shape[0] == 0:  # no person in it: left whole (the height filter judges it)
            out[members] = next_label
            next_label += 1
            continue
        if n_seeds == 1:
            sub = np.zeros(members.shape[0], dtype=np.int64)
        else:
            # Nearest seed cell of every cell (Euclidean distance transform).
            _, (ni, nj) = ndimage.distance_transform_edt(seeds == 0, return_indices=True)
            sub = seeds[ni, nj][ij[:, 0], ij[:, 1]] - 1
        # Overhangs (a ceiling above the people) belong to no person.
        out[members] = np.where(overhang, -1, next_label + sub)
        next_label += n_seeds
    return _keep_sizes(out, 1, None)


def _may_hold_heads(heights: FloatArray, head_heights: tuple[float, float]) -> bool:
    """False when no cell of the points' height map can be a head (a cheap pre-test).

    With a positive lower bound, a map cell is in the head range only if one of
    its points is; otherwise (lower bound <= 0, where empty cells count) assume yes.
    """
    lowest, highest = head_heights
    return lowest <= 0.0 or bool(((heights >= lowest) & (heights <= highest)).any())
