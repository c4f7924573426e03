"""The thesis authors' HOG classifier takes the synthetic people for people, as it takes real ones.

Issue 30 compares with real people: on PCL's ``five_people`` Kinect frame (2-3 m) the authors'
classifier (seed 000, 5.4.2; PCL's C++ model) gives +0.77, +0.40, 0.00, +0.11 and -0.96
(median +0.11). Our fully visible walkers at 3-4 m score higher than that median (about
+0.7, every orientation and person pooled; the profiles lowest): the guard here is the lower
side, that they stay at least as person-like as the real people (the mannequins they replace
scored about -1.0), and that person-sized objects (coat stand, plant, cabinet) score well
below them. ``tools/realism/measure.py`` reports the whole grid (distances, orientations,
SSDLite, OpenCV's HOG).
"""

from __future__ import annotations

import numpy as np
import pytest

from rgbd_eval import exact
from rgbd_eval.detect.authors_hog import PersonWindow, person_confidences
from rgbd_eval.sim.annotate import projected_extent
from rgbd_eval.sim.scenario import parse_scenario
from rgbd_eval.sim.simulate import Simulator
from rgbd_eval.types import Box2D

from .hog_response import GALLERY, Scores, measure

REAL_MEDIAN = 0.11


def _walker(distance: float, orientation_deg: int, person: int) -> float:
    """Authors' HOG confidence of one person walking at ``distance`` m, turned ``orientation``."""
    heading = exact.PI + orientation_deg * (exact.PI / 180.0)
    s, c = exact.sincos(heading)
    sc = parse_scenario(
        {
            "name": "walker",
            "duration_s": 1.0 / 1.2 + 0.1,
            "seed": 1000 + person,
            "room": {"x_min": -1.0, "x_max": 14.0, "y_min": -7.0, "y_max": 7.0},
            "people": [
                {
                    "id": person,
                    "height": 1.55 + 0.08 * (person % 5),
                    "path": [
                        {"x": distance - c, "y": -s},
                        {"x": distance + 20.0 * c, "y": 20.0 * s, "speed": 1.2},
                    ],
                }
            ],
        }
    )
    sim = Simulator(sc)
    index = sim.n_frames - 1
    f = sim.frame(index)
    (_, mesh, _, _), *_ = sim.people_meshes(sim.time(index))
    extent = projected_extent(mesh.vertices, sim.rgb_camera, f.rgb_pose)
    assert extent is not None
    u0, v0, u1, v1 = extent
    window = PersonWindow(v1 - v0, (u0 + u1) / 2, (v0 + v1) / 2)
    return float(person_confidences(f.rgb, [window])[0])


@pytest.mark.slow
def test_people_score_at_least_like_real_people() -> None:
    # fully in view from 1.1 m (nearer than about 2.8 m the feet leave the image)
    scores = [_walker(d, o, p) for d in (3.0, 4.0) for o in range(0, 360, 45) for p in (1, 2, 3)]
    assert float(np.median(scores)) >= REAL_MEDIAN - 0.3, sorted(scores)


def test_look_alikes_score_below_people_in_a_small_gallery() -> None:
    def authors(rgb: np.ndarray, box: Box2D) -> float:
        w = PersonWindow(box.height, box.left + box.width / 2, box.top + box.height / 2)
        return float(person_confidences(rgb, [w])[0])

    scores = Scores()
    measure(parse_scenario(GALLERY), 6, scores, authors)
    assert len(scores.objects) >= 10
    assert set(scores.by_kind) == {"coat_stand", "plant", "cabinet"}
    people = [_walker(3.0, o, 1) for o in (0, 180)]  # seen from the front and the back
    assert min(people) > float(np.median(scores.objects)) + 1.5
