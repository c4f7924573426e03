"""The vectorised and compiled detector code gives the same results as the straightforward one.

The ``reference_*`` functions below are the implementations before the speed-up
(``np.unique`` voxels and size filters, ``cKDTree`` pairs and ``scipy.sparse.csgraph``
components, ``np.maximum.at`` height maps, ``ndimage`` peak filter and labelling,
blob masks over the whole image), kept verbatim but for their docstrings. The tests
drive both with random inputs and compare the outputs exactly.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.typing import NDArray
from scipy import ndimage
from scipy.sparse import coo_matrix, csgraph
from scipy.spatial import cKDTree

from rgbd_eval.detect import clustering
from rgbd_eval.detect.cloud import (
    PointCloud,
    VoxelGrid,
    depth_to_cloud,
    stable_argsort,
    voxel_grid,
)
from rgbd_eval.detect.clustering import (
    HEAD_SEARCH_RADIUS,
    OVERHANG_GAP,
    PERSON_MAX_WIDTH,
    connected_components,
    euclidean_clusters,
    filter_cluster_sizes,
    find_heads,
    group_extrema,
    merge_close_clusters,
    split_by_heads,
)
from rgbd_eval.detect.plane import cross3
from rgbd_eval.methods.basso2012.features import blob, colour_histogram, touches_border
from rgbd_eval.types import CameraModel

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

SEEDS = st.integers(0, 2**32 - 1)

# ---------------------------------------------------------------- references


def reference_keep_sizes(labels: IntArray, min_points: int, max_points: int | None) -> IntArray:
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


def reference_euclidean_clusters(points: FloatArray, tolerance: float, min_points: int) -> IntArray:
    """Connected components of the graph linking points closer than ``tolerance``."""
    n = points.shape[0]
    if n == 0:
        return np.zeros(0, dtype=np.int64)
    tree = cKDTree(points, balanced_tree=False, compact_nodes=False)
    pairs = tree.query_pairs(tolerance, output_type="ndarray")
    graph = coo_matrix(
        (np.ones(pairs.shape[0], dtype=np.int8), (pairs[:, 0], pairs[:, 1])), shape=(n, n)
    )
    _, labels = csgraph.connected_components(graph, directed=False)
    return reference_keep_sizes(labels.astype(np.int64), min_points, None)


def reference_merge_close_clusters(
    ground_xy: FloatArray,
    labels: IntArray,
    distance: float,
    heights: FloatArray | None = None,
    max_height: float = np.inf,
) -> IntArray:
    """Merge person-sized clusters whose mean ground positions are closer than ``distance``."""
    k = int(labels.max()) + 1 if labels.size else 0
    if k < 2:
        return labels
    valid = labels >= 0
    lab = labels[valid]
    xy = ground_xy[valid]
    counts = np.bincount(lab, minlength=k).astype(np.float64)
    centres = (
        np.stack([np.bincount(lab, weights=xy[:, j], minlength=k) for j in (0, 1)], axis=1)
        / np.maximum(counts, 1.0)[:, None]
    )
    lo = np.full((k, 2), np.inf)
    hi = np.full((k, 2), -np.inf)
    for j in (0, 1):
        np.minimum.at(lo[:, j], lab, xy[:, j])
        np.maximum.at(hi[:, j], lab, xy[:, j])
    mergeable = np.hypot(*(hi - lo).T) <= PERSON_MAX_WIDTH
    if heights is not None:
        top = np.full(k, -np.inf)
        np.maximum.at(top, lab, heights[valid])
        mergeable &= top <= max_height
    candidates = np.flatnonzero(mergeable & (counts > 0))
    if candidates.shape[0] < 2:
        return labels
    pairs = candidates[cKDTree(centres[candidates]).query_pairs(distance, output_type="ndarray")]
    if pairs.shape[0] == 0:
        return labels
    graph = coo_matrix((np.ones(pairs.shape[0]), (pairs[:, 0], pairs[:, 1])), shape=(k, k))
    _, merged = csgraph.connected_components(graph, directed=False)
    out = labels.copy()
    out[valid] = merged[lab]
    return reference_keep_sizes(out, 1, None)


def reference_height_map(
    ground_xy: FloatArray, heights: FloatArray, cell: float, max_height: float
) -> tuple[FloatArray, IntArray, FloatArray, NDArray[np.bool_]]:
    """Highest point per ground cell, with overhangs taken out."""
    origin = ground_xy.min(axis=0)
    ij = np.floor((ground_xy - origin) / cell).astype(np.int64) + 1
    shape = (int(ij[:, 0].max()) + 2, int(ij[:, 1].max()) + 2)
    high = heights > max_height
    hmap = np.zeros(shape, dtype=np.float64)
    np.maximum.at(hmap, (ij[~high, 0], ij[~high, 1]), heights[~high])
    overhang = np.zeros(heights.shape, dtype=bool)
    if np.any(high):
        lowest_high = np.full(shape, np.inf)
        np.minimum.at(lowest_high, (ij[high, 0], ij[high, 1]), heights[high])
        top_high = np.zeros(shape)
        np.maximum.at(top_high, (ij[high, 0], ij[high, 1]), heights[high])
        floor_of_gap = np.maximum(hmap, max_height - OVERHANG_GAP)
        tall = np.isfinite(lowest_high) & (lowest_high - floor_of_gap <= OVERHANG_GAP)
        hmap[tall] = top_high[tall]
        overhang = high & ~tall[ij[:, 0], ij[:, 1]]
    return hmap, ij, origin, overhang


def reference_head_seeds(
    hmap: FloatArray,
    cell: float,
    min_head_distance: float,
    min_head_prominence: float,
    head_heights: tuple[float, float],
) -> tuple[IntArray, list[FloatArray]]:
    """Seed regions of the map (0 = none): the heads first (1..H), then tall structures."""
    lowest, highest = head_heights
    seeds = np.zeros(hmap.shape, dtype=np.int64)
    tall = hmap > highest
    radius = max(1, int(np.floor(0.5 * min_head_distance / cell)))
    yy, xx = np.mgrid[-radius : radius + 1, -radius : radius + 1]
    disk = yy * yy + xx * xx <= radius * radius
    peaks = (
        (hmap >= lowest)
        & ~tall
        & (hmap >= ndimage.maximum_filter(hmap, footprint=disk, mode="constant"))
    )
    pi, pj = np.nonzero(peaks)
    order = np.lexsort((pj, pi, -hmap[pi, pj]))
    half = max(1, int(np.ceil(HEAD_SEARCH_RADIUS / cell)))
    eight = np.ones((3, 3), dtype=bool)
    min_cells2 = (min_head_distance / cell) ** 2
    accepted: list[tuple[int, int]] = []
    centres: list[FloatArray] = []
    for i, j in zip(pi[order].tolist(), pj[order].tolist(), strict=True):
        if any((i - a) ** 2 + (j - b) ** 2 < min_cells2 for a, b in accepted):
            continue
        i0, j0 = max(0, i - half), max(0, j - half)
        window = hmap[i0 : i + half + 1, j0 : j + half + 1]
        regions, _ = ndimage.label(window >= hmap[i, j] - min_head_prominence, structure=eight)
        mine = regions == regions[i - i0, j - j0]
        taken = seeds[i0 : i + half + 1, j0 : j + half + 1]
        if np.any(mine & ((taken > 0) | (window > highest))):
            continue
        accepted.append((i, j))
        taken[mine] = len(accepted)
        ri, rj = np.nonzero(mine)
        centres.append(np.array([ri.mean() + i0, rj.mean() + j0]))
    tall_regions, _ = ndimage.label(tall, structure=eight)
    seeds[tall] = tall_regions[tall] + len(accepted)
    return seeds, centres


def reference_split_by_heads(
    ground_xy: FloatArray,
    heights: FloatArray,
    labels: IntArray,
    cell: float,
    min_head_distance: float,
    min_head_prominence: float,
    head_heights: tuple[float, float] = (0.0, np.inf),
) -> IntArray:
    """Split every cluster between its heads and taller structures."""
    out = np.full(labels.shape, -1, dtype=np.int64)
    next_label = 0
    k = int(labels.max()) + 1 if labels.size else 0
    members_sorted = np.argsort(labels, kind="stable")
    bounds = np.searchsorted(labels[members_sorted], np.arange(k + 1))
    for c in range(k):
        members = members_sorted[bounds[c] : bounds[c + 1]]
        hmap, ij, _, overhang = reference_height_map(
            ground_xy[members], heights[members], cell, head_heights[1]
        )
        seeds, heads = reference_head_seeds(
            hmap, cell, min_head_distance, min_head_prominence, head_heights
        )
        n_seeds = int(seeds.max())
        if not heads:
            out[members] = next_label
            next_label += 1
            continue
        if n_seeds == 1:
            sub = np.zeros(members.shape[0], dtype=np.int64)
        else:
            _, (ni, nj) = ndimage.distance_transform_edt(seeds == 0, return_indices=True)
            sub = seeds[ni, nj][ij[:, 0], ij[:, 1]] - 1
        out[members] = np.where(overhang, -1, next_label + sub)
        next_label += n_seeds
    return reference_keep_sizes(out, 1, None)


def reference_depth_to_cloud(
    depth: NDArray[np.floating], rays: FloatArray, max_depth: float
) -> PointCloud:
    """Back-project a depth image with precomputed unit-depth ``rays`` (``(H, W, 3)``)."""
    flat = depth.reshape(-1)
    valid = np.isfinite(flat) & (flat > 0.0) & (flat <= max_depth)
    pixels = np.flatnonzero(valid).astype(np.int64)
    z = flat[pixels].astype(np.float64)
    points = rays.reshape(-1, 3)[pixels] * z[:, None]
    return PointCloud(points=points, pixels=pixels)


def reference_voxel_grid(points: FloatArray, voxel_size: float) -> VoxelGrid:
    """Down-sample to the centroid of the points in each occupied cube of side ``voxel_size``."""
    cells = np.floor(points / voxel_size).astype(np.int64)
    cells -= cells.min(axis=0)
    dims = cells.max(axis=0) + 1
    keys = (cells[:, 0] * dims[1] + cells[:, 1]) * dims[2] + cells[:, 2]
    if int(dims.prod()) < 2**31:
        keys = keys.astype(np.int32)
    _, point_voxel, counts = np.unique(keys, return_inverse=True, return_counts=True)
    point_voxel = point_voxel.astype(np.int64).reshape(-1)
    m = counts.shape[0]
    sums = np.stack(
        [np.bincount(point_voxel, weights=points[:, k], minlength=m) for k in range(3)], axis=1
    )
    centroids = sums / counts[:, None]
    return VoxelGrid(centroids=centroids, point_voxel=point_voxel, counts=counts.astype(np.int64))


def reference_blob_pixels(uv: FloatArray, footprint: int, rgb_camera: CameraModel) -> IntArray:
    """Flat RGB-image indices of the blob: each projected point covers ``footprint^2`` pixels."""
    if uv.shape[0] == 0:
        return np.zeros(0, dtype=np.int64)
    k = max(1, int(footprint))
    offsets = np.arange(k, dtype=np.float64) - (k - 1) / 2.0
    du, dv = np.meshgrid(offsets, offsets)
    u = np.rint(uv[:, 0:1] + du.reshape(1, -1)).astype(np.int64).reshape(-1)
    v = np.rint(uv[:, 1:2] + dv.reshape(1, -1)).astype(np.int64).reshape(-1)
    ok = (u >= 0) & (u < rgb_camera.width) & (v >= 0) & (v < rgb_camera.height)
    mask = np.zeros(rgb_camera.width * rgb_camera.height, dtype=bool)
    mask[v[ok] * rgb_camera.width + u[ok]] = True
    pixels: IntArray = np.flatnonzero(mask).astype(np.int64)
    return pixels


def reference_colour_histogram(
    rgb: NDArray[np.uint8], pixels: IntArray, bins: int
) -> NDArray[np.float32]:
    """Flattened 3D RGB histogram (``bins**3`` values, R slowest) normalised to sum 1."""
    size = bins**3
    if pixels.shape[0] == 0:
        return np.full(size, 1.0 / size, dtype=np.float32)
    flat = rgb.reshape(-1, rgb.shape[-1])
    lut = np.arange(256, dtype=np.intp) * bins // 256
    index = (lut[flat[pixels, 0]] * bins + lut[flat[pixels, 1]]) * bins + lut[flat[pixels, 2]]
    hist = np.bincount(index, minlength=size).astype(np.float64)
    out: NDArray[np.float32] = (hist / hist.sum()).astype(np.float32)
    return out


# ---------------------------------------------------------------- random scenes


def people_scene(seed: int) -> tuple[FloatArray, FloatArray, IntArray]:
    """Ground positions, heights and cluster labels of a few random people, walls and shelves.

    People are head-and-shoulder bumps (sometimes two in one cluster), walls are
    tall columns reaching the floor, shelves are overhangs above ``max_height``,
    pieces lie next to the previous cluster (to be merged with it).
    """
    rng = np.random.default_rng(seed)
    xy_parts, h_parts, labels = [], [], []
    centre = rng.uniform(-1.5, 1.5, 2)
    for c in range(int(rng.integers(1, 6))):
        kind = rng.choice(["person", "pair", "wall", "shelf", "low", "piece"])
        if kind != "piece":
            centre = rng.uniform(-1.5, 1.5, 2)
        n = int(rng.integers(5, 300))
        if kind in ("person", "pair"):
            heads = [centre] if kind == "person" else [centre, centre + rng.uniform(-0.7, 0.7, 2)]
            pts = []
            for head in heads:
                offsets = rng.normal(0, 0.1, (n, 2))
                r = np.hypot(*offsets.T)
                top = rng.uniform(1.4, 2.0)
                pts.append((head + offsets, np.clip(top - 1.5 * r * r, 0.1, None)))
            xy = np.vstack([p[0] for p in pts])
            h = np.concatenate([p[1] for p in pts]) * rng.uniform(0.3, 1.0, len(pts) * n)
        elif kind == "wall":
            xy = centre + np.column_stack([rng.uniform(0, 2, n), rng.normal(0, 0.02, n)])
            h = rng.uniform(0.1, 2.8, n)
        elif kind == "shelf":
            xy = centre + rng.uniform(-0.5, 0.5, (n, 2))
            h = np.where(rng.random(n) < 0.5, rng.uniform(2.4, 2.6, n), rng.uniform(0.1, 1.9, n))
        elif kind == "low":
            xy = centre + rng.uniform(-0.4, 0.4, (n, 2))
            h = rng.uniform(0.1, 1.0, n)
        else:  # a piece near the previous cluster's centre (a head cut from its body)
            xy = centre + rng.uniform(-0.25, 0.25, 2) + rng.normal(0, 0.05, (n, 2))
            h = rng.uniform(1.2, 2.0, n)
        xy_parts.append(xy)
        h_parts.append(h)
        labels.append(np.full(len(h), c))
    order = rng.permutation(sum(len(h) for h in h_parts))
    lab = np.concatenate(labels)[order]
    lab[rng.random(lab.shape[0]) < 0.05] = -1  # a few unclustered points
    return np.vstack(xy_parts)[order], np.concatenate(h_parts)[order], lab


# ---------------------------------------------------------------- tests


@settings(max_examples=100, deadline=None)
@given(SEEDS, st.integers(1, 30), st.integers(0, 400))
def test_group_extrema_match_ufunc_at(seed: int, k: int, n: int) -> None:
    rng = np.random.default_rng(seed)
    groups = rng.integers(0, k, n)
    values = rng.normal(size=(n, 2))
    lo, hi = group_extrema(groups, values, k)
    want_lo, want_hi = np.full((k, 2), np.inf), np.full((k, 2), -np.inf)
    np.minimum.at(want_lo, groups, values)
    np.maximum.at(want_hi, groups, values)
    assert np.array_equal(lo, want_lo)
    assert np.array_equal(hi, want_hi)


@settings(max_examples=100, deadline=None)
@given(SEEDS, st.integers(1, 25), st.integers(1, 25), st.integers(1, 4))
def test_map_filter_matches_ndimage(seed: int, rows: int, cols: int, radius: int) -> None:
    rng = np.random.default_rng(seed)
    image = np.where(rng.random((rows, cols)) < 0.3, 0.0, rng.normal(1.0, 1.0, (rows, cols)))
    yy, xx = np.mgrid[-radius : radius + 1, -radius : radius + 1]
    disk = yy * yy + xx * xx <= radius * radius
    want = ndimage.maximum_filter(image, footprint=disk, mode="constant")
    assert np.array_equal(clustering._maximum_filter(image, radius), want)


@settings(max_examples=200, deadline=None)
@given(
    SEEDS,
    st.integers(1, 45),
    st.integers(1, 45),
    st.sampled_from([0.0, 0.1, 0.3]),
    st.sampled_from([(1.4, 2.3), (0.0, np.inf), (-1.0, 2.0)]),
)
def test_head_seeds_match_reference(
    seed: int, rows: int, cols: int, prominence: float, head_heights: tuple[float, float]
) -> None:
    rng = np.random.default_rng(seed)
    # Bumps of person-like heights in 2 cm steps (plateaus, ties), some cells empty.
    yy, xx = np.mgrid[0:rows, 0:cols]
    hmap = np.zeros((rows, cols))
    for _ in range(rng.integers(0, 6)):
        ci, cj, width = rng.uniform(0, rows), rng.uniform(0, cols), rng.uniform(1.0, 6.0)
        bump = rng.uniform(1.0, 2.6) * np.exp(-((yy - ci) ** 2 + (xx - cj) ** 2) / width**2)
        hmap = np.maximum(hmap, bump)
    hmap = np.round((hmap + rng.uniform(0, 0.3, hmap.shape)) / 0.02) * 0.02
    hmap[rng.random(hmap.shape) < 0.1] = 0.0
    seeds, centres = clustering._head_seeds(hmap, 0.06, 0.3, prominence, head_heights)
    want_seeds, want_centres = reference_head_seeds(hmap, 0.06, 0.3, prominence, head_heights)
    assert np.array_equal(seeds, want_seeds)
    assert np.array_equal(centres, np.asarray(want_centres, dtype=np.float64).reshape(-1, 2))


@settings(max_examples=150, deadline=None)
@given(SEEDS)
def test_height_map_matches_reference(seed: int) -> None:
    xy, h, _ = people_scene(seed)
    got = clustering._height_map(xy, h, 0.06, 2.3)
    want = reference_height_map(xy, h, 0.06, 2.3)
    for a, b in zip(got, want, strict=True):
        assert np.array_equal(a, b)


@settings(max_examples=150, deadline=None)
@given(SEEDS, st.sampled_from([(1.4, 2.3), (0.0, np.inf), (-1.0, 2.0)]))
def test_subclustering_matches_reference(seed: int, head_heights: tuple[float, float]) -> None:
    xy, h, labels = people_scene(seed)
    merged = merge_close_clusters(xy, labels, 0.3, h, head_heights[1])
    assert np.array_equal(
        merged, reference_merge_close_clusters(xy, labels, 0.3, h, head_heights[1])
    )
    assert np.array_equal(
        merge_close_clusters(xy, labels, 0.3), reference_merge_close_clusters(xy, labels, 0.3)
    )
    got = split_by_heads(xy, h, merged, 0.06, 0.3, 0.1, head_heights)
    want = reference_split_by_heads(xy, h, merged, 0.06, 0.3, 0.1, head_heights)
    assert np.array_equal(got, want)
    for c in range(int(merged.max()) + 1):  # the head positions of every cluster
        mine = merged == c
        hmap, _, origin, _ = reference_height_map(xy[mine], h[mine], 0.06, head_heights[1])
        _, centres = reference_head_seeds(hmap, 0.06, 0.3, 0.1, head_heights)
        heads = origin + (np.asarray(centres).reshape(-1, 2) - 1 + 0.5) * 0.06
        assert np.array_equal(find_heads(xy[mine], h[mine], 0.06, 0.3, 0.1, head_heights), heads)


@settings(max_examples=150, deadline=None)
@given(SEEDS, st.integers(0, 400), st.integers(1, 6), st.sampled_from([1, 3, 8, 16]))
def test_blob_and_histogram_match_reference(seed: int, n: int, footprint: int, bins: int) -> None:
    rng = np.random.default_rng(seed)
    camera = CameraModel(64, 48, 50.0, 50.0, 31.5, 23.5)
    # Points on and off the image, some on pixel centres and half-pixels (rounding ties).
    uv = rng.uniform(-10, 74, (n, 2))
    uv[: n // 3] = np.round(uv[: n // 3] * 2) / 2
    rgb = rng.integers(0, 256, (48, 64, 3), dtype=np.uint8)
    b = blob(uv, footprint, camera)
    rows, cols = np.nonzero(b.mask)
    want = reference_blob_pixels(uv, footprint, camera)
    assert np.array_equal((rows + b.top) * camera.width + (cols + b.left), want)
    got_hist = colour_histogram(rgb, b, bins)
    assert np.array_equal(got_hist, reference_colour_histogram(rgb, want, bins))


@settings(max_examples=200, deadline=None)
@given(SEEDS)
def test_cross3_is_np_cross(seed: int) -> None:
    rng = np.random.default_rng(seed)
    a, b = rng.normal(size=(2, 3)) * rng.choice([1e-3, 1.0, 1e3], (2, 3))
    assert np.array_equal(cross3(a, b), np.cross(a, b))


@settings(max_examples=100, deadline=None)
@given(SEEDS, st.integers(1, 3000), st.sampled_from([0.06, 0.5, 1e-3]))
def test_voxel_grid_matches_reference(seed: int, n: int, size: float) -> None:
    # Size 1 mm over a 6 m cube: more than 2**31 cells, the plain stable argsort.
    rng = np.random.default_rng(seed)
    points = rng.uniform(-3, 3, (n, 3))
    points[: n // 2] = np.round(points[: n // 2], 1)  # many points per voxel
    got, want = voxel_grid(points, size), reference_voxel_grid(points, size)
    assert np.array_equal(got.point_voxel, want.point_voxel)
    assert np.array_equal(got.counts, want.counts)
    assert np.array_equal(got.centroids, want.centroids)


@settings(max_examples=150, deadline=None)
@given(SEEDS, st.integers(0, 300), st.integers(0, 600))
def test_connected_components_match_csgraph(seed: int, n: int, edges: int) -> None:
    rng = np.random.default_rng(seed)
    pairs = rng.integers(0, max(n, 1), (edges if n else 0, 2))
    labels = connected_components(pairs, n)
    graph = coo_matrix((np.ones(pairs.shape[0]), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, theirs = csgraph.connected_components(graph, directed=False)
    # The same partition, each node labelled with the smallest node of its component.
    smallest = np.full(theirs.max() + 1 if n else 0, n)
    np.minimum.at(smallest, theirs, np.arange(n))
    assert np.array_equal(labels, smallest[theirs])


@settings(max_examples=100, deadline=None)
@given(SEEDS, st.integers(0, 2000), st.integers(1, 40), st.sampled_from([None, 30, 200]))
def test_clusters_and_size_filter_match_reference(
    seed: int, n: int, min_points: int, max_points: int | None
) -> None:
    rng = np.random.default_rng(seed)
    points = rng.uniform(0, 2, (n, 3)) * rng.uniform(0.2, 1.0, 3)
    got = euclidean_clusters(points, 0.12, min_points)
    assert np.array_equal(got, reference_euclidean_clusters(points, 0.12, min_points))
    labels = rng.integers(-1, 50, n) * rng.integers(1, 4)  # gaps in the numbering
    assert np.array_equal(
        filter_cluster_sizes(labels, min_points, max_points),
        reference_keep_sizes(labels, min_points, max_points),
    )


@settings(max_examples=200, deadline=None)
@given(
    SEEDS,
    st.integers(1, 600),
    st.sampled_from([0.12, 0.06 * 2.0, 0.1, 0.35, 1e-7]),
    st.sampled_from([1e-3, 1.0, 100.0]),
)
def test_grid_clusters_match_kdtree_at_the_tolerance(
    seed: int, n: int, tolerance: float, offset: float
) -> None:
    """Pairs at (or a few ulps around) exactly the tolerance are linked as by cKDTree."""
    rng = np.random.default_rng(seed)
    # Voxel-centroid-like points: a lattice of voxels (some of step ``tolerance``),
    # jittered or not, far from the origin or not.
    step = rng.choice([0.06, tolerance, tolerance / 2])
    base = (
        offset + step * rng.integers(0, 12, (n, 3)) + rng.choice([0.0, 1e-3]) * rng.random((n, 3))
    )
    # Partners displaced along one axis by the tolerance, nudged by -2..2 ulps.
    axis = rng.integers(0, 3, n)
    moved = base.copy()
    moved[np.arange(n), axis] += tolerance
    for _ in range(2):
        nudge = rng.integers(-1, 2, (n, 1)) * (np.arange(3) == axis[:, None])
        moved = np.where(nudge > 0, np.nextafter(moved, np.inf), moved)
        moved = np.where(nudge < 0, np.nextafter(moved, -np.inf), moved)
    points = np.concatenate([base, moved])[rng.permutation(2 * n)]
    got = euclidean_clusters(points, tolerance, 1)
    assert np.array_equal(got, reference_euclidean_clusters(points, tolerance, 1))


@settings(max_examples=100, deadline=None)
@given(SEEDS, st.sampled_from([np.float32, np.float64]))
def test_depth_to_cloud_matches_reference(seed: int, dtype: type) -> None:
    rng = np.random.default_rng(seed)
    depth = rng.uniform(-1.0, 8.0, (12, 16)).astype(dtype)
    specials = [np.nan, np.inf, -np.inf, 0.0, 6.5]  # invalid, and the limit itself
    depth.reshape(-1)[rng.integers(0, depth.size, 40)] = rng.choice(specials, 40)
    rays = CameraModel(16, 12, 10.0, 10.0, 7.5, 5.5).rays()
    got, want = depth_to_cloud(depth, rays, 6.5), reference_depth_to_cloud(depth, rays, 6.5)
    assert np.array_equal(got.pixels, want.pixels)
    assert np.array_equal(got.points, want.points)


@settings(max_examples=100, deadline=None)
@given(SEEDS, st.integers(0, 3000), st.sampled_from([1, 7, 5000, 2**31, 2**40]))
def test_stable_argsort_is_numpys(seed: int, n: int, key_count: int) -> None:
    keys = np.random.default_rng(seed).integers(0, key_count, n)
    for dtype in (np.int64, np.int32) if key_count <= 2**31 else (np.int64,):
        k = keys.astype(dtype)
        assert np.array_equal(stable_argsort(k, key_count), np.argsort(k, kind="stable"))


def reference_touches_border(pixels: IntArray, camera: CameraModel) -> tuple[bool, bool, bool]:
    """Whether a cluster's depth pixels reach the image's top, bottom, or left/right edge."""
    if pixels.shape[0] == 0:
        return (False, False, False)
    rows, cols = np.divmod(pixels, camera.width)
    return (
        bool(rows.min() == 0),
        bool(rows.max() == camera.height - 1),
        bool(cols.min() == 0 or cols.max() == camera.width - 1),
    )


@settings(max_examples=150, deadline=None)
@given(SEEDS, st.integers(0, 50), st.integers(1, 12), st.integers(1, 16))
def test_touches_border_matches_reference(seed: int, n: int, rows: int, cols: int) -> None:
    camera = CameraModel(cols, rows, 10.0, 10.0, cols / 2, rows / 2)
    pixels = np.random.default_rng(seed).integers(0, rows * cols, n)
    assert touches_border(pixels, camera) == reference_touches_border(pixels, camera)
