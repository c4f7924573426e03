"""Corrupt poses and frames are refused or reported, never used silently."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rgbd_eval.io.tf import TfBuffer, TransformLookupError, pose_problem
from rgbd_eval.io.validate import (
    depth_is_empty,
    empty_depth_warning,
    image_size_problem,
    implausible_depth,
)
from rgbd_eval.types import Pose

S = math.sqrt(0.5)


def test_pose_problems() -> None:
    assert pose_problem(Pose((1.0, 2.0, 3.0), (0.0, 0.0, S, S))) is None
    # Rounded to two decimals: norm sqrt(2 * 0.71^2) = 1.0041, within 0.1 of 1.
    assert pose_problem(Pose((0.0, 0.0, 0.0), (0.0, 0.0, 0.71, 0.71))) is None
    assert "not finite" in str(pose_problem(Pose((math.nan, 0.0, 0.0))))
    assert "not finite" in str(pose_problem(Pose((0.0, 0.0, 0.0), (0.0, 0.0, math.inf, 1.0))))
    assert "norm 0" in str(pose_problem(Pose((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 0.0))))
    # A flipped exponent bit: w = 4.6e77 is finite but no rotation.
    assert "norm 4.6e+77" in str(pose_problem(Pose((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 4.6e77))))


def test_buffer_refuses_a_corrupt_transform_naming_frames_and_stamp() -> None:
    tf = TfBuffer()
    with pytest.raises(
        TransformLookupError, match=r"odom->base_link at stamp 1500000000 ns \(1\.5"
    ):
        tf.add("odom", "base_link", 1_500_000_000, Pose((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 0.0)))
    assert tf.frames == set()


def test_image_and_depth_checks() -> None:
    assert image_size_problem(np.zeros((12, 16, 3), np.uint8)) is None
    assert "1x1, smaller than the 16x12" in str(image_size_problem(np.zeros((1, 1), np.float32)))
    depth = np.full((4, 4), np.nan, np.float32)
    assert depth_is_empty(depth)
    depth[2, 3] = 0.0  # zero is invalid too
    assert depth_is_empty(depth)
    depth[2, 3] = 1.5
    assert not depth_is_empty(depth)


def test_empty_depth_warning_lists_frames() -> None:
    assert empty_depth_warning([], 5) is None
    assert empty_depth_warning([0, 3], 5) == (
        "2 of 5 depth frames hold no valid pixel (all NaN or zero; no detections possible): "
        "frames 0, 3"
    )
    assert str(empty_depth_warning(list(range(12)), 20)).endswith(
        "frames 0, 1, 2, 3, 4, 5, 6, 7, 8, 9 and 2 more"
    )


def test_odometry_faster_than_20_m_s_is_a_jump() -> None:
    def buffer(step_m: float) -> TfBuffer:
        tf = TfBuffer()
        for k in range(5):  # 50 Hz, 0.2 m per message (10 m/s) plus step_m at message 3
            x = 0.2 * k + (step_m if k >= 3 else 0.0)
            tf.add("odom", "base_link", k * 20_000_000, Pose((x, 0.0, 0.0)))
        return tf

    assert buffer(0.0).jump_problem(["odom", "base_link"]) is None
    assert buffer(0.25).jump_problem(["odom", "base_link"]) is None  # 0.45 m in 20 ms: < 0.5
    child, problem = buffer(1000.0).jump_problem(["odom", "base_link"]) or ("", "")
    assert child == "base_link" and "odom->base_link moves 1e+03 m in 20 ms" in problem
    assert "faster than 20 m/s" in problem
    assert "beyond 1e+07 m" in (pose_problem(Pose((0.0, 1e30, 0.0))) or "")


def test_depth_mostly_beyond_20_m_is_implausible() -> None:
    depth = np.full((12, 16), 2.0, dtype=np.float32)
    assert implausible_depth(depth) is None
    depth[:7] = 65.535  # 7 of 12 rows: more than half beyond 20 m
    assert "58% of its valid pixels lie beyond 20 m" in (implausible_depth(depth) or "")
    assert implausible_depth(np.full((12, 16), np.nan, dtype=np.float32)) is None  # empty
