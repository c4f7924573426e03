"""Threshold calibration of pinto2022's appearance gates, by hand on tiny distributions."""

from __future__ import annotations

import numpy as np
import pytest

from rgbd_eval.methods.pinto2022.reid_calibration import (
    calibrate,
    equal_error_threshold,
    pair_distances,
    roc_auc,
)


def test_pair_distances_split_same_and_different() -> None:
    emb = np.array([[0.0, 0.0], [3.0, 4.0], [0.0, 1.0], [6.0, 8.0]])
    ids = np.array([1, 1, 2, 1])
    frames = np.array([0, 20, 0, 5])
    same, diff = pair_distances(emb, ids, frames, min_frame_gap=15)
    # same person, >= 15 frames apart: (0, 1) -> 5 and (1, 3) -> 5; (0, 3) is only 5 frames apart
    np.testing.assert_allclose(np.sort(same), [5.0, 5.0])
    # different: (0, 2) -> 1, (1, 2) -> sqrt(9 + 9), (2, 3) -> sqrt(36 + 49)
    np.testing.assert_allclose(np.sort(diff), np.sort([1.0, np.sqrt(18.0), np.sqrt(85.0)]))


def test_equal_error_threshold() -> None:
    # t = 4: P(same >= 4) = 1/4 = P(different < 4) = 1/4 exactly
    assert equal_error_threshold(np.array([1.0, 2, 3, 4]), np.array([3.5, 5, 6, 7])) == 4.0
    # t = 2.5: miss 1/3, false accept 0 (gap 1/3); t = 3: miss 1/3, false accept 1/2 (gap -1/6);
    # linear in between: 2.5 + 0.5 * (1/3) / (1/3 + 1/6) = 2.8333
    t = equal_error_threshold(np.array([1.0, 2, 3]), np.array([2.5, 4]))
    assert t == pytest.approx(2.5 + 0.5 * (1 / 3) / 0.5)


def test_roc_auc() -> None:
    # pairs (same < different): (1, 1.5), (1, 3), (2, 3) of 4 -> 0.75
    assert roc_auc(np.array([1.0, 2.0]), np.array([1.5, 3.0])) == pytest.approx(0.75)
    assert roc_auc(np.array([1.0]), np.array([1.0])) == pytest.approx(0.5)  # a tie counts half


def test_calibrate_overlapping_and_separated() -> None:
    th = calibrate(np.array([1.0, 2, 3, 4]), np.array([3.5, 5, 6, 7]))
    # T_recover: recovered when d < t; wrong decisions (same >= t + different < t) per cut:
    #   t=1: 4  t=2: 3  t=3: 2  t=3.5: 1+0=1  t=4: 1+1=2  t=5: 0+1=1  t=6: 2  t=7: 3  t=8: 4
    # best 1 on (3, 3.5] and (4, 5]: the wider, middle 4.5 (the equal-error rule gave 4.0).
    # T_lower: 1 % of different = 3.5 + 0.03 * 1.5 = 3.545; T_upper: 99 % of same = 3.97,
    # raised to T_recover (the ordering T_lower <= T_recover <= T_upper)
    assert (th.t_lower, th.t_upper, th.t_recover) == pytest.approx((3.545, 4.5, 4.5))
    sep = calibrate(np.array([1.0, 2.0]), np.array([5.0, 6.0]))
    # 1 % of different (5.01) > 99 % of same (1.99): both collapse to T_recover, the middle
    # of (2, 5] where no decision is wrong
    assert sep.t_lower == sep.t_upper == sep.t_recover == 3.5
