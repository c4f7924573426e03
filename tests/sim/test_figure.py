"""The articulated figure: height, floor contact, placement, gait."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rgbd_eval.sim.figure import (
    HIP_SWING_DEG,
    SHANK,
    THIGH,
    Outfit,
    Posture,
    figure_mesh,
    leg_angles,
)

OUTFIT = Outfit((10, 20, 30), (40, 50, 60), (200, 150, 120), (30, 20, 10), (5, 5, 5))


def test_standing_figure_is_exactly_its_height_and_stands_on_the_floor() -> None:
    mesh, top = figure_mesh(1.8, 2.0, -1.0, 0.0, Posture(), OUTFIT, 7)
    z = mesh.vertices[:, 2]
    assert top == pytest.approx(1.8)  # hair top at H
    assert z.max() == pytest.approx(1.8)
    assert z.min() == pytest.approx(0.0, abs=1e-9)  # soles on the floor
    assert set(np.unique(mesh.object_ids)) == {7}
    # centred on its ground position (feet between x 1.8..2.3, shoulders symmetric in y)
    assert np.mean(mesh.vertices[:, 1]) == pytest.approx(-1.0, abs=0.02)
    assert np.all(np.abs(mesh.vertices[:, 0] - 2.0) < 0.3)


def test_heading_rotates_the_figure() -> None:
    ahead, _ = figure_mesh(1.75, 0.0, 0.0, 0.0, Posture(), OUTFIT, 1)
    left, _ = figure_mesh(1.75, 0.0, 0.0, math.pi / 2, Posture(), OUTFIT, 1)
    # rotating by +90 deg maps (x, y) to (-y, x)
    assert np.allclose(left.vertices[:, 0], -ahead.vertices[:, 1])
    assert np.allclose(left.vertices[:, 1], ahead.vertices[:, 0])


@settings(max_examples=30, deadline=None)
@given(st.floats(0.0, 2 * math.pi), st.floats(0.0, 1.0), st.floats(1.5, 1.95))
def test_walking_keeps_one_foot_on_the_floor(phase: float, amplitude: float, height: float) -> None:
    mesh, top = figure_mesh(height, 0.0, 0.0, 0.0, Posture(phase, amplitude), OUTFIT, 1)
    assert mesh.vertices[:, 2].min() == pytest.approx(0.0, abs=1e-9)
    # The gait lowers the head by at most what a straight leg (thigh + shank = 0.491 H)
    # loses at the peak hip flexion of 24 deg: 0.491 H (1 - cos 24 deg) = 0.0425 H,
    # 7.4 cm at 1.75 m (hypothesis found 6.0 cm at phase 1.625, beyond an earlier 6 cm bound).
    bob = (THIGH + SHANK) * height * (1.0 - math.cos(math.radians(HIP_SWING_DEG)))
    assert height - bob - 1e-9 <= top <= height + 1e-9


def test_legs_swing_in_antiphase_and_sitting_bends_them() -> None:
    (lh, _), (rh, _) = leg_angles(Posture(math.pi / 2, 1.0))
    assert lh == pytest.approx(math.radians(24.0))
    assert rh == pytest.approx(-math.radians(24.0))
    seated, top = figure_mesh(1.75, 0.0, 0.0, 0.0, Posture(sit=1.0), OUTFIT, 1)
    assert top < 1.75 - 0.35  # a seated person is much lower
    assert seated.vertices[:, 2].min() == pytest.approx(0.0, abs=1e-9)


def test_bag_widens_the_figure() -> None:
    plain, _ = figure_mesh(1.75, 0.0, 0.0, 0.0, Posture(), OUTFIT, 1)
    bag_outfit = Outfit(
        OUTFIT.shirt, OUTFIT.trousers, OUTFIT.skin, OUTFIT.hair, OUTFIT.shoes, (1, 1, 1)
    )
    bag, _ = figure_mesh(1.75, 0.0, 0.0, 0.0, Posture(), bag_outfit, 1)
    assert bag.vertices[:, 1].min() < plain.vertices[:, 1].min() - 0.01


def test_bad_arguments() -> None:
    with pytest.raises(ValueError, match=r"height=3\.0"):
        figure_mesh(3.0, 0, 0, 0, Posture(), OUTFIT, 1)
    with pytest.raises(ValueError, match="amplitude"):
        figure_mesh(1.7, 0, 0, 0, Posture(amplitude=2.0), OUTFIT, 1)
