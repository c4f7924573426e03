"""Euclidean clusters, head-based sub-clustering and per-cluster features (seed 000, 5.2, 5.3)."""

from __future__ import annotations

import numpy as np
import pytest

from rgbd_eval.detect.clustering import (
    euclidean_clusters,
    filter_cluster_sizes,
    find_heads,
    merge_close_clusters,
    split_by_heads,
)
from rgbd_eval.methods.basso2012.features import (
    HEAD_FRACTION,
    Blob,
    blob,
    cluster_geometry,
    colour_histogram,
    occluded_by_nearer_points,
)
from rgbd_eval.types import Box2D, CameraModel

# ---------------------------------------------------------------- Euclidean clusters


def test_euclidean_clusters_link_chains_within_tolerance() -> None:
    # Tolerance 0.12 (2 x 0.06 voxel). Points 0-1-2 are 0.1 apart (one chain),
    # point 3 is 0.2 from point 2 (separate), points 4-5 are 0.05 apart.
    pts = np.array(
        [[0, 0, 0], [0.1, 0, 0], [0.2, 0, 0], [0.4, 0, 0], [2, 0, 0], [2.05, 0, 0]], float
    )
    labels = euclidean_clusters(pts, 0.12, min_points=1)
    assert labels.tolist() == [0, 0, 0, 1, 2, 2]
    # min_points = 2 drops the single point 3; labels renumbered in order.
    assert euclidean_clusters(pts, 0.12, min_points=2).tolist() == [0, 0, 0, -1, 1, 1]


def test_filter_cluster_sizes() -> None:
    labels = np.array([0, 0, 0, 1, 2, 2, -1])
    # Sizes: 0 -> 3, 1 -> 1, 2 -> 2. Keep 2..2: only cluster 2, renumbered 0.
    assert filter_cluster_sizes(labels, 2, 2).tolist() == [-1, -1, -1, -1, 0, 0, -1]


def test_bad_tolerance_raises() -> None:
    with pytest.raises(ValueError, match="tolerance"):
        euclidean_clusters(np.zeros((2, 3)), 0.0, 1)


def test_merge_close_clusters_joins_head_and_body() -> None:
    # Cluster 0 centred at (0, 0), cluster 1 at (0.1, 0): 0.1 < 0.3 apart -> merged;
    # cluster 2 at (1, 0) stays alone.
    xy = np.array([[0, 0], [0, 0], [0.1, 0], [0.1, 0], [1, 0], [1, 0]], float)
    labels = np.array([0, 0, 1, 1, 2, 2])
    assert merge_close_clusters(xy, labels, 0.3).tolist() == [0, 0, 0, 0, 1, 1]


def test_merge_leaves_out_tall_and_wide_pieces() -> None:
    # Cluster 0: a 0.2 m piece, centre (0, 0); cluster 1: a ceiling-like piece whose
    # centre (0.1, 0) is close but which spans 4 m (wider than a person, 1 m) and
    # is 2.7 m high (above max_height 2.3): they are not merged. Cluster 2, a small
    # piece at (0.2, 0), 1.5 m high, is merged with cluster 0.
    xy = np.array([[-0.1, 0], [0.1, 0], [-1.9, 0], [2.1, 0], [0.2, 0], [0.2, 0.05]])
    heights = np.array([1.0, 1.0, 2.7, 2.7, 1.5, 1.5])
    labels = np.array([0, 0, 1, 1, 2, 2])
    merged = merge_close_clusters(xy, labels, 0.3, heights, 2.3)
    assert merged.tolist() == [0, 0, 1, 1, 0, 0]


# ---------------------------------------------------------------- head sub-clustering


def _person_cloud(cx: float, cy: float, height: float) -> tuple[np.ndarray, np.ndarray]:
    """A crude person on a 3 cm ground grid: a head disc (r 0.1) above shoulders (r 0.22)."""
    g = np.arange(-0.3, 0.3001, 0.03)
    xx, yy = np.meshgrid(g, g)
    r = np.hypot(xx, yy)
    keep = r <= 0.22
    heights = np.where(r <= 0.1, height, height - 0.3)[keep]  # head-to-shoulder drop 0.3 m
    return np.column_stack([xx[keep] + cx, yy[keep] + cy]), heights


def test_two_people_shoulder_to_shoulder_give_two_heads() -> None:
    # Heads 0.45 m apart (>= 0.3 m); between them the map dips to shoulder level:
    # 1.65 - 1.75 + 0.3 = 0.2 m below the lower head >= 0.1 m prominence.
    a_xy, a_h = _person_cloud(0.0, 0.0, 1.75)
    b_xy, b_h = _person_cloud(0.45, 0.0, 1.65)
    xy, h = np.vstack([a_xy, b_xy]), np.concatenate([a_h, b_h])
    heads = find_heads(xy, h, 0.06, 0.3, 0.1)
    assert heads.shape == (2, 2)
    # Highest first, each within one cell of its true position.
    np.testing.assert_allclose(heads[0], [0.0, 0.0], atol=0.06)
    np.testing.assert_allclose(heads[1], [0.45, 0.0], atol=0.06)
    labels = split_by_heads(xy, h, np.zeros(len(h), dtype=np.int64), 0.06, 0.3, 0.1)
    # Every point goes to the nearer head on the ground.
    assert set(labels[: len(a_h)].tolist()) == {0}
    assert set(labels[len(a_h) :].tolist()) == {1}


