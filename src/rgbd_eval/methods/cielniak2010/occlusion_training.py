"""Train and evaluate the occlusion classifier on rendered pairs (seed 004, section 5).

The shipped model is trained on the overlapping pairs of people in the frames of the
tuning scenes (``configs/scenarios/tuning/cielniak2010_*_tuning.yaml``: other layouts,
people and paths than the scenes ``reproduce`` scores), rendered at the tuning seeds of
:class:`TrainingPlan`; ``reproduce`` reports it on the pairs of the scored scenes.
The features of each rendered pair (:mod:`rgbd_eval.sim.occlusion_pairs`) are taken in
both orders, ``f(a, b)`` labelled ``+1`` when ``a`` is in front and ``f(b, a) = -f(a, b)``
with the opposite label, so the classes are balanced and no feature can learn which slot
the near person was drawn in. One classifier is trained per feature group (thermal,
colour, both), as the paper compares them; accuracy is the share of held-out pairs whose
front person :func:`rgbd_eval.methods.cielniak2010.occlusion.order` names correctly.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
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
from rgbd_eval.sim.occlusion_pairs import RenderedPair, overlapping_pairs, scene_pairs
from rgbd_eval.sim.scenario import load_scenario, scenarios_dir
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


#: A scene and the scenario seed it is rendered with.
SceneSeed = tuple[str, int]


def scenes_features(
    scenes: Sequence[tuple[Path, int]],
    jitter: float,
    stride: int,
    limit: int | None = None,
    overrides: Sequence[tuple[str, Any]] = (),
    progress: Callable[[int], None] | None = None,
) -> PairFeatures:
    """Features of the overlapping pairs in scenario files rendered at the given seeds
    (:func:`rgbd_eval.sim.occlusion_pairs.scene_pairs`: every ``stride``-th frame, at most
    ``limit`` pairs per scene), with ``overrides`` applied to each scenario."""
    pairs = itertools.chain.from_iterable(
        scene_pairs(load_scenario(path, [*overrides, ("seed", seed)]), jitter, stride, limit)
        for path, seed in scenes
    )
    return features_of(pairs, progress)


def tuning_scene(name: str) -> Path:
    """A tuning scene's file (``configs/scenarios/tuning/<name>.yaml``)."""
    return scenarios_dir() / "tuning" / f"{name}.yaml"


_CROSSINGS, _CORRIDOR = "cielniak2010_crossings_tuning", "cielniak2010_corridor_tuning"


@dataclass(frozen=True)
class TrainingPlan:
    """What the shipped model is trained on; the defaults are what ships.

    Training and its held-out check read only the tuning scenes, each rendered at seeds of
    its own (each seed draws other bodies, clothes and hair for the scene's people and other
    sensor noise); the scored scenes never enter the model.
    """

    train: tuple[SceneSeed, ...] = (
        (_CROSSINGS, 201),
        (_CORRIDOR, 202),
        (_CROSSINGS, 203),
        (_CORRIDOR, 204),
    )
    #: pairs from every ``stride``-th frame (neighbouring frames repeat a pair nearly)
    stride: int = 4
    #: at most this many pairs per scene and seed (the corridor has more overlaps)
    limit: int = 60
    held_out: tuple[SceneSeed, ...] = ((_CROSSINGS, 205), (_CORRIDOR, 206))
    held_out_stride: int = 8
    #: box noise in box heights: a tracker's box is not the exact extent
    jitter: float = 0.03
    #: boosting rounds per group (stumps; a stump may repeat a feature)
    rounds: int = 40

    def training_data(self, progress: Callable[[int], None] | None = None) -> PairFeatures:
        scenes = [(tuning_scene(n), s) for n, s in self.train]
        return scenes_features(scenes, self.jitter, self.stride, self.limit, progress=progress)

    def held_out_data(self, progress: Callable[[int], None] | None = None) -> PairFeatures:
        scenes = [(tuning_scene(n), s) for n, s in self.held_out]
        return scenes_features(
            scenes, self.jitter, self.held_out_stride, self.limit, progress=progress
        )


def model_document(
    classifiers: Mapping[str, OcclusionClassifier],
    plan: TrainingPlan,
    held_out: Mapping[str, Mapping[str, Any]],
    train_pairs: int,
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
                "overlapping pairs of people in the frames of the tuning scenes "
                "(configs/scenarios/tuning/, rgbd_eval.sim.occlusion_pairs.scene_pairs) "
                "rendered at the seeds below; never the scenes reproduce scores"
            ),
            "plan": {
                "train": [list(x) for x in plan.train],
                "stride": plan.stride,
                "limit": plan.limit,
                "train_pairs": train_pairs,
                "held_out": [list(x) for x in plan.held_out],
                "held_out_stride": plan.held_out_stride,
                "jitter": plan.jitter,
                "rounds": plan.rounds,
            },
            "held_out": {g: dict(v) for g, v in held_out.items()},
        },
        "models": {g: c.model.to_dict() for g, c in classifiers.items()},
    }
