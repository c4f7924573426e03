"""What one frame contributes to scoring: scored ground truth, scored tracks, ignored ones.

- A track is scored when it is ``VALIDATED`` and not ``NOT_VISIBLE``.
- A ground-truth object is ignored when ``ignore`` is set or its visibility is
  below ``min_visibility``. Ignored objects count neither as misses nor as
  matches. As in the MOTChallenge devkit (TrackEval's MOT preprocessing), the
  scored tracks are matched against all ground truth of the frame, scored and
  ignored together (one assignment maximising the summed similarity over the
  pairs inside the gate), and the tracks matched to an ignored *distractor* are
  dropped from the frame; a track matched to a non-distractor ignored object
  (MOT17's consider flag 0, non-person classes) stays and may become a false
  positive. The rest is scored normally.
- IoU gating needs ``box2d`` on scored tracks and scored ground truth; metric
  gating needs ``world_xyz`` on scored ground truth (tracks always have x, y).
  An ignored object lacking the field (a person out of the image has no box)
  stays ignored and drops no track.

Ids must be unique per frame and smaller than 2**53 in magnitude (motmetrics,
the parity reference of one convention, stores them as float64).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rgbd_eval.config import Gating
from rgbd_eval.errors import ScoringError
from rgbd_eval.metrics.gating import (
    FloatArray,
    checked_measure,
    gate,
    measure_matrix,
    similarity_from_measure,
)
from rgbd_eval.metrics.matching import max_similarity_pairs
from rgbd_eval.types import Box2D, GroundTruthObject, TrackOutput, TrackStatus, Visibility

_MAX_ID = 2**53


@dataclass(frozen=True)
class FrameSelection:
    """The scored part of one frame, ready for a distance matrix.

    ``gt_values``/``track_values`` are ``(N, 4)`` boxes (IoU gating) or ``(N, 2)``
    ground-plane positions (metric gating), row-aligned with the ids.
    ``measure`` is their ungated IoU or ground-plane distance (rows: ground truth).
    ``present_track_ids`` are all scored tracks, including the dropped ones.
    """

    gt_ids: list[int]
    gt_values: FloatArray
    track_ids: list[int]
    track_values: FloatArray
    measure: FloatArray
    ignored_gt_ids: list[int]
    dropped_track_ids: list[int]
    present_track_ids: frozenset[int]


def is_scored_track(track: TrackOutput) -> bool:
    """Whether a track output takes part in scoring (validated and visible or occluded)."""
    return track.status is TrackStatus.VALIDATED and track.visibility is not Visibility.NOT_VISIBLE


def is_ignored(gt: GroundTruthObject, min_visibility: float) -> bool:
    """Whether a ground-truth object is ignored (flagged, or less visible than allowed)."""
    return gt.ignore or gt.visibility < min_visibility


def _check_ids(frame: int, what: str, ids: list[int]) -> None:
    if len(set(ids)) != len(ids):
        repeated = sorted({i for i in ids if ids.count(i) > 1})
        raise ScoringError(f"frame {frame}: {what} id(s) {repeated} appear more than once")
    if ids and (max(ids) >= _MAX_ID or min(ids) <= -_MAX_ID):
        raise ScoringError(f"frame {frame}: {what} ids must be smaller than 2**53 in magnitude")


def _gt_values(
    frame: int, objects: Sequence[GroundTruthObject], gating: Gating, required: bool
) -> tuple[list[int], FloatArray]:
    ids: list[int] = []
    rows: list[tuple[float, ...]] = []
    for gt in objects:
        if gating is Gating.IOU:
            value: tuple[float, ...] | None = gt.box2d.as_tuple() if gt.box2d is not None else None
            needed = "2D box (box2d), needed for IoU gating"
        else:
            value = gt.world_xyz[:2] if gt.world_xyz is not None else None
            needed = "world position (world_xyz), needed for metric gating"
        if value is None:
            if required:
                raise ScoringError(f"frame {frame}: ground-truth id {gt.object_id} has no {needed}")
            continue
        ids.append(gt.object_id)
        rows.append(value)
    return ids, _rows(frame, "ground-truth", ids, rows, gating)


def _track_values(
    frame: int, tracks: Sequence[TrackOutput], gating: Gating
) -> tuple[list[int], FloatArray]:
    ids = [t.track_id for t in tracks]
    rows: list[tuple[float, ...]] = []
    if gating is Gating.IOU:
        for t in tracks:
            if t.box2d is None:
                raise ScoringError(
                    f"frame {frame}: track id {t.track_id} has no 2D box (box2d), "
                    "needed for IoU gating"
                )
            rows.append(t.box2d.as_tuple())
    else:
        rows = [(t.x, t.y) for t in tracks]
    return ids, _rows(frame, "track", ids, rows, gating)


def _rows(
    frame: int, what: str, ids: list[int], rows: list[tuple[float, ...]], gating: Gating
) -> FloatArray:
    if not rows:
        return np.zeros((0, 4 if gating is Gating.IOU else 2))
    values = np.array(rows, dtype=np.float64)
    if np.isfinite(values).all() and (gating is Gating.METRIC or values[:, 2:].min() >= 0):
        return values
    bad = ~np.isfinite(values).all(axis=1)
    if gating is Gating.IOU:
        bad |= (values[:, 2:] < 0).any(axis=1)
    index = int(np.flatnonzero(bad)[0])
    kind = "box" if gating is Gating.IOU else "position"
    raise ScoringError(
        f"frame {frame}: {what} id {ids[index]} has an invalid {kind} {rows[index]} "
        "(values must be finite, box width and height >= 0)"
    )


def tracks_on_ignored(
    ignored_values: FloatArray, track_values: FloatArray, gating: Gating, threshold: float
) -> list[int]:
    """Indices of the tracks matched to ignored ground truth when nothing else is present."""
    if len(ignored_values) == 0 or len(track_values) == 0:
        return []
    measure = measure_matrix(gating, ignored_values, track_values)
    similarity = similarity_from_measure(gating, measure, threshold)
    valid = gate(gating, measure, similarity, threshold, exact_trackeval=True)
    _, cols = max_similarity_pairs(valid, similarity)
    return sorted(int(c) for c in cols)


def select_frame(
    frame: int,
    gt_objects: Sequence[GroundTruthObject],
    tracks: Sequence[TrackOutput],
    gating: Gating,
    threshold: float,
    min_visibility: float,
) -> FrameSelection:
    """Split one frame into scored and ignored parts (see the module docstring)."""
    selected = _select_valid(frame, gt_objects, tracks, gating, threshold, min_visibility)
    if selected is not None:
        return selected
    return _select_checking(frame, gt_objects, tracks, gating, threshold, min_visibility)


def _select_valid(
    frame: int,
    gt_objects: Sequence[GroundTruthObject],
    tracks: Sequence[TrackOutput],
    gating: Gating,
    threshold: float,
    min_visibility: float,
) -> FrameSelection | None:
    """:func:`select_frame` in one pass over the objects and one measure matrix (the scored
    ground truth's rows of the frame's); None when a check fails, for
    :func:`_select_checking` to name the problem as it always has."""
    iou = gating is Gating.IOU
    gt_ids: list[int] = []
    ignored_ids: list[int] = []
    joined: list[tuple[float, ...]] = []  # every object with the gated field, in input order
    scored_rows: list[bool] = []
    distractor: list[bool] = []
    for g in gt_objects:
        value = g.box2d if iou else g.world_xyz
        if g.ignore or g.visibility < min_visibility:
            ignored_ids.append(g.object_id)
            if value is None:
                continue
            scored_rows.append(False)
            distractor.append(g.distractor)
        elif value is None:
            return None
        else:
            gt_ids.append(g.object_id)
            scored_rows.append(True)
            distractor.append(False)
        joined.append(value.as_tuple() if isinstance(value, Box2D) else value[:2])
    scored_tracks = [t for t in tracks if is_scored_track(t)]
    track_ids = [t.track_id for t in scored_tracks]
    if iou:
        boxes = [t.box2d for t in scored_tracks]
        if None in boxes:
            return None
        track_rows: list[tuple[float, ...]] = [b.as_tuple() for b in boxes if b is not None]
    else:
        track_rows = [(t.x, t.y) for t in scored_tracks]
    columns = 4 if iou else 2
    joined_values = np.array(joined, dtype=np.float64).reshape(len(joined), columns)
    track_values = np.array(track_rows, dtype=np.float64).reshape(len(track_rows), columns)
    if not (_ids_ok(gt_ids + ignored_ids) and _ids_ok(track_ids)):
        return None
    if not (_values_ok(joined_values, iou) and _values_ok(track_values, iou)):
        return None
    return _split(
        gating,
        threshold,
        gt_ids,
        ignored_ids,
        joined_values,
        scored_rows,
        distractor,
        track_ids,
        track_values,
    )


def _split(
    gating: Gating,
    threshold: float,
    gt_ids: list[int],
    ignored_ids: list[int],
    joined_values: FloatArray,
    scored_rows: Sequence[bool] | NDArray[np.bool_],
    distractor: Sequence[bool] | NDArray[np.bool_],
    track_ids: list[int],
    track_values: FloatArray,
) -> FrameSelection:
    """The selection of a frame whose ids and values are checked: ``joined_values`` are the
    rows of its ground truth with the gated field (input order), ``scored_rows`` marks the
    scored ones and ``distractor`` the ignored distractors among them."""
    present = frozenset(track_ids)
    everyone_scored = not ignored_ids
    gt_values = joined_values if everyone_scored else joined_values[scored_rows]
    if not track_ids:
        measure = np.zeros((len(gt_ids), 0))
        return FrameSelection(
            gt_ids, gt_values, track_ids, track_values, measure, ignored_ids, [], present
        )
    joined_measure = checked_measure(gating, joined_values, track_values)
    if everyone_scored:
        return FrameSelection(
            gt_ids, gt_values, track_ids, track_values, joined_measure, [], [], present
        )
    similarity = similarity_from_measure(gating, joined_measure, threshold)
    valid = gate(gating, joined_measure, similarity, threshold, exact_trackeval=True)
    is_distractor = np.asarray(distractor, dtype=bool)
    measure = joined_measure[scored_rows]
    # A track is dropped only through a valid pair with a distractor (the assignment's pairs
    # are valid ones): without any, the assignment cannot drop one.
    if not valid[is_distractor].any():
        return FrameSelection(
            gt_ids, gt_values, track_ids, track_values, measure, ignored_ids, [], present
        )
    rows, cols = max_similarity_pairs(valid, similarity)
    dropped = np.zeros(len(track_ids), dtype=bool)
    dropped[cols[is_distractor[rows]]] = True
    keep = ~dropped
    return FrameSelection(
        gt_ids=gt_ids,
        gt_values=gt_values,
        track_ids=[i for i, k in zip(track_ids, keep.tolist(), strict=True) if k],
        track_values=track_values[keep],
        measure=measure[:, keep],
        ignored_gt_ids=ignored_ids,
        dropped_track_ids=[i for i, d in zip(track_ids, dropped.tolist(), strict=True) if d],
        present_track_ids=present,
    )


def select_frames(
    gt_frames: Sequence[Sequence[GroundTruthObject]],
    track_frames: Sequence[Sequence[TrackOutput]],
    gating: Gating,
    threshold: float,
    min_visibility: float,
) -> list[FrameSelection]:
    """:func:`select_frame` of every frame (``gt_frames[i]`` with ``track_frames[i]``), the
    objects' fields read and checked once for the sequence, as arrays. Should a check fail
    (or an object lack the gated field), frame by frame: the first problem is named as
    :func:`select_frame` names it."""
    if len(gt_frames) != len(track_frames):
        raise ValueError("gt_frames and track_frames must be equally long")
    selections = _select_sequence(gt_frames, track_frames, gating, threshold, min_visibility)
    if selections is not None:
        return selections
    return [
        select_frame(i, g, t, gating, threshold, min_visibility)
        for i, (g, t) in enumerate(zip(gt_frames, track_frames, strict=True))
    ]


def _select_sequence(
    gt_frames: Sequence[Sequence[GroundTruthObject]],
    track_frames: Sequence[Sequence[TrackOutput]],
    gating: Gating,
    threshold: float,
    min_visibility: float,
) -> list[FrameSelection] | None:
    """:func:`select_frames` when every check passes, else None."""
    iou = gating is Gating.IOU
    columns = 4 if iou else 2
    objects = [o for frame in gt_frames for o in frame]
    scored = [[t for t in frame if is_scored_track(t)] for frame in track_frames]
    tracks = [t for frame in scored for t in frame]
    gt_rows: list[tuple[float, ...]]
    track_rows: list[tuple[float, ...]]
    if iou:
        gt_boxes = [o.box2d for o in objects]
        track_boxes = [t.box2d for t in tracks]
        if any(b is None for b in gt_boxes) or any(b is None for b in track_boxes):
            return None
        gt_rows = [b.as_tuple() for b in gt_boxes if b is not None]
        track_rows = [b.as_tuple() for b in track_boxes if b is not None]
    else:
        worlds = [o.world_xyz for o in objects]
        if any(w is None for w in worlds):
            return None
        gt_rows = [w[:2] for w in worlds if w is not None]
        track_rows = [(t.x, t.y) for t in tracks]
    ids = [o.object_id for o in objects]
    track_ids = [t.track_id for t in tracks]
    if not (_ids_in_range(ids) and _ids_in_range(track_ids)):
        return None
    gt_values = np.array(gt_rows, dtype=np.float64).reshape(len(objects), columns)
    track_values = np.array(track_rows, dtype=np.float64).reshape(len(tracks), columns)
    gt_counts = [len(frame) for frame in gt_frames]
    track_counts = [len(frame) for frame in scored]
    frames = np.arange(len(gt_frames))
    if not (
        _values_ok(gt_values, iou)
        and _values_ok(track_values, iou)
        and _unique_per_frame(np.repeat(frames, gt_counts), ids)
        and _unique_per_frame(np.repeat(frames, track_counts), track_ids)
    ):
        return None
    ignored = [o.ignore or o.visibility < min_visibility for o in objects]
    is_scored = ~np.array(ignored, dtype=bool).reshape(len(objects))
    distractor = np.array([o.distractor for o in objects], dtype=bool) & ~is_scored
    out = []
    g1 = t1 = 0
    for n_gt, n_tracks in zip(gt_counts, track_counts, strict=True):
        g0, g1, t0, t1 = g1, g1 + n_gt, t1, t1 + n_tracks
        frame_ids, frame_ignored = ids[g0:g1], ignored[g0:g1]
        if any(frame_ignored):
            gt_ids = [i for i, ign in zip(frame_ids, frame_ignored, strict=True) if not ign]
            ignored_ids = [i for i, ign in zip(frame_ids, frame_ignored, strict=True) if ign]
        else:
            gt_ids, ignored_ids = frame_ids, []
        out.append(
            _split(
                gating,
                threshold,
                gt_ids,
                ignored_ids,
                gt_values[g0:g1],
                is_scored[g0:g1],
                distractor[g0:g1],
                track_ids[t0:t1],
                track_values[t0:t1],
            )
        )
    return out


def _ids_in_range(ids: list[int]) -> bool:
    """Whether ids are within :func:`_check_ids`' range."""
    return not ids or (min(ids) > -_MAX_ID and max(ids) < _MAX_ID)


