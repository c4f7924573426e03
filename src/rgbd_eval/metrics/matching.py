"""Per-frame assignment of ground truth to tracks, in the two conventions, exactly.

Ids are dense indices here (``0..G-1`` for ground truth, ``0..T-1`` for tracks),
and ``valid`` marks the pairs inside the gate.

``motchallenge`` (TrackEval's ``CLEAR.eval_sequence``, which reproduces the
official devkit): in each frame, one Hungarian assignment maximises
``1000 * continued + similarity`` over the valid pairs, where ``continued`` marks
the pair matched in the previous frame that had both ground truth and tracks
(TrackEval does not reset its memory on a frame without either). A match whose
track differs from the last track ever matched to the object is an id switch.

``motmetrics`` (``MOTAccumulator.update`` of py-motmetrics 1.4, scipy solver):
first every object takes back the track it was last matched to, however long
ago, when that pair is valid (objects in frame order, a track to the first
object claiming it); the rest is assigned by a Hungarian assignment that
maximises the number of pairs, then minimises the summed distance. A match of
that second step whose track differs from the object's last one is an id switch.

Hungarian assignments run only where the valid pairs conflict (a row or a column
with two of them); otherwise the valid pairs are the unique optimum. Where they
conflict, the solver sees the same full-frame matrix as the reference, so that
ties are broken the same way.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import linear_sum_assignment

from rgbd_eval.metrics.gating import EPS, FloatArray

IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]
_EMPTY = np.zeros(0, dtype=np.int64)


class FrameMatch(NamedTuple):
    """Matches of one frame: row and column indices into the frame, and id-switch flags."""

    rows: IntArray
    cols: IntArray
    switch: BoolArray


EMPTY_MATCH = FrameMatch(_EMPTY, _EMPTY, np.zeros(0, dtype=bool))


def distinct_pairs(valid: BoolArray) -> tuple[IntArray, IntArray] | None:
    """The valid pairs (rows, columns) when no row and no column holds two of them (then
    they are the assignment), else None."""
    rows, cols = np.nonzero(valid)
    if len(rows) > 1 and (
        len(set(rows.tolist())) < len(rows) or len(set(cols.tolist())) < len(cols)
    ):
        return None
    return rows.astype(np.int64, copy=False), cols.astype(np.int64, copy=False)


def conflict_free(valid: BoolArray) -> bool:
    """Whether no row and no column holds two valid pairs (then they are the assignment)."""
    return distinct_pairs(valid) is not None


def max_similarity_pairs(valid: BoolArray, score: FloatArray) -> tuple[IntArray, IntArray]:
    """TrackEval's assignment: maximise ``score`` over valid pairs (score 0 elsewhere)."""
    pairs = distinct_pairs(valid)
    if pairs is not None:
        return pairs
    masked = np.where(valid, score, 0.0)
    rows, cols = linear_sum_assignment(-masked)
    keep = masked[rows, cols] > EPS
    return rows[keep].astype(np.int64), cols[keep].astype(np.int64)


def _motmetrics_pairs(cost: FloatArray) -> tuple[IntArray, IntArray]:
    """motmetrics 1.4 ``lsa_solve_scipy``: NaN pairs get a cost no full valid set exceeds."""
    valid = np.isfinite(cost)
    if not valid.any():
        return _EMPTY, _EMPTY
    if valid.all():
        finite = cost.copy()
    else:
        c = np.abs(cost[valid]).max() + 1
        finite = np.where(valid, cost, 2 * min(cost.shape) * c + 1)
    rows, cols = linear_sum_assignment(finite)
    keep = valid[rows, cols]
    return rows[keep].astype(np.int64), cols[keep].astype(np.int64)


