"""DMT-BS tracking and blob splitting (seed 003, 3.3-3.4): hand-computed micro-scenarios."""

from __future__ import annotations

import numpy as np
import pytest

from rgbd_eval.methods.dmtbs.blob_split import nearest_blob, split_centroids, voronoi_split
from rgbd_eval.methods.dmtbs.tracker import DmtbsTracker, DmtbsTrackerConfig
from rgbd_eval.types import Box2D, Detection, TrackStatus, Visibility

STEP_NS = 100_000_000  # 10 Hz keeps the arithmetic short


def _disc(cx: float, cy: float) -> np.ndarray:
    """Cells of a disc of radius 0.2 m on a 0.1 m lattice: offsets i^2 + j^2 <= 4 (13 cells)."""
    ij = [(i, j) for i in range(-2, 3) for j in range(-2, 3) if i * i + j * j <= 4]
    return np.array([(cx + 0.1 * i, cy + 0.1 * j) for i, j in ij])


def _touching_discs() -> np.ndarray:
    # Disc A at (0, 0) reaches x = 0.2, disc B at (0.5, 0) starts at x = 0.3: adjacent cells,
    # one 8-connected blob of 26 cells.
    return np.concatenate([_disc(0.0, 0.0), _disc(0.5, 0.0)])


def _det(cells: np.ndarray) -> Detection:
    c = cells.mean(axis=0)
    return Detection(
        position=(float(c[0]), float(c[1]), 0.0),
        height=1.8,
        confidence=1.0,
        box2d=Box2D(0, 0, 0, 0),
        footprint=cells,
    )


def test_voronoi_split_of_two_touching_discs() -> None:
    cells = _touching_discs()
    # Predictions at (0.05, 0) and (0.5, 0): the bisector is x = 0.275, between the discs,
    # so each prediction gets its own disc back, centroids (0, 0) and (0.5, 0).
    parts = voronoi_split(cells, np.array([[0.05, 0.0], [0.5, 0.0]]))
    assert [p.shape[0] for p in parts] == [13, 13]
    np.testing.assert_allclose(
        split_centroids(cells, np.array([[0.05, 0.0], [0.5, 0.0]])),
        [(0.0, 0.0), (0.5, 0.0)],
        atol=1e-12,
    )


def test_voronoi_split_follows_the_predictions_not_the_discs() -> None:
    cells = _touching_discs()
    # Predictions at (-0.1, 0) and (0.3, 0): bisector x = 0.1. Track 0 gets disc A's cells
    # with x <= 0: column i = -2 (1 cell), i = -1 (3 cells), i = 0 (5 cells) = 9 cells, mean
    # x = (-0.2 * 1 - 0.1 * 3 + 0 * 5) / 9 = -0.5 / 9; y is symmetric: 0.
    # Track 1 gets the other 17: A's i = 1 (3 cells at 0.1), i = 2 (1 cell at 0.2) and all of
    # B (13 cells, mean 0.5): x = (0.3 + 0.2 + 6.5) / 17 = 7.0 / 17.
    parts = split_centroids(cells, np.array([[-0.1, 0.0], [0.3, 0.0]]))
    assert parts[0] == pytest.approx((-0.5 / 9, 0.0), abs=1e-12)
    assert parts[1] == pytest.approx((7.0 / 17, 0.0), abs=1e-12)


def test_voronoi_empty_part_and_no_seed() -> None:
    cells = _disc(0.0, 0.0)
    assert split_centroids(cells, np.array([[0.0, 0.0], [5.0, 0.0]]))[1] is None
    with pytest.raises(ValueError, match="at least one seed"):
        voronoi_split(cells, np.zeros((0, 2)))


def test_nearest_blob_within_distance() -> None:
    blobs = [_disc(0.0, 0.0), _disc(2.0, 0.0)]
    # (0.25, 0) is 0.05 from A's cell (0.2, 0): on blob A at 0.1 m, not at 0.04 m.
    assert nearest_blob(np.array([0.25, 0.0]), blobs, 0.1) == 0
    assert nearest_blob(np.array([0.25, 0.0]), blobs, 0.04) is None
    assert nearest_blob(np.array([1.9, 0.05]), blobs, 0.1) == 1


def _walk_to_merge(tracker: DmtbsTracker, frames_apart: int) -> list:
    """Two people 0.5 m apart stand still as two blobs, then their blobs touch.

    Each disc alone is detected for ``frames_apart`` frames; then the blob image holds one
    merged blob of both discs (its centroid is the mean of 26 cells: x = 0.25).
    """
    a, b = _disc(0.0, 0.0), _disc(0.5, 0.0)
    stamp = 0
    outputs = []
    for _ in range(frames_apart):
        stamp += STEP_NS
        outputs = tracker.update(stamp, [_det(a), _det(b)])
    stamp += STEP_NS
    merged = _touching_discs()
    outputs = tracker.update(stamp, [_det(merged)])
    return outputs


def test_tracks_older_than_one_second_are_split() -> None:
    cfg = DmtbsTrackerConfig(min_split_age_s=1.0, confirm_hits=3)
    tracker = DmtbsTracker(cfg)
    # 11 frames at 10 Hz: the tracks were born at 0.1 s; at the merge (1.2 s) they are 1.1 s old.
    out = _walk_to_merge(tracker, frames_apart=11)
    assert tracker.splits == 1
    assert [o.track_id for o in out] == [1, 2]
    # Both are measured (visible) at their own disc: the merged centroid (0.25, 0) is 0.25 m
    # from each prediction, the Hungarian gives it to one; the other falls on the blob (its
    # prediction is a cell of it), so the blob is split at x = 0.25 back into the discs.
    assert all(o.visibility is Visibility.VISIBLE for o in out)
    assert out[0].x == pytest.approx(0.0, abs=0.01)
    assert out[1].x == pytest.approx(0.5, abs=0.01)