def _unique_per_frame(frames: NDArray[np.int64], ids: list[int]) -> bool:
    """Whether no id repeats within a frame (ids in range: exact as int64)."""
    if len(ids) < 2:
        return True
    values = np.array(ids, dtype=np.int64)
    order = np.lexsort((values, frames))
    f, v = frames[order], values[order]
    return not bool(((f[1:] == f[:-1]) & (v[1:] == v[:-1])).any())


def _ids_ok(ids: list[int]) -> bool:
    """Whether ids are unique and within :func:`_check_ids`' range."""
    return not ids or (len(set(ids)) == len(ids) and min(ids) > -_MAX_ID and max(ids) < _MAX_ID)


def _values_ok(values: FloatArray, boxes: bool) -> bool:
    """Whether values pass :func:`_rows`' checks (finite; box sizes >= 0)."""
    if not len(values):
        return True
    return bool(np.isfinite(values).all()) and (not boxes or bool(values[:, 2:].min() >= 0))


def _select_checking(
    frame: int,
    gt_objects: Sequence[GroundTruthObject],
    tracks: Sequence[TrackOutput],
    gating: Gating,
    threshold: float,
    min_visibility: float,
) -> FrameSelection:
    """:func:`select_frame` step by step, each check raising its ScoringError."""
    _check_ids(frame, "ground-truth", [g.object_id for g in gt_objects])
    scored_tracks = [t for t in tracks if is_scored_track(t)]
    track_ids, track_values = _track_values(frame, scored_tracks, gating)
    _check_ids(frame, "track", track_ids)
    ignored_flags = [is_ignored(g, min_visibility) for g in gt_objects]
    scored_gt = [g for g, ignored in zip(gt_objects, ignored_flags, strict=True) if not ignored]
    gt_ids, gt_values = _gt_values(frame, scored_gt, gating, required=True)
    present = frozenset(track_ids)
    ignored_ids = [g.object_id for g, ign in zip(gt_objects, ignored_flags, strict=True) if ign]
    if not ignored_ids or not track_ids:
        measure = measure_matrix(gating, gt_values, track_values)
        return FrameSelection(
            gt_ids, gt_values, track_ids, track_values, measure, ignored_ids, [], present
        )
    # All ground truth of the frame, in input order, against the scored tracks.
    joined = [
        g for g, ign in zip(gt_objects, ignored_flags, strict=True) if not ign or _has(g, gating)
    ]
    _, joined_values = _gt_values(frame, joined, gating, required=False)
    joined_measure = measure_matrix(gating, joined_values, track_values)
    similarity = similarity_from_measure(gating, joined_measure, threshold)
    valid = gate(gating, joined_measure, similarity, threshold, exact_trackeval=True)
    rows, cols = max_similarity_pairs(valid, similarity)
    distractor = np.array(
        [is_ignored(g, min_visibility) and g.distractor for g in joined], dtype=bool
    )
    dropped = np.zeros(len(track_ids), dtype=bool)
    dropped[cols[distractor[rows]]] = True
    scored_rows = np.array([not is_ignored(g, min_visibility) for g in joined], dtype=bool)
    keep = ~dropped
    return FrameSelection(
        gt_ids=gt_ids,
        gt_values=gt_values,
        track_ids=[i for i, k in zip(track_ids, keep.tolist(), strict=True) if k],
        track_values=track_values[keep],
        measure=joined_measure[scored_rows][:, keep],
        ignored_gt_ids=ignored_ids,
        dropped_track_ids=[i for i, d in zip(track_ids, dropped.tolist(), strict=True) if d],
        present_track_ids=present,
    )


def _has(gt: GroundTruthObject, gating: Gating) -> bool:
    return (gt.box2d if gating is Gating.IOU else gt.world_xyz) is not None
