"""The occlusion classifier: pairwise features, order, depth order (seed 004, section 5)."""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path

import numpy as np
import pytest

from rgbd_eval.errors import ConfigError
from rgbd_eval.methods.cielniak2010.occlusion import (
    FEATURE_NAMES,
    GROUPS,
    OcclusionClassifier,
    OcclusionScene,
    depth_order,
    in_front,
    load_classifiers,
    merge_sort_by,
    order,
    overlap,
    pair_features,
    scene_for,
    shipped_classifier,
    sort_front_to_back,
)
from rgbd_eval.track.adaboost import BoostedStumps, Stump

RED, GREEN, BLUE = (200, 0, 0), (0, 200, 0), (0, 0, 200)


def _paint(
    boxes_back_to_front: list[tuple[int, int, int, int]],
    temps: list[float],
    colours: list[tuple[int, int, int]],
) -> OcclusionScene:
    """A 100x100 thermal (20 C) and colour (grey) scene, persons painted back to front."""
    t = np.full((100, 100), 20.0)
    c = np.full((100, 100, 3), 100, dtype=np.uint8)
    for (u0, v0, u1, v1), temp, col in zip(boxes_back_to_front, temps, colours, strict=True):
        t[v0:v1, u0:u1] = temp
        c[v0:v1, u0:u1] = col
    return OcclusionScene.of(t, c)


def _one_stump(feature: str) -> OcclusionClassifier:
    """'a in front' when ``feature`` is positive (one stump at threshold 0)."""
    stump = Stump(FEATURE_NAMES.index(feature), 0.0, 1, 1.0)
    return OcclusionClassifier(BoostedStumps(FEATURE_NAMES, (stump,)))


# back person b (28 C, red) at (40, 20, 60, 80); front person a (32 C, blue) at (50, 30, 74, 90)
B = (40.0, 20.0, 60.0, 80.0)
A = (50.0, 30.0, 74.0, 90.0)


def _hand_scene() -> OcclusionScene:
    return _paint([(40, 20, 60, 80), (50, 30, 74, 90)], [28.0, 32.0], [RED, BLUE])


def test_pair_features_by_hand() -> None:
    f = dict(zip(FEATURE_NAMES, pair_features(A, B, _hand_scene()), strict=True))
    # heights 60 and 60: mean 60
    assert f["bottom"] == pytest.approx((90 - 80) / 60)
    assert f["top"] == pytest.approx((30 - 20) / 60)
    assert f["log_height"] == pytest.approx(0.0)
    # overlap (50, 30, 60, 80): 500 px; |b| = 1200, |a| = 1440
    assert f["visible"] == pytest.approx(500 / 1200 - 500 / 1440)
    # rows 30..80; a's own strip (60..74) is 32 C like the overlap, b's (40..50) 28 C
    assert f["overlap_temp_mean"] == pytest.approx(abs(32 - 28) - 0.0)
    assert f["overlap_temp_std"] == pytest.approx(0.0)
    # a's side u=50 lies inside b: band 50 +- 1.44 -> columns 49, 50; central differences
    # (32 - 28) / 2 = 2 at both. b's side u=60 inside a: columns 59, 60, all 32 C: 0.
    assert f["edge_thermal"] == pytest.approx(2.0)
    # colour: overlap blue, a's strip blue, b's strip red: |(0,0,200) - (200,0,0)| = 400
    assert f["overlap_colour_mean"] == pytest.approx(400.0)
    assert f["overlap_colour_std"] == pytest.approx(0.0)
    assert f["overlap_colour_skew"] == pytest.approx(0.0)
    # luminance red 0.299*200 = 59.8, blue 0.114*200 = 22.8: |22.8 - 59.8| / 2 = 18.5
    assert f["edge_colour"] == pytest.approx(18.5)


def test_features_are_antisymmetric() -> None:
    scene = _hand_scene()
    np.testing.assert_allclose(pair_features(B, A, scene), -pair_features(A, B, scene), atol=1e-9)


def test_disjoint_boxes_have_only_geometry() -> None:
    f = pair_features((0.0, 0.0, 10.0, 50.0), (20.0, 10.0, 30.0, 40.0), _hand_scene())
    # heights 50 and 30: mean 40; bottom (50 - 40) / 40, top (0 - 10) / 40, ln(50/30)
    np.testing.assert_allclose(f[:3], [0.25, -0.25, math.log(50 / 30)])
    assert not f[3:].any()


def test_order_on_hand_made_pairs() -> None:
    scene = _hand_scene()
    colour = _one_stump("overlap_colour_mean")
    thermal = _one_stump("edge_thermal")
    # margin H(f) - H(-f) = 1 - (-1) = 2 > 0: a in front; never both ways
    for clf in (colour, thermal):
        assert in_front(A, B, scene, clf)
        assert not in_front(B, A, scene, clf)
    # the same boxes with the painting order swapped: now b shows in the overlap
    swapped = _paint([(50, 30, 74, 90), (40, 20, 60, 80)], [32.0, 28.0], [BLUE, RED])
    assert in_front(B, A, swapped, colour)
    assert not in_front(A, B, swapped, colour)


