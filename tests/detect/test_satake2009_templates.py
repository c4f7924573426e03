"""satake2009 distance templates (seed 002, 2.2): shipped data, scaling by distance, matching."""

from __future__ import annotations

import numpy as np
import pytest

from rgbd_eval.methods.satake2009 import templates as st

from .satake_scenes import H, W, person_depth


def _scene_depth(x: float, y: float, turned_deg: float, wall_m: float = 6.0) -> np.ndarray:
    """Depth of the test person (1.75 m) at (x, y) in front of a wall, camera 1.2 m up."""
    return np.fmin(person_depth(x, y, turned_deg), wall_m).astype(np.float32)


def test_shipped_templates_are_what_the_script_makes() -> None:
    shipped, fresh = st.load_templates(), st.build_templates()
    assert [t.orientation_deg for t in shipped] == [0.0, 45.0, 90.0]
    for a, b in zip(shipped, fresh, strict=True):
        assert np.array_equal(a.mask, b.mask)
        np.testing.assert_allclose(a.depth, b.depth, atol=1e-6)
        assert a.anchor == b.anchor


def test_a_person_at_4_m_is_half_the_size_of_one_at_2_m() -> None:
    t = st.load_templates()[0]  # 86 x 102 px at 2 m and F_REF
    h, w = t.mask.shape
    at2 = st.scale_template(t, 2.0, st.F_REF)
    at4 = st.scale_template(t, 4.0, st.F_REF)
    assert at2.mask.shape == (h, w)
    # scale (F_REF / F_REF) * (2 / 4) = 0.5: 86 x 102 -> 43 x 51
    assert at4.mask.shape == (round(h / 2), round(w / 2))
    assert at4.anchor == pytest.approx((t.anchor[0] / 2, t.anchor[1] / 2), abs=0.5)
    # depth values move with the distance: the template's median body depth is D
    assert np.nanmedian(at2.depth) == pytest.approx(2.0, abs=0.01)
    assert np.nanmedian(at4.depth) == pytest.approx(4.0, abs=0.01)
    # a camera with twice the focal length sees the 4 m person as large as F_REF sees it at 2 m
    assert st.scale_template(t, 4.0, 2 * st.F_REF).mask.shape == (h, w)
    with pytest.raises(ValueError, match="distance=0"):
        st.scale_template(t, 0.0, st.F_REF)


@pytest.mark.parametrize("turned", [0.0, 30.0, 80.0])
def test_matching_finds_the_person_at_their_distance(turned: float) -> None:
    # A person 3 m ahead and 0.5 m to the left: the head top (1.75 m, camera at 1.2 m)
    # projects to u = cx - F_REF * 0.5 / 3 = 255.5 - 35.8 = 219.7,
    # v = cy - F_REF * 0.55 / 3 = 191.5 - 39.4 = 152.1 (the nearest head surface is a bit
    # nearer than 3 m, so v is a pixel or two higher).
    depth = _scene_depth(3.0, 0.5, turned)
    templates = st.load_templates()
    matches = [st.best_match(depth, templates, d, st.F_REF, 0.3, 0.5) for d in (2.0, 3.0, 4.5)]
    best = max((m for m in matches if m is not None), key=lambda m: m.score)
    assert best.distance == 3.0
    # the template of the nearest orientation wins (measured: 0 -> 0, 30 -> 45, 80 -> 90)
    assert best.orientation_deg == min(st.ORIENTATIONS, key=lambda o: abs(o - turned))
    assert best.score > 0.85
    assert best.u == pytest.approx(219.7, abs=4)
    assert best.v == pytest.approx(152.1, abs=5)


def test_a_bare_wall_is_not_a_person() -> None:
    # A wall 3 m away fills every template box: no free outline, the body share alone
    # (about 0.4 of the box for the frontal template) is all that agrees.
    wall = np.full((H, W), 3.0, dtype=np.float32)
    best = st.best_match(wall, st.load_templates(), 3.0, st.F_REF, 0.3, 0.5)
    assert best is not None and best.score < 0.7


def test_agreement_without_nan_is_the_same_agreement() -> None:
    # 1 x 6 depths at D = 2 (band 0.3, gap 0.5): 1.6 is nearer than the band (neither),
    # 1.8 and 2.3 are on the body (near; the band is inclusive), 2.4 is behind but within
    # the gap (neither), 2.6 is free (> 2.5), and no depth (NaN; +inf once filled) is free.
    depth = np.array([[1.6, 1.8, 2.3, 2.4, 2.6, np.nan]], np.float32)
    near, free = st.agreement_u8(depth, 2.0, 0.3, 0.5)
    assert near.tolist() == [[0, 255, 255, 0, 0, 0]]
    assert free.tolist() == [[0, 0, 0, 0, 255, 255]]
    filled = st.no_depth_far(depth)
    assert np.isposinf(filled[0, 5]) and not np.isnan(filled).any()
    near_f, free_f = st.agreement_u8_far(filled, 2.0, 0.3, 0.5)
    np.testing.assert_array_equal(near_f, near)
    np.testing.assert_array_equal(free_f, free)


@pytest.mark.parametrize("shape", [(30, 40), (96, 128), (192, 256)])
def test_scores_through_a_shared_spectrum_are_the_direct_scores(shape: tuple[int, int]) -> None:
    # Random agreement maps, the three templates at 3 m on a quarter-size focal length:
    # score_all (one DFT of the map, above DFT_MIN_PIXELS) equals matchTemplate + box
    # filter placement for placement, up to float rounding; a template larger than the
    # map scores None.
    rng = np.random.default_rng(3)
    near = (rng.random(shape) < 0.4).astype(np.uint8) * 255
    free = ((rng.random(shape) < 0.5) & (near == 0)).astype(np.uint8) * 255
    maps = st.Agreement.of(near, free, 255.0)
    templates = [st.scale_template(t, 3.0, st.F_REF / 4) for t in st.load_templates()]
    huge = st.scale_template(st.load_templates()[0], 0.2, st.F_REF)
    got = maps.score_all([*templates, huge])
    assert got[-1] is None
    for t, scores in zip(templates, got[:-1], strict=True):
        assert scores is not None
        direct = maps.score(t)
        assert scores.shape == direct.shape
        np.testing.assert_allclose(scores, direct, atol=1e-5)
