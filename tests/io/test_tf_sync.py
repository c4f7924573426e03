"""tf chains and interpolation, and stamp pairing, on hand-made stamps."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from rgbd_eval.io.sync import first_non_increasing, pair_nearest
from rgbd_eval.io.tf import TfBuffer, TransformLookupError, slerp
from rgbd_eval.types import Pose


def yaw(angle: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, float(np.sin(angle / 2)), float(np.cos(angle / 2)))


def test_interpolation_lerp_and_slerp() -> None:
    tf = TfBuffer()
    tf.add("odom", "base", 0, Pose((0.0, 0.0, 0.0), yaw(0.0)))
    tf.add("odom", "base", 100, Pose((1.0, 2.0, 0.0), yaw(np.pi / 2)))
    # A quarter of the way: translation (0.25, 0.5, 0), yaw pi/8 (slerp is linear in angle).
    p = tf.lookup("odom", "base", 25)
    np.testing.assert_allclose(p.translation, (0.25, 0.5, 0.0))
    np.testing.assert_allclose(p.rotation, yaw(np.pi / 8), atol=1e-12)
    with pytest.raises(TransformLookupError, match="no transform at 130"):
        tf.lookup("odom", "base", 130, tolerance_ns=20)
    np.testing.assert_allclose(
        tf.lookup("odom", "base", 110, tolerance_ns=20).translation, (1.0, 2.0, 0.0)
    )


def test_a_stamp_with_a_recorded_transform_gives_it_bit_for_bit() -> None:
    # At a recorded stamp the transform is the recorded one, not slerp(q0, q1, 0): slerp
    # re-normalises q0 and moved yaw 0.1 and 0.3 in their last bit, so a frame built
    # from the odometry directly (synth --follow) and the same frame read back differed.
    for angle in (0.1, 0.3, 0.7):
        recorded = Pose((0.3, 0.1, 0.0), yaw(angle))
        tf = TfBuffer()
        tf.add("odom", "base", 0, recorded)
        tf.add("odom", "base", 100, Pose((1.0, 2.0, 0.0), yaw(angle + 0.2)))
        tf.add("odom", "base", 200, Pose((2.0, 2.0, 0.0), yaw(angle + 0.4)))
        static = TfBuffer()
        static.add("odom", "base", 0, recorded, static=True)
        assert tf.lookup("odom", "base", 0) == static.lookup("odom", "base", 0)
        moved = Pose((1.0, 2.0, 0.0), yaw(angle + 0.2))
        static = TfBuffer()
        static.add("odom", "base", 0, moved, static=True)
        assert tf.lookup("odom", "base", 100) == static.lookup("odom", "base", 0)


def test_chain_composition_and_inverse() -> None:
    tf = TfBuffer()
    tf.add("odom", "base", 0, Pose((1.0, 0.0, 0.0), yaw(np.pi / 2)))
    tf.add("base", "cam", 0, Pose((0.0, 0.0, 1.0)), static=True)
    tf.add("base", "laser", 0, Pose((0.5, 0.0, 0.0)), static=True)
    assert tf.chain("odom", "cam") == ["odom", "base", "cam"]
    # A point at the camera origin: base (0,0,1) -> odom: yaw 90 deg leaves z alone, + (1,0,0).
    np.testing.assert_allclose(
        tf.lookup("odom", "cam", 0).transform_points(np.zeros((1, 3))), [[1.0, 0.0, 1.0]]
    )
    # Sibling frames: laser_T_cam = (base_T_laser)^-1 base_T_cam -> translation (-0.5, 0, 1).
    np.testing.assert_allclose(tf.lookup("laser", "cam", 0).translation, (-0.5, 0.0, 1.0))


def test_broken_chain_and_two_parents() -> None:
    tf = TfBuffer()
    tf.add("odom", "base", 0, Pose())
    tf.add("rig", "cam", 0, Pose(), static=True)
    with pytest.raises(TransformLookupError, match="no tf chain from 'odom' to 'cam'"):
        tf.chain("odom", "cam")
    with pytest.raises(TransformLookupError, match="two parents"):
        tf.add("map", "base", 0, Pose())


@given(st.floats(-3.0, 3.0), st.floats(-3.0, 3.0), st.floats(0.0, 1.0))
def test_slerp_is_unit_and_between(a: float, b: float, t: float) -> None:
    q = slerp(np.array(yaw(a)), np.array(yaw(b)), t)
    assert abs(np.linalg.norm(q) - 1.0) < 1e-9
    # For rotations about one axis, slerp moves along the shorter arc.
    d = (b - a + np.pi) % (2 * np.pi) - np.pi
    expected = Pose(rotation=yaw(a + t * d)).rotation_matrix()
    np.testing.assert_allclose(Pose(rotation=tuple(q)).rotation_matrix(), expected, atol=1e-7)  # type: ignore[arg-type]


def test_pairing_hand_made() -> None:
    rgb = np.array([0, 33, 66, 100, 133])
    depth = np.array([2, 30, 31, 98, 200])
    p = pair_nearest(rgb, depth, max_gap_ns=5)
    # 0-2 (2), 33-31 (2) beats 33-30 (3), 100-98 (2); 66 and 133 have no partner within 5;
    # depth 30 loses to 31, depth 200 is alone.
    assert p.pairs == ((0, 0), (1, 2), (3, 3))
    assert (p.rgb_unpaired, p.depth_unpaired, p.worst_gap_ns) == (2, 2, 2)


@given(
    st.lists(st.integers(0, 10_000), min_size=1, max_size=40, unique=True),
    st.lists(st.integers(0, 10_000), min_size=1, max_size=40, unique=True),
    st.integers(0, 500),
)
def test_pairing_invariants(rgb: list[int], depth: list[int], gap: int) -> None:
    r, d = np.sort(np.array(rgb)), np.sort(np.array(depth))
    p = pair_nearest(r, d, gap)
    used_r = [a for a, _ in p.pairs]
    used_d = [b for _, b in p.pairs]
    assert len(set(used_r)) == len(used_r) and len(set(used_d)) == len(used_d)
    assert all(abs(int(r[a]) - int(d[b])) <= gap for a, b in p.pairs)
    assert p.rgb_unpaired + len(p.pairs) == r.size and p.depth_unpaired + len(p.pairs) == d.size


def test_first_non_increasing() -> None:
    assert first_non_increasing(np.array([1, 2, 3])) is None
    assert first_non_increasing(np.array([1, 3, 3, 4])) == 2
    assert first_non_increasing(np.array([5, 4])) == 1
