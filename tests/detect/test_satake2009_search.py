"""satake2009's template search around a track's prediction (seed 002, 2.4 step 2.2)."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from rgbd_eval.methods.satake2009 import search as search
from rgbd_eval.methods.satake2009 import templates as st

from .satake_scenes import CAM
from .satake_scenes import scene_depth as _scene

PARAMS = search.MatchParams(band_m=0.3, gap_m=0.5, min_score=0.8)


def test_the_search_finds_the_person_near_the_prediction() -> None:
    # Person 3 m ahead, 0.5 m left: head top at u = 255.5 - 214.8 * 0.5 / 3 = 219.7,
    # v = 191.5 - 214.8 * 0.55 / 3 = 152.1 (1.75 m head, camera at 1.2 m). The prediction
    # is 12 px right and 6 px low, at 3.1 m; the window (20 px) holds the true head.
    templates = st.load_templates()
    depth = _scene((3.0, 0.5))
    m = search.search_around(
        depth, CAM.fx, templates, (231.7, 158.1), [3.1 / 1.08, 3.1, 3.1 * 1.08], 20.0, 40, PARAMS
    )
    assert m is not None and m.score > 0.85
    assert m.u == pytest.approx(219.7, abs=4)
    assert m.v == pytest.approx(152.1, abs=5)
    # The templates' bodies are 1.69 m tall (their median): a 1.75 m person at 3.0 m fills
    # the template scaled for 3.0 * 1.69 / 1.75 = 2.9 m, of 2.87, 3.1 and 3.35 m the nearest
    # is 2.87; the body's median depth then gives the distance
    assert m.distance == pytest.approx(3.1 / 1.08)
    assert search.body_distance(depth, m, 0.3) == pytest.approx(3.0, abs=0.15)


def test_the_window_bounds_the_search() -> None:
    # The same person, predicted 40 px to the right with a 5 px window: no placement
    # within 5 px of the prediction covers the body, so the best of them scores low
    # (the caller rejects it with min_score = 0.8).
    templates = st.load_templates()
    depth = _scene((3.0, 0.5))
    m = search.search_around(depth, CAM.fx, templates, (259.7, 152.1), [3.0], 5.0, 40, PARAMS)
    assert m is not None and m.score < 0.8
    assert abs(m.u - 259.7) <= 5 and abs(m.v - 152.1) <= 5


def test_a_nearer_person_in_front_does_not_take_the_farther_ones_search() -> None:
    # A stands 4.5 m ahead (head top u = 255.5, v = 191.5 - 214.8 * 0.55 / 4.5 = 165.2);
    # B stands 2.5 m ahead, 0.35 m to the left (u = 255.5 - 214.8 * 0.35 / 2.5 = 225.4),
    # covering part of A's left side. Searched at A's distance the template agrees with A
    # (B is neither at 4.5 m nor free behind), and at B's with B: each keeps its person.
    # A's hidden side costs agreement (0.82 measured, against 0.94 unoccluded), but the match
    # stays on A rather than being pulled toward B.
    templates = st.load_templates()
    depth = _scene((4.5, 0.0), (2.5, 0.35))
    a = search.search_around(depth, CAM.fx, templates, (250.0, 170.0), [4.5], 24.0, 40, PARAMS)
    b = search.search_around(depth, CAM.fx, templates, (232.0, 150.0), [2.5], 24.0, 40, PARAMS)
    assert a is not None and b is not None
    assert a.u == pytest.approx(255.5, abs=4) and a.v == pytest.approx(165.2, abs=5)
    assert b.u == pytest.approx(225.4, abs=4)
    assert 0.7 < a.score < 0.85 and b.score > 0.9


def test_whole_image_search_finds_both_and_quantised_distances() -> None:
    # Two people apart, A 4.5 m ahead 0.6 m right (u = 255.5 + 214.8 * 0.6 / 4.5 = 284.1),
    # B 2.5 m ahead 0.6 m left (u = 255.5 - 214.8 * 0.6 / 2.5 = 204.0), searched over the
    # detector's grid (1 m * 1.15^k) where templates are ~16 rows tall: both, nothing else.
    templates = st.load_templates()
    depth = _scene((4.5, -0.6), (2.5, 0.6))
    grid = [1.0 * 1.15**k for k in range(13)]
    found = search.suppress(search.search_whole(depth, CAM.fx, templates, grid, 16, PARAMS), 0.3)
    assert len(found) == 2
    us = sorted(m.u for m in found)
    assert us[0] == pytest.approx(204.0, abs=6) and us[1] == pytest.approx(284.1, abs=6)
    # 1.02^k grid: 3.0 -> 1.02^55 = 2.972, 3.1 -> 1.02^57 = 3.092
    assert search.quantised(3.0) == pytest.approx(1.02**55)
    assert search.quantised(3.1) == pytest.approx(1.02**57)


def test_suppression_keeps_the_best_of_each_overlapping_group() -> None:
    # Boxes (left, top, w, h): a = (0,0,10,10) 0.9; b = (2,0,10,10) 0.8 overlaps a by
    # 8*10 / (100 + 100 - 80) = 0.67 > 0.3: dropped; c = (7,0,10,10) 0.7 overlaps a by
    # 3*10 / 170 = 0.18 and b (dropped, so it does not count) by 0.54: kept; d = (30,0,5,5)
    # 0.95 overlaps nothing: kept first. Equal scores keep their input order.
    def m(box: tuple[int, int, int, int], score: float) -> st.Match:
        return st.Match(box[0] + 5.0, float(box[1]), 3.0, score, 0.0, box)

    a, b, c, d = (
        m((0, 0, 10, 10), 0.9),
        m((2, 0, 10, 10), 0.8),
        m((7, 0, 10, 10), 0.7),
        m((30, 0, 5, 5), 0.95),
    )
    assert search.suppress([a, b, c, d], 0.3) == [d, a, c]
    assert search.suppress([], 0.3) == []
    e, f = m((50, 0, 4, 4), 0.5), m((60, 0, 4, 4), 0.5)
    assert search.suppress([e, f], 0.3) == [e, f]


@pytest.mark.parametrize("n", [1, 2, 3, 4, 7, 13])
def test_reduced_maps_are_opencvs_threshold_and_area_average(n: int) -> None:
    # The one-pass cell counts equal inRange/compare, INTER_AREA and Agreement.of bit for
    # bit: depths on and either side of the float32 bounds D - band, D + band, D + gap,
    # no depth (+inf), and a map whose size is not a multiple of n (last cells dropped).
    rng = np.random.default_rng(n)
    for D in rng.uniform(0.8, 7.0, 20):
        edges = [np.float32(D - 0.3), np.float32(D + 0.3), np.float32(D + 0.5)]
        values = [np.nextafter(e, np.float32(s)) for e in edges for s in (-np.inf, np.inf)]
        values += [*edges, np.float32(np.inf), np.float32(0.0), np.float32(D)]
        depth = np.array(values, np.float32)[rng.integers(0, len(values), (5 * n + 3, 7 * n + 2))]
        near, free = st.agreement_u8_far(depth, float(D), 0.3, 0.5)
        if n > 1:
            h, w = (depth.shape[0] // n) * n, (depth.shape[1] // n) * n
            size = (w // n, h // n)
            near = cv2.resize(near[:h, :w], size, interpolation=cv2.INTER_AREA)
            free = cv2.resize(free[:h, :w], size, interpolation=cv2.INTER_AREA)
        want = st.Agreement.of(near, free, 255.0)
        got = search._reduced(depth, float(D), n, PARAMS)
        assert got.diff.tobytes() == want.diff.tobytes()
        assert got.free.tobytes() == want.free.tobytes()
