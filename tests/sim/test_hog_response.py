"""OpenCV's Dalal-Triggs people detector responds to the synthetic people, not to look-alikes.

The issue's criterion: fully visible people between 1.5 and 6 m reach a median HOG
confidence >= -0.5 on their full-body window; person-sized non-person objects
mostly score below -1.5.
"""

from __future__ import annotations

import numpy as np
import pytest

from rgbd_eval.sim.scenario import parse_scenario

from .hog_response import GALLERY, Scores, measure, thesis_scenarios


def test_people_score_high_and_look_alikes_low_in_a_small_gallery() -> None:
    scores = Scores()
    measure(parse_scenario(GALLERY), 6, scores)
    assert len(scores.people) >= 10
    assert len(scores.objects) >= 10
    assert float(np.median(scores.people)) >= -0.5
    assert float(np.mean(np.asarray(scores.objects) < -1.5)) >= 0.8
    assert set(scores.by_kind) == {"coat_stand", "plant", "cabinet"}
    assert float(np.median(scores.people)) > float(np.median(scores.objects)) + 1.5


@pytest.mark.slow
def test_thesis_scenarios_meet_the_hog_criterion() -> None:
    scores = Scores()
    for sc in thesis_scenarios():
        measure(sc, 25, scores)
    assert len(scores.people) >= 100
    assert float(np.median(scores.people)) >= -0.5
    assert float(np.mean(np.asarray(scores.objects) < -1.5)) > 0.5