def test_heads_closer_than_the_minimum_distance_are_one() -> None:
    a_xy, a_h = _person_cloud(0.0, 0.0, 1.75)
    b_xy, b_h = _person_cloud(0.2, 0.0, 1.70)  # 0.2 m < 0.3 m
    heads = find_heads(np.vstack([a_xy, b_xy]), np.concatenate([a_h, b_h]), 0.06, 0.3, 0.1)
    assert heads.shape[0] == 1


def test_flat_l_shaped_top_edge_is_one_object() -> None:
    # The top edges of a cabinet's front and side faces at 1.9 m (+- 1 cm noise):
    # every path between its local maxima stays within 2 cm of 1.9, below the
    # 0.1 m prominence, so it is not split although it is 1.1 m long.
    rng = np.random.default_rng(0)
    front = np.column_stack([np.zeros(40), np.linspace(0, 0.6, 40)])
    side = np.column_stack([np.linspace(0, 0.5, 30), np.zeros(30)])
    xy = np.vstack([front, side])
    h = 1.9 + rng.uniform(-0.01, 0.01, xy.shape[0])
    assert find_heads(xy, h, 0.06, 0.3, 0.1).shape[0] == 1


# ---------------------------------------------------------------- features


PLANE = np.array([0.0, -1.0, 0.0, 1.0])  # floor 1 m below a level camera (optical y down)


def test_cluster_geometry_height_centroids_distance() -> None:
    # A vertical stick of points at x = 0.5, z = 4 from height 0.1 to 1.7 (optical y = 1 - h).
    hs = np.linspace(0.1, 1.7, 17)
    pts = np.column_stack([np.full(17, 0.5), 1.0 - hs, np.full(17, 4.0)])
    g = cluster_geometry(pts, pts, PLANE, head_centroid=False, surface_correction=False)
    assert g.height == pytest.approx(1.7)
    assert g.lowest == pytest.approx(0.1)
    # Real centroid: mean height 0.9 -> y = 0.1; distance sqrt(0.5^2 + 0.1^2 + 4^2).
    np.testing.assert_allclose(g.real_centroid, [0.5, 0.1, 4.0])
    assert g.distance == pytest.approx(np.sqrt(0.25 + 0.01 + 16.0))
    # Theoretical centroid: ground projection (y = 1) raised by h/2 = 0.85 -> y = 0.15.
    np.testing.assert_allclose(g.theoretical_centroid, [0.5, 0.15, 4.0])
    np.testing.assert_allclose(g.ground_point, [0.5, 1.0, 4.0])
    np.testing.assert_allclose(g.top_point, [0.5, -0.7, 4.0])
    # Head centroid: points with height >= 1.7 * (1 - 1/8) = 1.4875 -> 1.5, 1.6, 1.7.
    head = cluster_geometry(pts, pts, PLANE, head_centroid=True, surface_correction=False)
    assert abs(HEAD_FRACTION - 1 / 8) < 1e-12
    assert head.real_centroid[1] == pytest.approx(1.0 - 1.6)


def test_surface_correction_finds_the_axis_of_a_cylinder() -> None:
    # The visible half of an upright cylinder (r = 0.1, axis at x = 0, z = 3), sampled
    # uniformly in the across coordinate x as a camera's pixels do. Its mean is
    # pi r / 4 = 7.9 cm in front of the axis; the correction moves it back.
    r = 0.1
    x = np.linspace(-r, r, 201)[1:-1]
    z = 3.0 - np.sqrt(r * r - x * x)
    pts = np.vstack([np.column_stack([x, np.full_like(x, 1.0 - h), z]) for h in (1.6, 1.65, 1.7)])
    raw = cluster_geometry(pts, pts, PLANE, head_centroid=True, surface_correction=False)
    fixed = cluster_geometry(pts, pts, PLANE, head_centroid=True, surface_correction=True)
    assert 3.0 - raw.real_centroid[2] == pytest.approx(np.pi * r / 4, abs=2e-3)
    assert fixed.real_centroid[2] == pytest.approx(3.0, abs=0.01)


