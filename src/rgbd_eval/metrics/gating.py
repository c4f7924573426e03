"""Distance matrices between ground truth and tracks, in the motmetrics convention.

A distance matrix has one row per ground-truth object and one column per track;
NaN marks a pair that may not be matched (outside the gate). Two gates:

- IoU on RGB image boxes (seed 000, 7.3: the PASCAL test, IoU >= 0.5). The
  distance is ``1 - IoU``; a pair is matchable when ``IoU >= threshold``.
- Euclidean distance on the ground plane (world x, y) in metres (seed 001, V-B:
  a match needs a distance below 1 m). A pair is matchable when
  ``distance <= threshold`` ("no more than the threshold distance", seed 003,
  Evaluation metrics); the two differ only for a distance of exactly 1 m.

Boxes are ``(left, top, width, height)`` rows in continuous pixel coordinates
(no "+1" pixel convention). ``motmetrics.distances.iou_matrix`` is not used: in
motmetrics 1.4.0 it calls ``np.asfarray``, which NumPy 2 removed.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rgbd_eval.config import Gating

FloatArray = NDArray[np.float64]

#: Float tolerance of TrackEval's comparisons (``np.finfo("float").eps``).
EPS = float(np.finfo(np.float64).eps)
#: IoU a match needs by default: the PASCAL criterion (seed 000, 7.3).
DEFAULT_IOU_THRESHOLD = 0.5
#: Ground-plane distance (m) a match may have by default (seed 001, V-B).
DEFAULT_METRIC_THRESHOLD = 1.0


def _as_rows(values: ArrayLike, columns: int, name: str) -> FloatArray:
    array = np.asarray(values, dtype=np.float64)
    if array.size == 0:
        return np.zeros((0, columns))
    if array.ndim != 2 or array.shape[1] != columns:
        raise ValueError(f"{name} must have shape (N, {columns}), got {array.shape}")
    if not np.isfinite(array).all():  # one reduction: cheap on the tiny per-frame arrays
        raise ValueError(f"{name} contains non-finite values")
    return array


def _as_boxes(boxes: ArrayLike, name: str) -> FloatArray:
    array = _as_rows(boxes, 4, name)
    if len(array) and array[:, 2:].min() < 0:
        raise ValueError(f"{name}: box width and height must be >= 0")
    return array


def iou_matrix(gt_boxes: ArrayLike, track_boxes: ArrayLike) -> FloatArray:
    """Intersection over union of every ground-truth box with every track box.

    Both inputs are ``(N, 4)`` / ``(M, 4)`` arrays of ``(left, top, width, height)``;
    the result is ``(N, M)`` in ``[0, 1]``. The arithmetic is TrackEval's
    (``_calculate_box_ious``, corners first, areas from the corners), so that the
    values are bit for bit the ones the devkit convention is defined on; a box of
    zero area has IoU 0 with everything.
    """
    return box_iou(_as_boxes(gt_boxes, "gt_boxes"), _as_boxes(track_boxes, "track_boxes"))


def box_iou(a: FloatArray, b: FloatArray) -> FloatArray:
    """:func:`iou_matrix` of boxes already checked: ``(N, 4)`` and ``(M, 4)`` float64 arrays,
    finite, width and height >= 0 (the per-frame scoring checks them once, as arrays)."""
    ax0, ay0 = a[:, 0:1], a[:, 1:2]
    ax1, ay1 = ax0 + a[:, 2:3], ay0 + a[:, 3:4]
    bx0, by0 = b[:, 0], b[:, 1]
    bx1, by1 = bx0 + b[:, 2], by0 + b[:, 3]
    width = np.maximum(np.minimum(ax1, bx1) - np.maximum(ax0, bx0), 0.0)
    height = np.maximum(np.minimum(ay1, by1) - np.maximum(ay0, by0), 0.0)
    intersection = width * height
    area_a = (ax1 - ax0) * (ay1 - ay0)
    area_b = (bx1 - bx0) * (by1 - by0)
    union = area_a + area_b - intersection
    intersection[(area_a <= EPS)[:, 0], :] = 0.0
    intersection[:, area_b <= EPS] = 0.0
    degenerate = union <= EPS
    intersection[degenerate] = 0.0
    union[degenerate] = 1.0
    iou: FloatArray = intersection / union
    return iou


def ground_distance_matrix(gt_xy: ArrayLike, track_xy: ArrayLike) -> FloatArray:
    """Euclidean distance (m) of every ground-truth (x, y) to every track (x, y)."""
    a = _as_rows(gt_xy, 2, "gt_xy")
    b = _as_rows(track_xy, 2, "track_xy")
    diff = a[:, None, :] - b[None, :, :]
    return np.asarray(np.hypot(diff[..., 0], diff[..., 1]), dtype=np.float64)


def check_threshold(gating: Gating, threshold: float) -> None:
    """Raise ``ValueError`` unless ``threshold`` is valid for ``gating``."""
    if gating is Gating.IOU:
        if not 0.0 < threshold <= 1.0:
            raise ValueError(f"threshold={threshold} for IoU gating must be in (0, 1]")
    elif not (np.isfinite(threshold) and threshold > 0.0):
        raise ValueError(f"threshold={threshold} for metric gating must be a positive distance (m)")


def iou_distance_matrix(
    gt_boxes: ArrayLike, track_boxes: ArrayLike, threshold: float = DEFAULT_IOU_THRESHOLD
) -> FloatArray:
    """``1 - IoU`` where ``IoU >= threshold``, NaN elsewhere (not matchable)."""
    check_threshold(Gating.IOU, threshold)
    iou = iou_matrix(gt_boxes, track_boxes)
    return np.where(iou >= threshold, 1.0 - iou, np.nan)


def metric_distance_matrix(
    gt_xy: ArrayLike, track_xy: ArrayLike, threshold: float = DEFAULT_METRIC_THRESHOLD
) -> FloatArray:
    """Ground-plane distance (m) where ``distance <= threshold``, NaN elsewhere."""
    check_threshold(Gating.METRIC, threshold)
    distance = ground_distance_matrix(gt_xy, track_xy)
    return np.where(distance <= threshold, distance, np.nan)


def distance_matrix(
    gating: Gating, gt_values: ArrayLike, track_values: ArrayLike, threshold: float
) -> FloatArray:
    """The gated distance matrix for ``gating``: boxes for IoU, (x, y) rows for metric."""
    if gating is Gating.IOU:
        return iou_distance_matrix(gt_values, track_values, threshold)
    return metric_distance_matrix(gt_values, track_values, threshold)


def similarity(gating: Gating, distance: float) -> float:
    """What MOTP averages for one match: IoU (``1 - distance``) or the distance in metres."""
    return 1.0 - distance if gating is Gating.IOU else distance


def measure_matrix(gating: Gating, gt_values: ArrayLike, track_values: ArrayLike) -> FloatArray:
    """Ungated IoU (IoU gating) or ground-plane distance in metres (metric gating)."""
    if gating is Gating.IOU:
        return iou_matrix(gt_values, track_values)
    return ground_distance_matrix(gt_values, track_values)


def checked_measure(gating: Gating, gt_values: FloatArray, track_values: FloatArray) -> FloatArray:
    """:func:`measure_matrix` of values already checked (``(N, 4)`` boxes or ``(N, 2)``
    positions, float64, finite, box sizes >= 0): the same numbers, fewer checks."""
    if gating is Gating.IOU:
        return box_iou(gt_values, track_values)
    diff = gt_values[:, None, :] - track_values[None, :, :]
    return np.asarray(np.hypot(diff[..., 0], diff[..., 1]), dtype=np.float64)


def similarity_from_measure(gating: Gating, measure: FloatArray, threshold: float) -> FloatArray:
    """TrackEval's similarity in [0, 1]: IoU, or ``max(0, 1 - d / (2 threshold))``.

    The distance form is TrackEval's Euclidean similarity with its zero distance set
    to twice the gate, so that similarity 0.5 is exactly the gate distance (TrackEval's
    default zero distance of 2 m for the default 1 m gate). HOTA and the
    ``motchallenge`` matching use this similarity.
    """
    if gating is Gating.IOU:
        return measure
    return np.maximum(0.0, 1.0 - measure / (2.0 * threshold))


def similarity_threshold(gating: Gating, threshold: float) -> float:
    """The similarity a ``motchallenge`` match needs: the IoU threshold, or 0.5 for distances."""
    return threshold if gating is Gating.IOU else 0.5


def gate(
    gating: Gating,
    measure: FloatArray,
    similarity: FloatArray,
    threshold: float,
    exact_trackeval: bool,
) -> NDArray[np.bool_]:
    """Which pairs may match: TrackEval's ``similarity >= t - eps``, or motmetrics' plain test."""
    if exact_trackeval:
        out: NDArray[np.bool_] = similarity >= similarity_threshold(gating, threshold) - EPS
        return out
    if gating is Gating.IOU:
        return measure >= threshold
    return measure <= threshold
