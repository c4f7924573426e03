"""HOG people-detector response on synthetic people vs person-sized objects.

Shared by ``test_hog_response.py`` and runnable for the note::

    .venv/bin/python tests/sim/hog_response.py [STEP]

prints, over the six thesis scenarios (every STEP-th frame), the distribution of
the people detector's confidence on the full-body box of fully visible people
between 1.5 and 6 m, and on the boxes of person-sized non-person objects.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from rgbd_eval.detect.hog import hog_confidence
from rgbd_eval.sim.annotate import clip_box, projected_extent
from rgbd_eval.sim.scenario import (
    ObstacleKind,
    Scenario,
    load_scenario,
    parse_scenario,
    scenario_paths,
)
from rgbd_eval.sim.simulate import Simulator
from rgbd_eval.sim.world import OBSTACLE_ID_BASE
from rgbd_eval.types import Box2D

PERSON_SIZED = (ObstacleKind.COAT_STAND, ObstacleKind.PLANT, ObstacleKind.CABINET)
#: "Fully visible": at least this visible fraction and the whole box inside the image.
FULLY_VISIBLE = 0.98
MIN_DIST, MAX_DIST = 1.5, 6.0


#: A small scene with every person-sized object kind (cabinet included) and three people.
GALLERY: dict[str, object] = {
    "name": "gallery",
    "duration_s": 2.0,
    "obstacles": [
        {"kind": "coat_stand", "x": 4.0, "y": 1.3},
        {"kind": "plant", "x": 4.5, "y": -1.4},
        {"kind": "cabinet", "x": 5.0, "y": 0.2, "yaw_deg": 180},
    ],
    "people": [
        {"id": 1, "height": 1.75, "path": [{"x": 3.4, "y": 1.8}, {"x": 3.4, "y": -1.8}]},
        {
            "id": 2,
            "height": 1.6,
            "shirt": [170, 40, 40],
            "bag": True,
            "path": [{"x": 5.8, "y": -2.5}, {"x": 5.8, "y": 2.5}],
        },
        {
            "id": 3,
            "height": 1.9,
            "shirt": [220, 220, 210],
            "trousers": [30, 40, 90],
            "path": [{"x": 4.6, "y": 2.6}, {"x": 4.6, "y": -2.6, "speed": 1.4}],
        },
    ],
}

#: An object's box with more person pixels than this share is not scored (a person in front).
MAX_PERSON_SHARE = 0.02


@dataclass
class Scores:
    people: list[float] = field(default_factory=list)
    objects: list[float] = field(default_factory=list)
    by_kind: dict[str, list[float]] = field(default_factory=dict)


def measure(
    scenario: Scenario,
    step: int,
    scores: Scores,
    scorer: Callable[[NDArray[np.uint8], Box2D], float] = hog_confidence,
) -> None:
    """Confidences of ``scorer`` (default: OpenCV's INRIA HOG) on fully visible people and on
    person-sized objects, every ``step``-th frame."""
    sim = Simulator(scenario)
    cam = sim.rgb_camera
    objects = [
        (OBSTACLE_ID_BASE + i, ob)
        for i, ob in enumerate(scenario.obstacles)
        if ob.kind in PERSON_SIZED
    ]
    for index in range(0, sim.n_frames, step):
        f = sim.frame(index)
        cam_xyz = np.asarray(f.rgb_pose.translation)
        for gt in f.ground_truth:
            if gt.box2d is None or gt.world_xyz is None or gt.visibility < FULLY_VISIBLE:
                continue
            b = gt.box2d
            inside = b.left > 0 and b.top > 0 and b.right < cam.width and b.bottom < cam.height
            dist = float(np.hypot(*(np.asarray(gt.world_xyz[:2]) - cam_xyz[:2])))
            if inside and MIN_DIST <= dist <= MAX_DIST:
                scores.people.append(scorer(f.rgb, b))
        for oid, ob in objects:
            verts = sim.static.vertices[sim.static.triangles[sim.static.object_ids == oid].ravel()]
            extent = projected_extent(verts, cam, f.rgb_pose)
            if extent is None or not np.any(f.ids == oid):
                continue
            box = clip_box(extent, cam.width, cam.height)
            if box is None or box.as_tuple() != (
                extent[0],
                extent[1],
                extent[2] - extent[0],
                extent[3] - extent[1],
            ):
                continue  # only objects fully inside the image
            dist = float(np.hypot(ob.x - cam_xyz[0], ob.y - cam_xyz[1]))
            if not MIN_DIST <= dist <= MAX_DIST:
                continue
            window = f.ids[round(box.top) : round(box.bottom), round(box.left) : round(box.right)]
            people = np.count_nonzero((window > 0) & (window < OBSTACLE_ID_BASE))
            if people > MAX_PERSON_SHARE * window.size:
                continue  # someone stands in front of or behind the object
            score = scorer(f.rgb, box)
            scores.objects.append(score)
            scores.by_kind.setdefault(ob.kind.value, []).append(score)


def thesis_scenarios() -> list[Scenario]:
    return [load_scenario(p) for p in scenario_paths() if p.stem != "demo"]


def summary(values: list[float]) -> str:
    if not values:
        return "n=0"
    q = np.percentile(values, [5, 25, 50, 75, 95])
    return (
        f"n={len(values)} p5={q[0]:.2f} p25={q[1]:.2f} median={q[2]:.2f} "
        f"p75={q[3]:.2f} p95={q[4]:.2f}"
    )


if __name__ == "__main__":
    step = int(sys.argv[1]) if len(sys.argv) > 1 else 10
    total = Scores()
    for sc in thesis_scenarios():
        s = Scores()
        measure(sc, step, s)
        print(f"{sc.name:18s} people  {summary(s.people)}")
        print(f"{sc.name:18s} objects {summary(s.objects)}")
        total.people += s.people
        total.objects += s.objects
        for kind, values in s.by_kind.items():
            total.by_kind.setdefault(kind, []).extend(values)
    print(f"{'all':18s} people  {summary(total.people)}")
    print(f"{'all':18s} objects {summary(total.objects)}")
    for kind, values in sorted(total.by_kind.items()):
        print(f"{kind:18s} objects {summary(values)}")
    below = np.mean(np.asarray(total.objects) < -1.5) if total.objects else float("nan")
    print(f"objects below -1.5: {below:.1%}")
    gallery = Scores()
    measure(parse_scenario(GALLERY), 1, gallery)
    print(f"{'gallery':18s} people  {summary(gallery.people)}")
    for kind, values in sorted(gallery.by_kind.items()):
        print(f"{'gallery ' + kind:18s} objects {summary(values)}")
