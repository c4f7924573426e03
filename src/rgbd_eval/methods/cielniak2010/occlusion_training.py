"""Train and evaluate the occlusion classifier on rendered pairs (seed 004, section 5).

The features of each rendered pair (:mod:`rgbd_eval.sim.occlusion_pairs`) are taken in
both orders, ``f(a, b)`` labelled ``+1`` when ``a`` is in front and ``f(b, a) = -f(a, b)``
with the opposite label, so the classes are balanced and no feature can learn which slot
the near person was drawn in. One classifier is trained per feature group (thermal,
colour, both), as the paper compares them; accuracy is the share of held-out pairs whose
front person :func:`rgbd_eval.methods.cielniak2010.occlusion.order` names correctly.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from rgbd_eval.methods.cielniak2010.occlusion import (
    FEATURE_NAMES,
    GROUPS,
    OcclusionClassifier,
    OcclusionScene,
    pair_features,
)
from rgbd_eval.sim.occlusion_pairs import RenderedPair, overlapping_pairs
from rgbd_eval.track.adaboost import train

F64 = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class PairFeatures:
    """Features ``f(a, b)`` of pairs (``(n, d)``), whether ``a`` is in front, and the tie rule."""

    x: F64
    a_in_front: NDArray[np.bool_]
    #: what :func:`~rgbd_eval.methods.cielniak2010.occlusion.order` answers on a zero margin
    tie_a_in_front: NDArray[np.bool_]
    #: the share of the occluded person's thermal pixels that is visible
    back_visible: F64

    def __len__(self) -> int:
        return int(self.x.shape[0])

    def both_orders(self) -> tuple[F64, NDArray[np.int64]]:
        """Training samples: every pair as ``(a, b)`` and as ``(b, a)``, labels in {-1, +1}."""
        y = np.where(self.a_in_front, 1, -1).astype(np.int64)
        return np.concatenate([self.x, -self.x]), np.concatenate([y, -y])


def features_of(
    pairs: Iterable[RenderedPair], progress: Callable[[int], None] | None = None
) -> PairFeatures:
    """Compute the features of rendered pairs (person 0 as ``a``)."""
    xs, fronts, ties, back = [], [], [], []
    for k, p in enumerate(pairs):
        scene = OcclusionScene.of(p.temperature, p.colour, _Affine(p.scale, p.offset))
        a, b = p.boxes
        xs.append(pair_features(a, b, scene))
        fronts.append(p.front == 0)
        ties.append((a[3], a[2] - a[0], a[0]) > (b[3], b[2] - b[0], b[0]))
        back.append(p.visible[1 - p.front])
        if progress is not None:
            progress(k + 1)
    if not xs:
        raise ValueError("no pairs to compute features of")
    return PairFeatures(
        np.stack(xs), np.array(fronts, dtype=bool), np.array(ties, dtype=bool), np.array(back)
    )


@dataclass(frozen=True)
class _Affine:
    scale: tuple[float, float]
    offset: tuple[float, float]


def render_features(
    seed: int,
    count: int,
    jitter: float,
    illumination: float = 1.0,
    progress: Callable[[int], None] | None = None,
) -> PairFeatures:
    """Render ``count`` pairs for ``seed`` and compute their features."""
    return features_of(overlapping_pairs(seed, count, jitter, illumination), progress)


def train_groups(data: PairFeatures, rounds: int) -> dict[str, OcclusionClassifier]:
    """One classifier per feature group (``thermal``, ``colour``, ``both``)."""
    x, y = data.both_orders()
    return {
        group: OcclusionClassifier(train(x, y, FEATURE_NAMES, rounds, cols), group)
        for group, cols in GROUPS.items()
    }


def decisions(clf: OcclusionClassifier, data: PairFeatures) -> NDArray[np.bool_]:
    """What :func:`~rgbd_eval.methods.cielniak2010.occlusion.order` answers for ``(a, b)`` of every pair."""
    s = clf.model.score(np.concatenate([data.x, -data.x]))
    n = len(data)
    margin = s[:n] - s[n:]
    out: NDArray[np.bool_] = np.where(margin != 0.0, margin > 0.0, data.tie_a_in_front)
    return out


def accuracy(clf: OcclusionClassifier, data: PairFeatures) -> float:
    """Share of pairs whose front person the classifier names correctly."""
    return float(np.mean(decisions(clf, data) == data.a_in_front))


def evaluate(
    classifiers: Mapping[str, OcclusionClassifier], data: PairFeatures
) -> dict[str, dict[str, Any]]:
    """Per group: accuracy overall and on pairs where the back person is at most half visible."""
    hard = data.back_visible <= 0.5
    out: dict[str, dict[str, Any]] = {}
    for group, clf in classifiers.items():
        ok = decisions(clf, data) == data.a_in_front
        out[group] = {
            "accuracy": float(ok.mean()),
            "pairs": len(data),
            "accuracy_half_hidden": float(ok[hard].mean()) if hard.any() else None,
            "pairs_half_hidden": int(hard.sum()),
            "stumps": len(clf.model.stumps),
        }
    return out


@dataclass(frozen=True)
class TrainingPlan:
    """What the shipped model is trained on; the defaults are what ships."""

    train_seed: int = 1
    train_pairs: int = 600
    test_seed: int = 2
    test_pairs: int = 300
    #: box noise in box heights: a tracker's box is not the exact extent
    jitter: float = 0.03
    #: boosting rounds per group (stumps; a stump may repeat a feature)
    rounds: int = 40


def model_document(
    classifiers: Mapping[str, OcclusionClassifier],
    plan: TrainingPlan,
    held_out: Mapping[str, Mapping[str, Any]],
) -> dict[str, Any]:
    """The JSON document of the shipped model: stumps per group and their provenance."""
    return {
        "schema": 1,
        "description": (
            "cielniak2010 occlusion classifier (seed 004, section 5): discrete AdaBoost "
            "with decision stumps over pairwise thermal and colour features, one per group"
        ),
        "provenance": {
            "tool": "tools/cielniak2010/train_occlusion.py",
            "data": (
                "rendered pairs of overlapping people (rgbd_eval.sim.occlusion_pairs), "
                "pair k of seed s drawn from numpy default_rng([s, k])"
            ),
            "plan": {
                "train_seed": plan.train_seed,
                "train_pairs": plan.train_pairs,
                "test_seed": plan.test_seed,
                "test_pairs": plan.test_pairs,
                "jitter": plan.jitter,
                "rounds": plan.rounds,
            },
            "held_out": {g: dict(v) for g, v in held_out.items()},
        },
        "models": {g: c.model.to_dict() for g, c in classifiers.items()},
    }
