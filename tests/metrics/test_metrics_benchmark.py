"""Scoring speed on a thesis-sized sequence: 750 frames, 3 people (seed 000, chapter 7).

Run with ``pytest tests/metrics/test_metrics_benchmark.py -m slow -s`` to see the time.
"""

from __future__ import annotations

import math
import time

import numpy as np
import pytest
from metrics_builders import gt, track

from rgbd_eval.config import EvaluationConfig, Gating
from rgbd_eval.metrics import evaluate_sequence
from rgbd_eval.types import GroundTruthObject, TrackOutput

N_FRAMES = 750  # about 750 frames per thesis test sequence (seed 000, chapter 7)
N_PEOPLE = 3


def _sequence() -> tuple[list[list[GroundTruthObject]], list[list[TrackOutput]]]:
    """People walking side to side; a noisy tracker that misses 5 %, changes ids twice."""
    rng = np.random.default_rng(0)
    gts, tracks = [], []
    for f in range(N_FRAMES):
        frame_gt, frame_tracks = [], []
        for p in range(N_PEOPLE):
            u = 100.0 + 150.0 * p + 50.0 * math.sin(f / 40.0 + p)
            x = p + math.sin(f / 40.0)
            frame_gt.append(gt(p, (u, 100.0, 60.0, 160.0), (x, 2.0), frame=f))
            if rng.random() < 0.95:
                du, dv, dx = rng.normal(0.0, 8.0), rng.normal(0.0, 5.0), rng.normal(0.0, 0.2)
                box = (u + du, 100.0 + dv, 60.0, 160.0)
                frame_tracks.append(track(10 * (1 + f // 300) + p, box, (x + dx, 2.0)))
        if rng.random() < 0.05:
            frame_tracks.append(track(99, (500.0, 300.0, 50.0, 100.0), (5.0, 5.0)))
        gts.append(frame_gt)
        tracks.append(frame_tracks)
    return gts, tracks


@pytest.mark.slow
@pytest.mark.parametrize("gating", list(Gating))
def test_scoring_a_thesis_sized_sequence_is_fast(gating: Gating) -> None:
    gts, tracks = _sequence()
    config = EvaluationConfig(gating=gating)
    evaluate_sequence(gts[:10], tracks[:10], config)  # warm up imports
    best = math.inf
    for _ in range(3):
        start = time.perf_counter()
        scores = evaluate_sequence(gts, tracks, config)
        best = min(best, time.perf_counter() - start)
    print(f"\n{gating.value}: {N_FRAMES} frames x {N_PEOPLE} people scored in {best * 1e3:.0f} ms")
    assert scores.counts.num_gt == N_FRAMES * N_PEOPLE
    assert scores.counts.id_switches >= N_PEOPLE  # the ids change at frames 300 and 600
    assert best < 5.0  # generous: about 0.2-0.3 s on one shared core
