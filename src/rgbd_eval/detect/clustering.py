"""Euclidean clustering (seed 000, 5.2) and head-based sub-clustering.

Sub-clustering follows the improvement of the thesis' authors (Munaro, Basso and
Menegatti, "Tracking people within groups with RGB-D data", IROS 2012): clusters
whose ground projections are close are merged (a person cut in two by an
occluder), then a cluster holding several heads (people walking side by side)
is split between them, every point going to the nearest head on the ground.

Here the heads are found on a true 2D height map over the ground plane (cell =
one voxel), so that people side by side and one behind the other are both
separated. A head is a local maximum of the map that is at least
``min_head_distance`` (on the ground) from every higher head and cannot reach
any of them without descending by ``min_head_prominence`` (its topographic
prominence): between two people every path dips to shoulder level, along the
flat top edge of a cabinet none does.

Labels are integers per point, ``-1`` for "no cluster".
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


def euclidean_clusters(points: FloatArray, tolerance: float, min_points: int) -> IntArray:
    """Connected components of the graph linking points closer than ``tolerance``.

    Components smaller than ``min_points`` get label -1. Labels are renumbered
    0..K-1 in order of each component's first point (deterministic).
    """
    if not tolerance > 0:
        raise ValueError(f"tolerance must be positive, got {tolerance}")
    n = points.shape[0]
    if n == 0:
        return np.zeros(0, dtype=np.int64)
    pairs = cKDTree(points).query_pairs(tolerance, output_type="ndarray")
    graph = coo_matrix(
        (np.ones(pairs.shape[0], dtype=np.int8), (pairs[:, 0], pairs[:, 1])), shape=(n, n)
    )
    _, labels = connected_components(graph, directed=False)
    return _keep_sizes(labels.astype(np.int64), min_points, None)


def _keep_sizes(labels: IntArray, min_points: int, max_points: int | None) -> IntArray:
    """Drop labels with too few/many points; renumber the rest by first occurrence."""
    valid = labels >= 0
    if not np.any(valid):
        return np.full(labels.shape, -1, dtype=np.int64)
    uniq, first, counts = np.unique(labels[valid], return_index=True, return_counts=True)
    keep = counts >= min_points
    if max_points is not None:
        keep &= counts <= max_points
    kept = uniq[keep][np.argsort(first[keep], kind="stable")]
    lookup = np.full(int(uniq.max()) + 1, -1, dtype=np.int64)
    lookup[kept] = np.arange(kept.shape[0], dtype=np.int64)
    out = np.full(labels.shape, -1, dtype=np.int64)
    out[valid] = lookup[labels[valid]]
    return out


def filter_cluster_sizes(labels: IntArray, min_points: int, max_points: int | None) -> IntArray:
    """Clusters with ``min_points <= size <= max_points`` kept and renumbered, others -1."""
    return _keep_sizes(labels, min_points, max_points)


def ground_basis(normal: FloatArray) -> FloatArray:
    """Two orthonormal vectors ``(2, 3)`` spanning the plane with the given normal."""
    n = normal / float(np.linalg.norm(normal))
    helper = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = np.cross(n, helper)
    e1 /= float(np.linalg.norm(e1))
    e2 = np.cross(n, e1)
    return np.stack([e1, e2])


def merge_close_clusters(ground_xy: FloatArray, labels: IntArray, distance: float) -> IntArray:
    """Merge clusters whose mean ground positions are closer than ``distance`` (transitively)."""
    k = int(labels.max()) + 1 if labels.size else 0
    if k < 2:
        return labels
    valid = labels >= 0
    counts = np.bincount(labels[valid], minlength=k).astype(np.float64)
    centres = (
        np.stack(
            [np.bincount(labels[valid], weights=ground_xy[valid, j], minlength=k) for j in (0, 1)],
            axis=1,
        )
        / np.maximum(counts, 1.0)[:, None]
    )
    pairs = cKDTree(centres).query_pairs(distance, output_type="ndarray")
    if pairs.shape[0] == 0:
        return labels
    graph = coo_matrix((np.ones(pairs.shape[0]), (pairs[:, 0], pairs[:, 1])), shape=(k, k))
    _, merged = connected_components(graph, directed=False)
    out = labels.copy()
    out[valid] = merged[labels[valid]]
    return _keep_sizes(out, 1, None)


def find_heads(
    ground_xy: FloatArray,
    heights: FloatArray,
    cell: float,
    min_head_distance: float,
    min_head_prominence: float,
) -> FloatArray:
    """Ground positions ``(H, 2)`` of the heads of one cluster, highest first.

    ``ground_xy`` are the points' ground-plane coordinates, ``heights`` their
    heights above the floor; the height map keeps the highest point per cell.
    """
    if ground_xy.shape[0] == 0:
        return np.zeros((0, 2))
    origin = ground_xy.min(axis=0)
    ij = np.floor((ground_xy - origin) / cell).astype(np.int64) + 1  # one empty cell of border
    shape = (int(ij[:, 0].max()) + 2, int(ij[:, 1].max()) + 2)
    hmap = np.zeros(shape, dtype=np.float64)
    np.maximum.at(hmap, (ij[:, 0], ij[:, 1]), heights)
    occupied = hmap > 0
    peaks = occupied & (hmap >= ndimage.maximum_filter(hmap, size=3, mode="constant"))
    pi, pj = np.nonzero(peaks)
    order = np.lexsort((pj, pi, -hmap[pi, pj]))  # highest first, then raster order
    pi, pj = pi[order], pj[order]
    # No hole bridging: between two heads 0.4 m apart only two or three cells of
    # shoulder separate their regions; a hole that splits one head's region leaves
    # a second peak closer than ``min_head_distance``, which is dropped anyway.
    eight = np.ones((3, 3), dtype=bool)
    accepted: list[tuple[int, int]] = []
    centres: list[FloatArray] = []
    for i, j in zip(pi.tolist(), pj.tolist(), strict=True):
        if any(np.hypot(i - a, j - b) * cell < min_head_distance for a, b in accepted):
            continue
        # The head's region: cells reachable from the peak without descending by the
        # prominence. A higher head inside it makes this peak part of that head.
        regions, _ = ndimage.label(hmap >= hmap[i, j] - min_head_prominence, structure=eight)
        own = regions[i, j]
        if any(regions[a, b] == own for a, b in accepted):
            continue
        accepted.append((i, j))
        ri, rj = np.nonzero((regions == own) & occupied)
        centre = np.array([ri.mean(), rj.mean()]) if ri.size else np.array([i, j], float)
        centres.append(centre)
    cells = np.asarray(centres, dtype=np.float64).reshape(-1, 2)
    heads: FloatArray = origin + (cells - 1 + 0.5) * cell
    return heads


def split_by_heads(
    ground_xy: FloatArray,
    heights: FloatArray,
    labels: IntArray,
    cell: float,
    min_head_distance: float,
    min_head_prominence: float,
) -> IntArray:
    """Split every cluster between its heads: each point goes to the nearest head on the ground."""
    out = np.full(labels.shape, -1, dtype=np.int64)
    next_label = 0
    k = int(labels.max()) + 1 if labels.size else 0
    members_sorted = np.argsort(labels, kind="stable")
    bounds = np.searchsorted(labels[members_sorted], np.arange(k + 1))
    for c in range(k):
        members = members_sorted[bounds[c] : bounds[c + 1]]
        heads = find_heads(
            ground_xy[members], heights[members], cell, min_head_distance, min_head_prominence
        )
        if heads.shape[0] <= 1:
            out[members] = next_label
            next_label += 1
            continue
        d2 = ((ground_xy[members, None, :] - heads[None, :, :]) ** 2).sum(axis=2)
        out[members] = next_label + np.argmin(d2, axis=1)
        next_label += heads.shape[0]
    return out
