"""Matching tracks to ignored ground truth, and which objects are scored."""

from __future__ import annotations

import numpy as np
from metrics_builders import gt, track

from rgbd_eval.config import Gating
from rgbd_eval.metrics.selection import is_ignored, is_scored_track, tracks_on_ignored
from rgbd_eval.types import TrackStatus, Visibility


def test_tracks_on_ignored_takes_the_most_pairs() -> None:
    # Ignored I1 = (0, 0, 10, 10), I2 = (3, 0, 10, 10). Tracks:
    #   T0 = (0, 0, 10, 10): IoU with I1 1, with I2 70 / 130 = 0.54
    #   T1 = (2, 0, 10, 10): IoU with I1 80 / 120 = 0.67, with I2 90 / 110 = 0.82
    #   T2 far away.
    # Distances 1 - IoU: I1-T0 0 + I2-T1 0.18 = 0.18 beats I1-T1 0.33 + I2-T0 0.46;
    # either way both T0 and T1 are dropped and T2 stays.
    ignored = np.array([(0, 0, 10, 10), (3, 0, 10, 10)], dtype=float)
    tracks = np.array([(0, 0, 10, 10), (2, 0, 10, 10), (500, 0, 10, 10)], dtype=float)
    assert tracks_on_ignored(ignored, tracks, Gating.IOU, 0.5) == [0, 1]


def test_tracks_on_ignored_pairs_as_many_as_possible() -> None:
    # On the ground: ignored I1 at 0 m, I2 at 1.8 m; tracks T0 at 0.9 m, T1 at 0.0 m.
    # Inside the 1 m gate: I1-T0 0.9, I1-T1 0.0, I2-T0 0.9 (I2-T1 is 1.8 m: out).
    # Two pairs exist only as I1-T1 + I2-T0 (0.0 + 0.9): both tracks are dropped.
    ignored = np.array([(0.0, 0.0), (1.8, 0.0)])
    tracks = np.array([(0.9, 0.0), (0.0, 0.0)])
    assert tracks_on_ignored(ignored, tracks, Gating.METRIC, 1.0) == [0, 1]
    # A gate of 0.5 m leaves only the exact pair.
    assert tracks_on_ignored(ignored, tracks, Gating.METRIC, 0.5) == [1]


def test_tracks_on_ignored_with_nothing() -> None:
    none = np.zeros((0, 2))
    assert tracks_on_ignored(none, np.array([(0.0, 0.0)]), Gating.METRIC, 1.0) == []
    far = np.array([(9.0, 9.0)])
    assert tracks_on_ignored(np.array([(0.0, 0.0)]), far, Gating.METRIC, 1.0) == []


def test_which_objects_are_scored() -> None:
    assert is_scored_track(track(1))
    assert is_scored_track(track(1, visibility=Visibility.OCCLUDED))
    assert not is_scored_track(track(1, visibility=Visibility.NOT_VISIBLE))
    assert not is_scored_track(track(1, status=TrackStatus.NEW))
    assert is_ignored(gt(1, ignore=True), 0.0)
    assert is_ignored(gt(1, visibility=0.3), 0.5)
    assert not is_ignored(gt(1, visibility=0.5), 0.5)  # exactly at the limit: kept