class MotChallengeMatcher:
    """The ``motchallenge`` convention, frame by frame (see the module docstring).

    ``starts[g]`` counts how often object ``g`` became tracked after not being
    tracked in the previous frame: TrackEval's fragmentation count is the sum of
    ``starts - 1`` over objects tracked at least once.
    """

    def __init__(self, num_gt: int) -> None:
        self.prev_step = np.full(num_gt, -1, dtype=np.int64)
        self.last = np.full(num_gt, -1, dtype=np.int64)
        self.starts = np.zeros(num_gt, dtype=np.int64)
        self._stepped = _EMPTY

    def step(
        self, gt: IntArray, tracks: IntArray, similarity: FloatArray, valid: BoolArray
    ) -> FrameMatch:
        """Match one frame; a frame without ground truth or tracks leaves the memory as is."""
        if len(gt) == 0 or len(tracks) == 0:
            return EMPTY_MATCH
        pairs = distinct_pairs(valid)
        if pairs is None:
            continued = tracks[None, :] == self.prev_step[gt][:, None]
            rows, cols = max_similarity_pairs(valid, 1000.0 * continued + similarity)
        else:
            rows, cols = pairs
        matched_gt, matched_tracks = gt[rows], tracks[cols]
        previous = self.last[matched_gt]
        switch = (previous >= 0) & (previous != matched_tracks)
        self.last[matched_gt] = matched_tracks
        self.starts[matched_gt] += self.prev_step[matched_gt] < 0
        self.prev_step[self._stepped] = -1
        self.prev_step[matched_gt] = matched_tracks
        self._stepped = matched_gt
        return FrameMatch(rows, cols, switch)

    def fragmentations(self) -> int:
        """TrackEval's Frag: tracked stretches after the first, summed over objects."""
        return int(np.maximum(self.starts - 1, 0).sum())


class MotMetricsMatcher:
    """The ``motmetrics`` 1.4 convention, frame by frame (see the module docstring).

    Fragmentations follow motmetrics too: per object, over the frames it is
    present in, every change from missed back to tracked.
    """

    _NEVER, _TRACKED, _LOST = 0, 1, 2

    def __init__(self, num_gt: int, num_tracks: int) -> None:
        self.last = np.full(num_gt, -1, dtype=np.int64)
        self._column = np.full(num_tracks, -1, dtype=np.int64)
        self._state = np.zeros(num_gt, dtype=np.int8)
        self.frags = 0

    def step(
        self, gt: IntArray, tracks: IntArray, distance: FloatArray, valid: BoolArray
    ) -> FrameMatch:
        """Match one frame; ``distance`` is what motmetrics minimises (1 - IoU, or metres)."""
        empty = len(gt) == 0 or len(tracks) == 0
        match = EMPTY_MATCH if empty else self._match(gt, tracks, distance, valid)
        self._count_fragments(gt, match.rows)
        return match

    def _match(
        self, gt: IntArray, tracks: IntArray, distance: FloatArray, valid: BoolArray
    ) -> FrameMatch:
        # 1. Every object takes back its last track when that pair is valid.
        self._column[tracks] = np.arange(len(tracks))
        previous = self.last[gt]
        rows1 = np.flatnonzero(previous >= 0)
        cols1 = self._column[previous[rows1]]
        self._column[tracks] = -1
        present = cols1 >= 0
        rows1, cols1 = rows1[present], cols1[present]
        kept = valid[rows1, cols1]
        rows1, cols1 = rows1[kept], cols1[kept]
        if len(cols1) > 1:  # two objects claiming one track: the first in frame order wins
            _, first = np.unique(cols1, return_index=True)
            first.sort()
            rows1, cols1 = rows1[first], cols1[first]
        # 2. The rest by the Hungarian algorithm (most pairs, then least distance).
        rest = valid.copy()
        rest[rows1, :] = False
        rest[:, cols1] = False
        if not rest.any():
            rows2, cols2 = _EMPTY, _EMPTY
        elif conflict_free(rest):
            rows2, cols2 = (a.astype(np.int64) for a in np.nonzero(rest))
        else:
            rows2, cols2 = _motmetrics_pairs(np.where(rest, distance, np.nan))
        previous2 = previous[rows2]
        switch2 = (previous2 >= 0) & (previous2 != tracks[cols2])
        rows = np.concatenate([rows1, rows2])
        cols = np.concatenate([cols1, cols2])
        self.last[gt[rows]] = tracks[cols]
        switch = np.concatenate([np.zeros(len(rows1), dtype=bool), switch2])
        return FrameMatch(rows, cols, switch)

    def _count_fragments(self, gt: IntArray, matched_rows: IntArray) -> None:
        tracked = np.zeros(len(gt), dtype=bool)
        tracked[matched_rows] = True
        state = self._state[gt]
        self.frags += int(np.count_nonzero(tracked & (state == self._LOST)))
        self._state[gt] = np.where(
            tracked, self._TRACKED, np.where(state == self._NEVER, self._NEVER, self._LOST)
        )
