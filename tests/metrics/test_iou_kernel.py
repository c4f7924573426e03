"""The compiled per-sequence IoU equals box_iou frame by frame, to the last bit."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rgbd_eval.metrics.gating import box_iou
from rgbd_eval.metrics.iou_kernel import sequence_box_iou

# Coordinates from a small grid (so that edges often coincide, boxes touch, nest or have no
# size) and signed zeros, beside arbitrary finite values.
_COORD = st.one_of(
    st.sampled_from([0.0, -0.0, 1.0, 2.5, 3.0, 10.0]),
    st.floats(-1e4, 1e4, allow_nan=False, allow_infinity=False),
)
_SIZE = st.one_of(
    st.sampled_from([0.0, -0.0, 1e-9, 1.0, 2.5]),
    st.floats(0.0, 1e4, allow_nan=False, allow_infinity=False),
)
_BOX = st.tuples(_COORD, _COORD, _SIZE, _SIZE)
_FRAME = st.tuples(st.lists(_BOX, max_size=5), st.lists(_BOX, max_size=5))


def _bits(a: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=np.float64).view(np.uint64)


def _stack(frames: list[list[tuple[float, float, float, float]]]) -> np.ndarray:
    rows = [box for frame in frames for box in frame]
    return np.array(rows, dtype=np.float64).reshape(len(rows), 4)


@settings(max_examples=300, deadline=None)
@given(st.lists(_FRAME, max_size=6))
def test_each_frame_is_box_iou_bit_for_bit(frames: list[tuple[list, list]]) -> None:
    a_frames = [a for a, _ in frames]
    b_frames = [b for _, b in frames]
    got = sequence_box_iou(
        _stack(a_frames), [len(a) for a in a_frames], _stack(b_frames), [len(b) for b in b_frames]
    )
    assert len(got) == len(frames)
    for matrix, a, b in zip(got, a_frames, b_frames, strict=True):
        want = box_iou(
            np.array(a, dtype=np.float64).reshape(len(a), 4),
            np.array(b, dtype=np.float64).reshape(len(b), 4),
        )
        assert matrix.shape == want.shape
        assert np.array_equal(_bits(matrix), _bits(want))


def test_hand_computed_frames() -> None:
    # frame 0: a = (0, 0, 2, 2) against b = (1, 1, 2, 2): overlap 1 x 1 = 1, union 4 + 4 - 1 = 7
    #          and against (0, 0, 2, 2) itself: 4 / 4 = 1
    # frame 1: no ground truth, one track: a 0 x 1 matrix
    # frame 2: a box of no size has IoU 0 with everything, even with itself
    a = np.array([[0, 0, 2, 2], [5, 5, 0, 3]], dtype=np.float64)
    b = np.array([[1, 1, 2, 2], [0, 0, 2, 2], [9, 9, 1, 1], [5, 5, 0, 3]], dtype=np.float64)
    f0, f1, f2 = sequence_box_iou(a, [1, 0, 1], b, [2, 1, 1])
    assert f0.tolist() == [[1 / 7, 1.0]]
    assert f1.shape == (0, 1)
    assert f2.tolist() == [[0.0]]


def test_counts_that_do_not_add_up_are_refused() -> None:
    boxes = np.zeros((2, 4))
    with pytest.raises(ValueError, match="add up"):
        sequence_box_iou(boxes, [1], boxes, [2])
    with pytest.raises(ValueError, match="equally long"):
        sequence_box_iou(boxes, [1, 1], boxes, [2])