def test_without_colour_the_colour_votes_cancel() -> None:
    t = np.full((100, 100), 20.0)
    scene = OcclusionScene.of(t)  # no colour image: colour features are 0
    clf = _one_stump("overlap_colour_mean")
    # margin H(0) - H(-0) = 0: the tie goes to the lower bottom (a: 90 > b: 80), both ways
    assert in_front(A, B, scene, clf)
    assert not in_front(B, A, scene, clf)


def test_sort_is_m_log_m_and_correct() -> None:
    rng = np.random.default_rng(0)
    for m in range(1, 12):
        depth = rng.permutation(m)
        calls = 0

        def in_front(i: int, j: int, depth: np.ndarray = depth) -> bool:
            nonlocal calls
            calls += 1
            return bool(depth[i] < depth[j])

        assert merge_sort_by(m, in_front) == list(np.argsort(depth))
        # merge sort: at most m * ceil(log2 m) comparisons (seed 004: M_O log M_O)
        assert calls <= m * math.ceil(math.log2(m)) if m > 1 else calls == 0


def test_depth_order_of_three_painted_persons() -> None:
    # painted back to front: p0 red, p1 green over it, p2 blue over p1 (p0 and p2 do not touch;
    # their tie goes to p2, further right, which agrees)
    boxes = [(10, 10, 40, 90), (30, 10, 60, 90), (50, 10, 80, 90)]
    scene = _paint(boxes, [28.0, 29.0, 30.0], [RED, GREEN, BLUE])
    clf = _one_stump("overlap_colour_mean")
    fboxes = [tuple(float(v) for v in b) for b in boxes]
    for perm in itertools.permutations(range(3)):
        given = [fboxes[k] for k in perm]
        front_to_back = [perm[i] for i in depth_order(given, scene, clf)]  # type: ignore[arg-type]
        assert front_to_back == [2, 1, 0]


def test_shipped_model_has_every_group() -> None:
    models = load_classifiers()
    assert set(models) == set(GROUPS)
    for group, clf in models.items():
        used = {FEATURE_NAMES[s.feature] for s in clf.model.stumps}
        assert used, group
        assert used <= {FEATURE_NAMES[i] for i in GROUPS[group]}, group


def test_bad_input_is_refused(tmp_path: Path) -> None:
    scene = _hand_scene()
    with pytest.raises(ValueError, match="u1 > u0"):
        pair_features((10.0, 10.0, 5.0, 20.0), B, scene)
    with pytest.raises(ValueError, match="HxW"):
        OcclusionScene.of(np.zeros((4, 4, 3)))
    bad = tmp_path / "model.json"
    bad.write_text(json.dumps({"models": {"both": {"feature_names": ["x"], "stumps": []}}}))
    with pytest.raises(ConfigError, match="not an occlusion classifier"):
        load_classifiers(bad)
    with pytest.raises(ConfigError, match="cannot read"):
        load_classifiers(tmp_path / "missing.json")


def test_tracker_interface() -> None:
    # order(a, b, thermal, colour) -> 0 when a is in front, 1 when b is (track/cielniak2010.py)
    thermal = np.full((100, 100), 20.0)
    thermal[20:80, 40:60] = 28.0
    thermal[30:90, 50:74] = 32.0
    colour = np.full((100, 100, 3), 100, dtype=np.uint8)
    colour[20:80, 40:60] = RED
    colour[30:90, 50:74] = BLUE
    clf = _one_stump("overlap_colour_mean")
    a, b = np.array(A), np.array(B)
    assert order(a, b, thermal, colour, classifier=clf) == 0
    assert order(b, a, thermal, colour, classifier=clf) == 1
    assert sort_front_to_back([b, a], thermal, colour, classifier=clf) == [1, 0]
    # the scene is built once per frame: same image objects, same scene
    assert scene_for(thermal, colour) is scene_for(thermal, colour)
    assert scene_for(thermal.copy(), colour) is not scene_for(thermal, colour)
    # intersection 10 x 50 = 500 over the smaller box, b: 20 x 60 = 1200
    assert overlap(a, b) == pytest.approx(500 / 1200)
    assert overlap(a, (0.0, 0.0, 10.0, 10.0)) == 0.0


def test_shipped_classifier_puts_lower_feet_in_front_on_a_blank_image() -> None:
    # no appearance (a uniform image): only the geometry speaks; the near person's box is
    # taller and its feet lower (v = 200 against 150)
    near = np.array([100.0, 40.0, 140.0, 200.0])
    far = np.array([120.0, 60.0, 150.0, 150.0])
    thermal = np.zeros((240, 320))
    assert order(near, far, thermal) == 0 and order(far, near, thermal) == 1
    assert in_front(tuple(near), tuple(far), scene_for(thermal), shipped_classifier("thermal"))
