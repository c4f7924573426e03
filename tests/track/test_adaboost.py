"""Discrete AdaBoost with decision stumps (seed 004 section 5, ref. [1])."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rgbd_eval.track.adaboost import BoostedStumps, Stump, train


def test_separable_data_needs_one_stump() -> None:
    # x = 1 2 3 4 with labels - - + +: the split between 2 and 3 (threshold 2.5) has error 0,
    # clamped to 1e-10: alpha = 1/2 ln((1 - 1e-10) / 1e-10) = 11.51
    x = np.array([[1.0], [2.0], [3.0], [4.0]])
    y = np.array([-1, -1, 1, 1])
    model = train(x, y, ["f"], rounds=1)
    (s,) = model.stumps
    assert (s.feature, s.threshold, s.polarity) == (0, 2.5, 1)
    assert s.alpha == pytest.approx(0.5 * math.log((1 - 1e-10) / 1e-10))
    assert list(model.predict(x)) == [-1, -1, 1, 1]


def test_two_rounds_by_hand() -> None:
    # x = 1 2 3 4 5, labels - - + - +. Class-balanced start: positives 1/4 each, negatives 1/6.
    # Round 1: threshold 2.5 (+1 above) misses only x=4: e = 1/6, alpha = 1/2 ln 5 = 0.8047.
    #   (threshold 4.5 misses x=3: 1/4; 3.5 misses 3 and 4: 5/12.)
    # Re-weighting gives the missed sample half the weight: x=4 -> 0.5; the others share 0.5
    # in proportion: positives 0.25 / (5/6) * 0.5 = 0.15 each, x=1,2: 0.1 each.
    # Round 2: threshold 4.5 (+1 above) misses only x=3: e = 0.15, alpha = 1/2 ln(0.85/0.15).
    x = np.array([[1.0], [2.0], [3.0], [4.0], [5.0]])
    y = np.array([-1, -1, 1, -1, 1])
    model = train(x, y, ["f"], rounds=2)
    s1, s2 = model.stumps
    assert (s1.threshold, s1.polarity) == (2.5, 1)
    assert s1.alpha == pytest.approx(0.5 * math.log(5.0))
    assert (s2.threshold, s2.polarity) == (4.5, 1)
    assert s2.alpha == pytest.approx(0.5 * math.log(0.85 / 0.15))
    # scores: x=3: 0.8047 - 0.8673 < 0 (still wrong); x=5: both +1
    np.testing.assert_allclose(model.score(x)[[2, 4]], [s1.alpha - s2.alpha, s1.alpha + s2.alpha])


def test_feature_group_restricts_the_stumps() -> None:
    # column 0 separates perfectly, column 1 only partly: restricted to [1] it must use 1
    x = np.array([[0.0, 1.0], [0.1, 3.0], [1.0, 2.0], [1.1, 4.0]])
    y = np.array([-1, -1, 1, 1])
    assert train(x, y, ["a", "b"], 1).stumps[0].feature == 0
    restricted = train(x, y, ["a", "b"], 3, features=[1])
    assert {s.feature for s in restricted.stumps} == {1}


def test_stops_when_no_stump_beats_chance() -> None:
    # identical features, opposite labels: every stump has weighted error 1/2
    x = np.array([[1.0], [1.0]])
    y = np.array([1, -1])
    assert train(x, y, ["f"], 5).stumps == ()


def test_training_is_deterministic_and_round_trips() -> None:
    rng = np.random.default_rng(3)
    x = rng.normal(size=(200, 4))
    y = np.where(x[:, 0] + 0.5 * x[:, 2] > 0, 1, -1)
    a = train(x, y, ["p", "q", "r", "s"], 15)
    b = train(x, y, ["p", "q", "r", "s"], 15)
    assert a == b
    assert BoostedStumps.from_dict(a.to_dict()) == a
    assert np.mean(a.predict(x) == y) > 0.95


@pytest.mark.parametrize(
    ("x", "y", "message"),
    [
        (np.array([[1.0], [2.0]]), np.array([1, 1]), "both classes"),
        (np.array([[1.0], [np.nan]]), np.array([1, -1]), "finite"),
        (np.array([[1.0], [2.0]]), np.array([1, 0]), "-1 or \\+1"),
        (np.array([1.0, 2.0]), np.array([1, -1]), "do not agree"),
    ],
)
def test_bad_training_data_is_refused(x: np.ndarray, y: np.ndarray, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        train(x, y, ["f"], 3)


def test_bad_model_is_refused() -> None:
    with pytest.raises(ValueError, match="must index"):
        BoostedStumps(("f",), (Stump(1, 0.0, 1, 1.0),))
    with pytest.raises(ValueError, match="polarity"):
        BoostedStumps(("f",), (Stump(0, 0.0, 0, 1.0),))
    with pytest.raises(ValueError, match="not one of"):
        BoostedStumps.from_dict(
            {
                "feature_names": ["f"],
                "stumps": [{"feature": "g", "threshold": 0, "polarity": 1, "alpha": 1}],
            }
        )