def test_tracks_younger_than_one_second_are_not_split() -> None:
    cfg = DmtbsTrackerConfig(min_split_age_s=1.0, confirm_hits=3)
    tracker = DmtbsTracker(cfg)
    # 9 frames: born at 0.1 s, at the merge (1.0 s) they are 0.9 s old: too young. One track
    # takes the merged centroid (x = 0.25) and moves towards it; the other coasts, occluded.
    out = _walk_to_merge(tracker, frames_apart=9)
    assert tracker.splits == 0
    assert [o.visibility for o in out] == [Visibility.VISIBLE, Visibility.OCCLUDED]
    assert 0.0 < out[0].x < 0.25
    assert out[1].x == pytest.approx(0.5, abs=1e-9)


def test_age_rule_boundary_is_inclusive() -> None:
    # 10 frames: born at 0.1 s, the merge at 1.1 s: exactly 1 s old -> split.
    tracker = DmtbsTracker(DmtbsTrackerConfig(min_split_age_s=1.0))
    _walk_to_merge(tracker, frames_apart=10)
    assert tracker.splits == 1


def test_time_spent_coasting_does_not_count_towards_the_split_age() -> None:
    # The seed splits "blobs that have been in view for enough frames". Disc A is seen from
    # 0.1 s on; disc B from 0.1 to 0.4 s (4 frames, confirmed at its third), then B's track
    # coasts (max_missed 1 s) standing still while A is still seen. At 1.2 s A's blob has
    # grown over B's prediction (the two discs touch): B is 1.1 s old but has been in view
    # only 0.3 s (0.1 -> 0.4 s; 0.8 s coasting), so the blob is not split; B coasts on.
    tracker = DmtbsTracker(DmtbsTrackerConfig(min_split_age_s=1.0, confirm_hits=3))
    a, b = _disc(0.0, 0.0), _disc(0.5, 0.0)
    for k in range(1, 12):
        tracker.update(k * STEP_NS, [_det(a), _det(b)] if k <= 4 else [_det(a)])
    out = tracker.update(12 * STEP_NS, [_det(_touching_discs())])
    assert tracker.splits == 0
    assert [o.visibility for o in out] == [Visibility.VISIBLE, Visibility.OCCLUDED]
    # The same timeline with B seen throughout is split (test above: 1.1 s in view).
    seen = DmtbsTracker(DmtbsTrackerConfig(min_split_age_s=1.0, confirm_hits=3))
    for k in range(1, 12):
        seen.update(k * STEP_NS, [_det(a), _det(b)])
    seen.update(12 * STEP_NS, [_det(_touching_discs())])
    assert seen.splits == 1


def test_confirmation_and_deletion_counts() -> None:
    cfg = DmtbsTrackerConfig(confirm_hits=3, max_missed_s=0.3)
    tracker = DmtbsTracker(cfg)
    det = _det(_disc(1.0, 1.0))
    statuses = [tracker.update(k * STEP_NS, [det])[0].status for k in range(1, 4)]
    # hits 1, 2 -> new; hit 3 confirms
    assert statuses == [TrackStatus.NEW, TrackStatus.NEW, TrackStatus.VALIDATED]
    # Missed at 0.4, 0.5, 0.6 s (0.1, 0.2, 0.3 s since last seen at 0.3 s): kept, occluded;
    # at 0.7 s it is 0.4 s > 0.3 s: dropped.
    for k in (4, 5, 6):
        out = tracker.update(k * STEP_NS, [])
        assert [o.visibility for o in out] == [Visibility.OCCLUDED]
    assert tracker.update(7 * STEP_NS, []) == []


def test_unconfirmed_track_dies_on_its_first_miss() -> None:
    tracker = DmtbsTracker(DmtbsTrackerConfig(confirm_hits=3))
    tracker.update(STEP_NS, [_det(_disc(1.0, 1.0))])
    assert tracker.update(2 * STEP_NS, []) == []


def test_constant_velocity_prediction_follows_a_walker() -> None:
    # A blob moving 0.1 m per 0.1 s (1 m/s along x): after 20 frames the velocity estimate is
    # near 1 m/s, and one missed frame is coasted to about x + 0.1.
    tracker = DmtbsTracker(DmtbsTrackerConfig())
    for k in range(20):
        tracker.update((k + 1) * STEP_NS, [_det(_disc(0.1 * k, 0.0))])
    out = tracker.update(21 * STEP_NS, [])
    assert out[0].x == pytest.approx(2.0, abs=0.05)


def test_gate_refuses_far_detections() -> None:
    tracker = DmtbsTracker(DmtbsTrackerConfig(gate_m=1.0))
    tracker.update(STEP_NS, [_det(_disc(0.0, 0.0))])
    # 1.5 m away: a new track, and the first one (unconfirmed, missed) is dropped.
    out = tracker.update(2 * STEP_NS, [_det(_disc(1.5, 0.0))])
    assert [o.track_id for o in out] == [2]


def test_stamps_must_increase() -> None:
    tracker = DmtbsTracker(DmtbsTrackerConfig())
    tracker.update(STEP_NS, [])
    with pytest.raises(ValueError, match="must increase"):
        tracker.update(STEP_NS, [])
