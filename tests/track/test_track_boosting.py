"""The on-line boosted classifier on its own: features, separation, drift, determinism."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rgbd_eval.track.boosting import (
    OnlineBoostingClassifier,
    _select_kernel,
    box_corners,
    box_masks,
)
from rgbd_eval.track.synthetic import colour_histogram

RED, BLUE, GREEN = (200.0, 40.0, 40.0), (40.0, 40.0, 200.0), (40.0, 200.0, 40.0)
MIN_PREDICTION = 9.0  # Table 6.1 ~recovery/min_prediction


def test_box_mask_by_hand() -> None:
    # bins = 2, box r in [0,0], g in [1,1], b in [0,1]: flat index r*4 + g*2 + b = 2 and 3
    mask = box_masks(np.array([[[0, 0], [1, 1], [0, 1]]]), 2)
    assert mask.shape == (8, 1)
    assert np.flatnonzero(mask[:, 0]).tolist() == [2, 3]


def test_features_are_box_sums() -> None:
    c = OnlineBoostingClassifier(4, weak_classifiers=20, selectors=5, seed=1)
    hist = np.random.default_rng(0).random(64).astype(np.float32)
    masks = box_masks(c.boxes, 4)
    assert np.allclose(c.features(hist), hist @ masks, rtol=1e-5)
    # feature exchange: each update replaces exactly one unselected weak hypothesis
    before = c.boxes
    c.update(hist, True)
    changed = np.flatnonzero((c.boxes != before).any(axis=(1, 2)))
    assert len(changed) == 1 and not set(changed) & set(c.selected.tolist())
    assert np.allclose(c.features(hist), hist @ box_masks(c.boxes, 4), rtol=1e-5)


def _train(
    c: OnlineBoostingClassifier,
    rng: np.random.Generator,
    pos: tuple[float, float, float],
    neg: tuple[float, float, float],
    n: int,
) -> None:
    for _ in range(n):
        c.update(colour_histogram(rng, pos), True)
        c.update(colour_histogram(rng, neg), False)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_separates_two_colour_distributions_after_a_few_updates(seed: int) -> None:
    rng = np.random.default_rng(100 + seed)
    c = OnlineBoostingClassifier(8, 250, 50, seed=seed)  # Table 6.1 sizes
    # 20 updates each: less than a second of a person at 30 Hz
    _train(c, rng, RED, BLUE, 20)
    pos = c.predict(np.stack([colour_histogram(rng, RED) for _ in range(50)]))
    neg = c.predict(np.stack([colour_histogram(rng, BLUE) for _ in range(50)]))
    assert (pos > 0).all() and (neg < 0).all()
    assert np.mean(pos > MIN_PREDICTION) >= 0.9
    assert np.mean(neg < -MIN_PREDICTION) >= 0.9


def test_adapts_when_the_target_drifts() -> None:
    rng = np.random.default_rng(7)
    c = OnlineBoostingClassifier(8, seed=3)
    _train(c, rng, RED, BLUE, 20)
    # the target's colour drifts from red to green; blue stays the negative
    _train(c, rng, GREEN, BLUE, 30)
    assert c.predict(colour_histogram(rng, GREEN)) > MIN_PREDICTION
    assert c.predict(colour_histogram(rng, BLUE)) < 0
    assert c.predict(colour_histogram(rng, RED)) < MIN_PREDICTION


def test_same_seed_same_result_bit_for_bit() -> None:
    out = []
    for _ in range(2):
        rng = np.random.default_rng(5)
        c = OnlineBoostingClassifier(8, seed=11)
        _train(c, rng, RED, BLUE, 5)
        out.append((c.predict(colour_histogram(rng, GREEN)), c.selected, c.alpha))
    assert out[0][0] == out[1][0]
    assert (out[0][1] == out[1][1]).all() and (out[0][2] == out[1][2]).all()
    other = OnlineBoostingClassifier(8, seed=12)
    assert not np.array_equal(other.boxes, OnlineBoostingClassifier(8, seed=11).boxes)


@settings(max_examples=15, deadline=None)
@given(st.integers(0, 2**16), st.lists(st.booleans(), min_size=1, max_size=12))
def test_votes_and_selection_stay_valid(seed: int, labels: list[bool]) -> None:
    rng = np.random.default_rng(seed)
    c = OnlineBoostingClassifier(4, weak_classifiers=30, selectors=10, seed=seed)
    for label in labels:
        c.update(colour_histogram(rng, RED if label else BLUE, bins=4), label)
    assert (c.alpha >= 0).all()
    assert ((c.selected >= 0) & (c.selected < 30)).all()
    batch = np.stack([colour_histogram(rng, GREEN, bins=4) for _ in range(3)])
    assert c.predict(batch).tolist() == [float(c.predict(h)) for h in batch]
    assert abs(float(c.predict(batch[0]))) <= c.alpha.sum() + 1e-9
    assert c.positives == sum(labels) and c.negatives == len(labels) - sum(labels)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"bins": 0}, "bins=0"),
        ({"bins": 8, "weak_classifiers": 0}, "weak_classifiers=0"),
        ({"bins": 8, "weak_classifiers": 10, "selectors": 11}, "selectors=11"),
        ({"bins": 8, "learning_rate": 0.0}, "learning_rate=0.0"),
    ],
)
def test_bad_arguments_raise(kwargs: dict[str, int], match: str) -> None:
    with pytest.raises(ValueError, match=match):
        OnlineBoostingClassifier(**kwargs)


def test_wrong_histogram_size_raises() -> None:
    c = OnlineBoostingClassifier(8)
    with pytest.raises(ValueError, match="bins=8"):
        c.predict(np.zeros(64, dtype=np.float32))
    with pytest.raises(ValueError, match="one histogram"):
        c.update(np.zeros((2, 512), dtype=np.float32), True)


def _boost(c: OnlineBoostingClassifier, correct: np.ndarray) -> None:
    """The selectors' part of an update, given which weak hypotheses are right."""
    _select_kernel(~correct, c._wrong, c._total, c._selected, c._errors)
    c._alpha = None  # the votes follow the new errors


