"""Rendered overlapping pairs (training data of the cielniak2010 occlusion classifier)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rgbd_eval.methods.cielniak2010.occlusion import MODEL_PATH, shipped_classifier
from rgbd_eval.methods.cielniak2010.occlusion_training import (
    TrainingPlan,
    accuracy,
    features_of,
    train_groups,
    tuning_scene,
)
from rgbd_eval.sim.occlusion_pairs import (
    MIN_OVERLAP,
    overlapping_pairs,
    render_pair,
    scene_pairs,
)
from rgbd_eval.sim.scenario import Scenario, parse_scenario


def _overlap(a: tuple[float, ...], b: tuple[float, ...]) -> float:
    w = min(a[2], b[2]) - max(a[0], b[0])
    h = min(a[3], b[3]) - max(a[1], b[1])
    small = min((a[2] - a[0]) * (a[3] - a[1]), (b[2] - b[0]) * (b[3] - b[1]))
    return max(w, 0.0) * max(h, 0.0) / small


def test_pair_is_deterministic_for_a_seed_and_overlaps() -> None:
    p = render_pair(np.random.default_rng([5, 0]))
    q = render_pair(np.random.default_rng([5, 0]))
    np.testing.assert_array_equal(p.temperature, q.temperature)
    np.testing.assert_array_equal(p.colour, q.colour)
    assert p.boxes == q.boxes
    assert _overlap(*p.boxes) >= MIN_OVERLAP
    # the near person is the front one and nothing hides it; the far one is partly hidden
    assert p.distances[p.front] < p.distances[1 - p.front]
    assert p.visible[p.front] == pytest.approx(1.0)
    assert p.visible[1 - p.front] < 1.0
    # people are warmer than the room
    (u0, v0, u1, v1) = (round(x) for x in p.boxes[p.front])
    assert p.temperature[v0:v1, u0:u1].max() > np.median(p.temperature) + 5.0


def test_training_is_deterministic_for_a_seed() -> None:
    a = features_of(overlapping_pairs(11, 4, jitter=0.03))
    b = features_of(overlapping_pairs(11, 4, jitter=0.03))
    np.testing.assert_array_equal(a.x, b.x)
    ma, mb = train_groups(a, 5), train_groups(b, 5)
    assert {g: m.model.to_dict() for g, m in ma.items()} == {
        g: m.model.to_dict() for g, m in mb.items()
    }


@pytest.mark.slow
def test_shipped_classifier_on_fresh_pairs() -> None:
    # random pairs (sim.occlusion_pairs.overlapping_pairs): neither the tuning scenes the
    # model is trained on nor the scenes reproduce scores
    data = features_of(overlapping_pairs(99, 12, jitter=0.03))
    assert accuracy(shipped_classifier("both"), data) >= 10 / 12


def _crossing(seed: int) -> Scenario:
    """0.5 s: person 1 at 3 m and person 2 at 5 m behind it, crossing the view."""
    people = [
        {"id": 1, "path": [{"x": 3.0, "y": -0.3}, {"x": 3.0, "y": 0.3, "speed": 1.0}]},
        {"id": 2, "path": [{"x": 5.0, "y": 0.4}, {"x": 5.0, "y": -0.4, "speed": 1.0}]},
    ]
    return parse_scenario(
        {
            "name": "crossing",
            "duration_s": 0.5,
            "seed": seed,
            "room": {"x_min": -1.0, "x_max": 8.0, "y_min": -3.0, "y_max": 3.0},
            "people": people,
            "robot": {"x": 0.0, "y": 0.0, "yaw_deg": 0.0},
            "sensor": {"depth_decimation": 4},
            "rig": [{"kind": "thermal", "name": "thermal"}],
        },
        "test",
    )


@pytest.mark.slow
def test_scene_pairs_are_the_overlapping_pairs_of_a_scenes_frames() -> None:
    pairs = list(scene_pairs(_crossing(3), jitter=0.03, stride=5))
    again = list(scene_pairs(_crossing(3), jitter=0.03, stride=5))
    assert len(pairs) >= 2  # of frames 0, 5 and 10 of 15
    for p, q in zip(pairs, again, strict=True):
        assert p.boxes == q.boxes
        np.testing.assert_array_equal(p.temperature, q.temperature)
        assert p.front == 0  # person 1, listed first, is the nearer
        assert p.distances[0] < p.distances[1] - 1.5  # 3 m and 5 m, give or take the gait
        assert p.visible[0] == pytest.approx(1.0) and p.visible[1] < 1.0
    # another scenario seed: other people (bodies) and noise, the same geometry
    other = next(scene_pairs(_crossing(4), jitter=0.03, stride=5))
    assert not np.array_equal(other.temperature, pairs[0].temperature)
    assert len(list(scene_pairs(_crossing(3), stride=5, limit=2))) == 2
    with pytest.raises(ValueError, match="stride"):
        next(scene_pairs(_crossing(3), stride=0))


def test_the_shipped_model_is_trained_on_the_tuning_scenes_only() -> None:
    plan = TrainingPlan()
    for name, _ in (*plan.train, *plan.held_out):
        assert name.endswith("_tuning") and tuning_scene(name).exists(), name
    # the training seeds are not the held-out seeds
    assert not set(plan.train) & set(plan.held_out)
    # occlusion.json says it came from this plan (tools/cielniak2010/train_occlusion.py)
    shipped = json.loads(MODEL_PATH.read_text())["provenance"]["plan"]
    assert shipped["train"] == [list(x) for x in plan.train]
    assert shipped["held_out"] == [list(x) for x in plan.held_out]
    assert (shipped["stride"], shipped["limit"], shipped["held_out_stride"]) == (
        plan.stride,
        plan.limit,
        plan.held_out_stride,
    )
    assert (shipped["jitter"], shipped["rounds"]) == (plan.jitter, plan.rounds)
