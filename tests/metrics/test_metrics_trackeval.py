"""Parity with TrackEval (the ``motchallenge`` convention) on random sequences.

The reference is PyPI's ``trackeval`` 1.3.0 (a packaging of Luiten's TrackEval; its
``CLEAR``, ``HOTA`` and ``Identity`` ``eval_sequence`` bodies were compared line by
line with github.com/JonathonLuiten/TrackEval and are the same algorithm). It is
installed without its dependencies (opencv-python would shadow our headless
OpenCV); see the Makefile. Its metrics get exactly the similarity matrices we
score, so any difference is in the matching and counting.
"""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from metrics_builders import gt, track
from trackeval_parity import assert_counts_equal_trackeval, trackeval_data

from rgbd_eval.config import Convention, EvaluationConfig, Gating
from rgbd_eval.metrics import evaluate_sequence
from rgbd_eval.types import GroundTruthObject, TrackOutput

pytest.importorskip("trackeval.metrics")

Frames = tuple[list[list[GroundTruthObject]], list[list[TrackOutput]]]


@st.composite
def sequences(draw: st.DrawFn) -> Frames:
    """Up to 14 frames of up to 4 people and 5 track ids crowded together (integer boxes)."""
    n_frames = draw(st.integers(1, 14))
    gts: list[list[GroundTruthObject]] = []
    tracks: list[list[TrackOutput]] = []
    for _ in range(n_frames):
        people = draw(st.lists(st.integers(1, 4), unique=True, max_size=4))
        ids = draw(st.lists(st.integers(1, 5), unique=True, max_size=5))
        gts.append(
            [
                gt(
                    p,
                    (float(draw(st.integers(0, 24))), 0.0, 10.0, 10.0),
                    (draw(st.integers(0, 12)) / 4, 0.0),
                )
                for p in people
            ]
        )
        tracks.append(
            [
                track(
                    i,
                    (float(draw(st.integers(0, 24))), float(draw(st.integers(0, 3))), 10.0, 10.0),
                    (draw(st.integers(0, 12)) / 4, draw(st.integers(0, 2)) / 4),
                )
                for i in ids
            ]
        )
    return gts, tracks


@pytest.mark.parametrize("gating", list(Gating))
@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=sequences())
def test_counts_equal_trackeval(gating: Gating, data: Frames) -> None:
    gts, tracks = data
    config = EvaluationConfig(gating=gating, convention=Convention.MOTCHALLENGE)
    c = evaluate_sequence(gts, tracks, config).counts
    assert_counts_equal_trackeval(
        c, trackeval_data(gts, tracks, gating), similarity_is_iou=gating is Gating.IOU
    )