def _reference_boost(
    wrong: list[list[float]], total: list[float], correct: list[bool]
) -> tuple[list[list[float]], list[float], list[int], list[float]]:
    """Grabner-Bischof selectors over Oza's importance, written plainly, one weight at a time."""
    wrong = [list(r) for r in wrong]
    total = list(total)
    lam, taken, selected, alpha = 1.0, set(), [], []
    for n in range(len(wrong)):
        total[n] += lam
        for m in range(len(correct)):
            if not correct[m]:
                wrong[n][m] += lam
        free = [m for m in range(len(correct)) if m not in taken]
        best = min(free, key=lambda m: (wrong[n][m] / total[n], m))
        e = wrong[n][best] / total[n]
        taken.add(best)
        selected.append(best)
        alpha.append(0.5 * np.log((1 - e) / e) if e < 0.5 else 0.0)
        lam = lam / (2 * (1 - e)) if correct[best] else lam / (2 * e)
    return wrong, total, selected, alpha


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 6), st.integers(6, 12))
def test_selector_update_matches_a_plain_reference(seed: int, N: int, M: int) -> None:
    rng = np.random.default_rng(seed)
    c = OnlineBoostingClassifier(2, weak_classifiers=M, selectors=N, seed=seed)
    total = rng.uniform(2.0, 20.0, N)
    c._total = total.copy()
    c._wrong = rng.uniform(0.05, 0.95, (N, M)) * total[:, None]
    correct = rng.random(M) < 0.5
    ref_wrong, ref_total, ref_sel, ref_alpha = _reference_boost(
        c._wrong.tolist(), total.tolist(), correct.tolist()
    )
    _boost(c, correct)
    assert np.allclose(c._wrong, ref_wrong) and np.allclose(c._total, ref_total)
    assert c.selected.tolist() == ref_sel
    assert np.allclose(c.alpha, ref_alpha)


def test_one_update_by_hand() -> None:
    # 2 weak hypotheses, 2 selectors, all weights at their start (wrong 1, total 2).
    # Sample: h0 right, h1 wrong. Selector 0: lam = 1 -> wrong = (1, 2), total 3;
    # errors (1/3, 2/3): takes h0, e = 1/3, alpha = 1/2 ln 2; lam -> 1 / (2 * 2/3) = 3/4.
    # Selector 1: only h1 is free: wrong = (1, 1.75), total 2.75, e = 1.75/2.75 > 1/2 -> alpha 0
    c = OnlineBoostingClassifier(2, weak_classifiers=2, selectors=2, seed=0)
    _boost(c, np.array([True, False]))
    assert c.selected.tolist() == [0, 1]
    assert c.alpha.tolist() == pytest.approx([0.5 * np.log(2.0), 0.0])
    assert c._wrong.tolist() == [[1.0, 2.0], [1.0, 1.75]]
    assert c._total.tolist() == [3.0, 2.75]


def _two_bin_hist(mass_in_red_low: float) -> np.ndarray:
    """bins = 2: ``mass`` in bin (r=0, g=0, b=0), the rest in bin (1, 1, 1)."""
    h = np.zeros(8, dtype=np.float32)
    h[0], h[7] = mass_in_red_low, 1.0 - mass_in_red_low
    return h


def test_weak_hypothesis_threshold_by_hand() -> None:
    # one weak hypothesis on the box r in [0,0], g and b in [0,1]: it sees bin 0's mass.
    # positive mass 0.8, negative 0.2: means 0.8 and 0.2, threshold 0.5
    c = OnlineBoostingClassifier(2, weak_classifiers=1, selectors=1, seed=0)
    c._boxes[0] = [[0, 0], [0, 1], [0, 1]]
    c._corners = box_corners(c._boxes, 2)
    c.update(_two_bin_hist(0.8), True)
    c.update(_two_bin_hist(0.2), False)
    assert c.features(_two_bin_hist(0.6)).tolist() == pytest.approx([0.6])
    # both samples were classified right (0.8 > 0.4 = (0.8 + 0)/2, then 0.2 < 0.5), each with
    # lambda = 1: wrong weight 1, total 2 + 1 + 1 = 4, e = 1/4, alpha = 1/2 ln 3
    a = float(c.alpha[0])
    assert a == pytest.approx(0.5 * np.log(3.0))
    assert float(c.predict(_two_bin_hist(0.6))) == pytest.approx(a)  # 0.6 > 0.5
    assert float(c.predict(_two_bin_hist(0.4))) == pytest.approx(-a)
