"""IoU and ground-plane distance matrices, and their gates."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from rgbd_eval.config import Gating
from rgbd_eval.metrics.gating import (
    distance_matrix,
    ground_distance_matrix,
    iou_distance_matrix,
    iou_matrix,
    metric_distance_matrix,
    similarity,
)


def test_iou_hand_computed() -> None:
    gt = [(0, 0, 10, 10)]
    tracks = [
        (0, 0, 10, 10),  # identical: 100 / 100 = 1
        (5, 0, 10, 10),  # overlap 5x10 = 50; union 100 + 100 - 50 = 150 -> 1/3
        (5, 5, 10, 10),  # overlap 5x5 = 25; union 175 -> 1/7
        (10, 0, 10, 10),  # touching edge: overlap 0 -> 0
        (2, 2, 4, 4),  # inside: 16 / 100
    ]
    np.testing.assert_allclose(iou_matrix(gt, tracks), [[1.0, 1 / 3, 1 / 7, 0.0, 0.16]])


def test_iou_gate_is_inclusive_at_threshold() -> None:
    # areas 300 each; shifted down by 10: overlap 10x20 = 200, union 300 + 300 - 200 = 400
    # -> IoU exactly 0.5: matchable at 0.5, distance 0.5
    gt = [(0, 0, 10, 30)]
    tracks = [(0, 10, 10, 30), (0, 11, 10, 30)]  # second: 190 / 410 < 0.5 -> NaN
    d = iou_distance_matrix(gt, tracks, 0.5)
    assert d[0, 0] == 0.5
    assert math.isnan(d[0, 1])


def test_zero_area_boxes_have_iou_zero() -> None:
    assert iou_matrix([(3, 3, 0, 0)], [(3, 3, 0, 0)])[0, 0] == 0.0


def test_metric_gate_hand_computed() -> None:
    # distances: (3, 4) -> 5 m; (0.6, 0.8) -> 1 m, exactly at the 1 m gate (inclusive)
    d = metric_distance_matrix([(0.0, 0.0)], [(3.0, 4.0), (0.6, 0.8)], 1.0)
    assert math.isnan(d[0, 0])
    assert d[0, 1] == pytest.approx(1.0)
    np.testing.assert_allclose(ground_distance_matrix([(0, 0), (3, 0)], [(3, 4)]), [[5.0], [4.0]])


def test_empty_inputs_give_empty_matrices() -> None:
    assert iou_matrix(np.zeros((0, 4)), [(0, 0, 1, 1)]).shape == (0, 1)
    assert iou_distance_matrix([(0, 0, 1, 1)], []).shape == (1, 0)
    assert metric_distance_matrix([], []).shape == (0, 0)


def test_dispatch_and_similarity() -> None:
    boxes = [(0, 0, 10, 10)]
    np.testing.assert_array_equal(
        distance_matrix(Gating.IOU, boxes, boxes, 0.5), iou_distance_matrix(boxes, boxes)
    )
    assert similarity(Gating.IOU, 0.25) == 0.75  # IoU = 1 - distance
    assert similarity(Gating.METRIC, 0.25) == 0.25  # metres


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: iou_matrix([(0, 0, 1)], [(0, 0, 1, 1)]), "gt_boxes must have shape"),
        (lambda: iou_matrix([(0, 0, -1, 1)], [(0, 0, 1, 1)]), "width and height"),
        (lambda: iou_matrix([(0, 0, 1, 1)], [(0, np.nan, 1, 1)]), "track_boxes contains"),
        (lambda: iou_distance_matrix([], [], 1.5), "threshold=1.5"),
        (lambda: iou_distance_matrix([], [], 0.0), "threshold=0.0"),
        (lambda: metric_distance_matrix([], [], -1.0), "threshold=-1.0"),
        (lambda: ground_distance_matrix([(0, 0, 0)], [(0, 0)]), "gt_xy must have shape"),
    ],
)
def test_bad_input_raises_value_error(call: object, message: str) -> None:
    with pytest.raises(ValueError, match=message.replace("(", r"\(")):
        call()  # type: ignore[operator]


coordinate = st.integers(-50, 50)
extent = st.integers(0, 40)
box = st.tuples(coordinate, coordinate, extent, extent)


def _naive_iou(a: tuple[int, ...], b: tuple[int, ...]) -> float:
    w = max(0, min(a[0] + a[2], b[0] + b[2]) - max(a[0], b[0]))
    h = max(0, min(a[1] + a[3], b[1] + b[3]) - max(a[1], b[1]))
    union = a[2] * a[3] + b[2] * b[3] - w * h
    return w * h / union if union > 0 else 0.0


@given(st.lists(box, max_size=5), st.lists(box, max_size=5))
def test_iou_matches_naive_formula_and_is_symmetric(
    gts: list[tuple[int, ...]], tracks: list[tuple[int, ...]]
) -> None:
    iou = iou_matrix(np.array(gts).reshape(-1, 4), np.array(tracks).reshape(-1, 4))
    expected = [[_naive_iou(g, t) for t in tracks] for g in gts]
    np.testing.assert_allclose(
        iou.reshape(len(gts), len(tracks)), np.array(expected).reshape(len(gts), len(tracks))
    )
    assert ((iou >= 0) & (iou <= 1)).all()
    np.testing.assert_allclose(
        iou_matrix(np.array(tracks).reshape(-1, 4), np.array(gts).reshape(-1, 4)), iou.T
    )


@given(box.filter(lambda b: b[2] * b[3] > 0))
def test_a_box_overlaps_itself_fully(b: tuple[int, ...]) -> None:
    assert iou_matrix([b], [b])[0, 0] == 1.0
