"""satake2009's colour test of false detections (ours; seed 002, 2.2 gives none)."""

from __future__ import annotations

import numpy as np
import pytest

from rgbd_eval.methods.satake2009 import colour as colour
from rgbd_eval.methods.satake2009.templates import Match

# A 40 x 80 px head-to-hip box at 3 m on a 100 x 100 image, head top at row 10:
# head rows 10..30 (top quarter of 80 rows), torso rows 46..90 (its lower 55 %).
M = Match(u=50.0, v=10.0, distance=3.0, score=0.9, orientation_deg=0.0, box=(30, 10, 40, 80))
SKIN, SHIRT, PLASTIC = (200, 160, 130), (40, 90, 150), (200, 180, 160)


def _scene(head: tuple[int, int, int], torso: tuple[int, int, int], head_depth: float = 3.0):
    """Body pixels at 3 m in columns 40..60 (head) and 35..65 (torso); wall at 8 m elsewhere."""
    depth = np.full((100, 100), 8.0, np.float32)
    rgb = np.full((100, 100, 3), 128, np.uint8)
    depth[10:30, 40:60], rgb[10:30, 40:60] = head_depth, head
    depth[30:90, 35:65], rgb[30:90, 35:65] = 3.0, torso
    return rgb, depth


def test_a_person_has_a_head_that_differs_from_the_torso() -> None:
    # skin (200,160,130) is (a*, b*) = (10.5, 21.2) in CIELAB, the blue shirt (40,90,150)
    # (4.7, -37.9): hypot(5.8, 59.1) = 59.4 apart, far above 6.
    rgb, depth = _scene(SKIN, SHIRT)
    c = colour.head_torso_chroma(rgb, depth, M, 3.0, 0.3)
    assert c == pytest.approx(59.4, abs=0.2)
    assert colour.passes(rgb, depth, M, 3.0, 0.3, 6.0)


def test_a_one_colour_mannequin_is_rejected_even_where_shading_differs() -> None:
    # The same plastic (200,180,160) = (a*, b*) (3.9, 12.8), the head 30 % darker by shading,
    # (140,126,112) = (2.8, 9.8): hypot(1.1, 3.0) = 3.2 apart, under 6 (L* 74 vs 54 is ignored).
    rgb, depth = _scene((140, 126, 112), PLASTIC)
    c = colour.head_torso_chroma(rgb, depth, M, 3.0, 0.3)
    assert c == pytest.approx(3.2, abs=0.2)
    assert not colour.passes(rgb, depth, M, 3.0, 0.3, 6.0)


def test_no_head_where_the_template_has_one_is_rejected() -> None:
    # The head rows hold only the 8 m wall (the object's top is lower): not a person.
    rgb, depth = _scene(SKIN, SHIRT, head_depth=8.0)
    assert colour.head_torso_chroma(rgb, depth, M, 3.0, 0.3) is None
    assert not colour.passes(rgb, depth, M, 3.0, 0.3, 6.0)


def test_a_grey_image_keeps_every_match() -> None:
    rgb, depth = _scene(PLASTIC, PLASTIC)
    grey = rgb[:, :, 0].copy()
    assert colour.passes(grey, depth, M, 3.0, 0.3, 6.0)


@pytest.mark.parametrize("chroma", [0.0, 6.0])
def test_threshold_zero_keeps_a_mannequin(chroma: float) -> None:
    rgb, depth = _scene(PLASTIC, PLASTIC)
    assert colour.passes(rgb, depth, M, 3.0, 0.3, chroma) is (chroma == 0.0)