def test_occlusion_by_nearer_points_in_the_box() -> None:
    box = Box2D(100.0, 50.0, 40.0, 200.0)
    uv = np.array([[120.0, 240.0], [300.0, 100.0]])
    # The first point is inside the box and 1 m nearer: occluded.
    assert occluded_by_nearer_points(box, 4.0, uv, np.array([3.0, 3.0]), 0.12)
    # Inside the box but farther (behind the person): not occluded.
    assert not occluded_by_nearer_points(box, 4.0, uv, np.array([5.0, 3.0]), 0.12)
    # Nearer, but only by 0.1 < 0.12 margin: the same body, not an occluder.
    assert not occluded_by_nearer_points(box, 4.0, uv, np.array([3.9, 3.0]), 0.12)
    assert not occluded_by_nearer_points(box, 4.0, np.zeros((0, 2)), np.zeros(0), 0.12)


def test_colour_histogram_counts_blob_pixels() -> None:
    rgb = np.zeros((2, 2, 3), dtype=np.uint8)
    rgb[0, 0] = (255, 0, 0)  # bins (1, 0, 0) with 2 bins per channel -> index 4
    rgb[0, 1] = (255, 0, 0)
    rgb[1, 0] = (0, 0, 200)  # bins (0, 0, 1) -> index 1
    three = Blob(0, 0, np.array([[True, True], [True, False]]))
    hist = colour_histogram(rgb, three, 2)
    assert hist.dtype == np.float32 and hist.shape == (8,)
    # 2 of 3 pixels in bin 4, 1 of 3 in bin 1.
    np.testing.assert_allclose(hist, [0, 1 / 3, 0, 0, 2 / 3, 0, 0, 0], atol=1e-7)
    # The box is placed on the image: only pixel (1, 0) in a 1x1 box.
    np.testing.assert_allclose(colour_histogram(rgb, Blob(1, 0, np.ones((1, 1), bool)), 2)[1], 1)
    empty = colour_histogram(rgb, Blob(0, 0, np.zeros((0, 0), dtype=bool)), 2)
    np.testing.assert_allclose(empty, np.full(8, 1 / 8))


def test_blob_covers_each_points_footprint() -> None:
    cam = CameraModel(10, 10, 5.0, 5.0, 4.5, 4.5)
    # A point off the image adds nothing.
    b = blob(np.array([[2.0, 3.0], [50.0, 50.0]]), 3, cam)
    # Footprint 3: offsets -1, 0, 1 -> a 3x3 block centred on (u=2, v=3).
    rows, cols = np.nonzero(b.mask)
    assert sorted(set((rows + b.top).tolist())) == [2, 3, 4]
    assert sorted(set((cols + b.left).tolist())) == [1, 2, 3]
    assert rows.shape[0] == 9
    assert not blob(np.array([[50.0, 50.0]]), 3, cam).mask.any()


def test_person_next_to_a_wall_is_split_from_it() -> None:
    # A wall line at y = 0.4 m, 2.6 m tall and 2 m long (above max_height 2.3: a
    # tall seed), with a person at the origin whose shoulders touch it.
    p_xy, p_h = _person_cloud(0.0, 0.0, 1.75)
    wx = np.arange(-1.0, 1.0, 0.03)
    w_xy = np.column_stack([np.concatenate([wx] * 41), np.full(41 * wx.size, 0.4)])
    w_h = np.repeat(np.linspace(0.2, 2.6, 41), wx.size)  # 6 cm apart, as voxels
    xy, h = np.vstack([p_xy, w_xy]), np.concatenate([p_h, w_h])
    labels = split_by_heads(xy, h, np.zeros(len(h), dtype=np.int64), 0.06, 0.3, 0.1, (1.4, 2.3))
    person, wall = labels[: len(p_h)], labels[len(p_h) :]
    assert len(set(person.tolist())) == 1 and len(set(wall.tolist())) == 1
    assert person[0] != wall[0]


def test_overhanging_ceiling_does_not_hide_the_person() -> None:
    # A ceiling at 2.7 m over the person (no points between 1.75 and 2.7 in those
    # cells): the head is still found and the ceiling points belong to no one.
    p_xy, p_h = _person_cloud(0.0, 0.0, 1.75)
    g = np.arange(-0.6, 0.6, 0.05)
    cx, cy = np.meshgrid(g, g)
    c_xy = np.column_stack([cx.ravel(), cy.ravel()])
    c_h = np.full(c_xy.shape[0], 2.7)
    xy, h = np.vstack([p_xy, c_xy]), np.concatenate([p_h, c_h])
    heads = find_heads(xy, h, 0.06, 0.3, 0.1, (1.4, 2.3))
    assert heads.shape == (1, 2)
    np.testing.assert_allclose(heads[0], [0.0, 0.0], atol=0.06)
    labels = split_by_heads(xy, h, np.zeros(len(h), dtype=np.int64), 0.06, 0.3, 0.1, (1.4, 2.3))
    assert set(labels[: len(p_h)].tolist()) == {0}
    assert set(labels[len(p_h) :].tolist()) == {-1}
