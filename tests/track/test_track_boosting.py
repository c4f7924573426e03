"""The on-line boosted classifier on its own: features, separation, drift, determinism."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rgbd_eval.track.boosting import OnlineBoostingClassifier, box_masks
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
    masks = box_masks(c._boxes, 4)
    assert np.allclose(c.features(hist), hist @ masks, rtol=1e-5)


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
    assert not np.array_equal(other._boxes, OnlineBoostingClassifier(8, seed=11)._boxes)


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
    assert np.allclose(c.predict(batch), [c.predict(h) for h in batch])
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
