"""Scoring time against TrackEval on one core, on the same input (not a test; run it).

    taskset -c 0 .venv/bin/python tests/metrics/scoring_speed.py

A synthetic crowded MOT17-like sequence: 1050 frames, about 45 people per frame
(47k ground-truth boxes) and a tracker that finds 80 % of them with box noise,
occasional id changes and one false positive per frame (about 37k boxes). Printed,
best of 5: our ``evaluate_sequence`` from objects (building the per-frame arrays
included), our scoring from built frames (``score_selections``), and TrackEval's
``CLEAR`` + ``Identity`` + ``HOTA`` ``eval_sequence`` on its data dict (IoU matrices
precomputed, i.e. without its own input preparation).
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

from rgbd_eval.config import Convention, EvaluationConfig, Gating
from rgbd_eval.metrics import evaluate_sequence, score_selections
from rgbd_eval.metrics.gating import iou_matrix
from rgbd_eval.metrics.selection import select_frame
from rgbd_eval.types import Box2D, GroundTruthObject, TrackOutput, Visibility

N_FRAMES, N_PEOPLE, PRESENT = 1050, 60, 45


def sequence() -> tuple[list[list[GroundTruthObject]], list[list[TrackOutput]]]:
    rng = np.random.default_rng(1)
    start = rng.uniform(0, 1800, (N_PEOPLE, 2)) * (1, 0.5)
    velocity = rng.normal(0, 1.5, (N_PEOPLE, 2))
    size = rng.uniform(40, 90, N_PEOPLE)
    track_of = np.arange(N_PEOPLE) + 1000
    gts, tracks = [], []
    next_id = 5000
    present = np.arange(PRESENT)
    for f in range(N_FRAMES):
        if f % 50 == 0:  # a new crowd every 50 frames
            present = np.sort(rng.choice(N_PEOPLE, PRESENT, replace=False))
        pos = (start + velocity * f) % (1800, 900)
        frame_gt, frame_tracks = [], []
        for p in present:
            w, h = size[p], 2.5 * size[p]
            frame_gt.append(
                GroundTruthObject(f, 0, int(p), Box2D(pos[p, 0], pos[p, 1], w, h), None)
            )
            if rng.random() < 0.002:
                track_of[p] = next_id
                next_id += 1
            if rng.random() < 0.8:
                dx, dy = rng.normal(0, 0.08 * w, 2)
                box = Box2D(pos[p, 0] + dx, pos[p, 1] + dy, w * rng.uniform(0.9, 1.1), h)
                frame_tracks.append(
                    TrackOutput(int(track_of[p]), 0.0, 0.0, 1.7, box, Visibility.VISIBLE)
                )
        fp = Box2D(*rng.uniform(0, 1800, 2), 60.0, 150.0)
        frame_tracks.append(TrackOutput(9_000_000 + f, 0.0, 0.0, 1.7, fp, Visibility.VISIBLE))
        gts.append(frame_gt)
        tracks.append(frame_tracks)
    return gts, tracks


def best_of(fn: Callable[[], object], repeat: int = 5) -> float:
    best = float("inf")
    for _ in range(repeat):
        start = time.process_time()
        fn()
        best = min(best, time.process_time() - start)
    return best


def main() -> None:
    from trackeval.metrics import CLEAR, HOTA, Identity

    gts, tracks = sequence()
    n_gt = sum(map(len, gts))
    n_tr = sum(map(len, tracks))
    print(f"{N_FRAMES} frames, {n_gt} ground-truth boxes, {n_tr} tracker boxes")
    for convention in Convention:
        config = EvaluationConfig(gating=Gating.IOU, convention=convention)
        selections = [
            select_frame(i, g, t, Gating.IOU, 0.5, 0.0)
            for i, (g, t) in enumerate(zip(gts, tracks, strict=True))
        ]
        full = best_of(lambda c=config: evaluate_sequence(gts, tracks, c))
        core = best_of(lambda c=config, s=selections: score_selections(s, c))
        print(f"ours ({convention.value}): {full:.3f} s CPU from objects, {core:.3f} s from frames")
    gt_map: dict[int, int] = {}
    tr_map: dict[int, int] = {}
    data = {
        "num_timesteps": N_FRAMES,
        "gt_ids": [np.array([gt_map.setdefault(o.object_id, len(gt_map)) for o in g]) for g in gts],
        "tracker_ids": [
            np.array([tr_map.setdefault(t.track_id, len(tr_map)) for t in f]) for f in tracks
        ],
        "similarity_scores": [
            iou_matrix([o.box2d.as_tuple() for o in g], [t.box2d.as_tuple() for t in f])  # type: ignore[union-attr]
            for g, f in zip(gts, tracks, strict=True)
        ],
        "num_gt_dets": n_gt,
        "num_tracker_dets": n_tr,
    }
    data["num_gt_ids"], data["num_tracker_ids"] = len(gt_map), len(tr_map)
    metrics = [CLEAR({"PRINT_CONFIG": False}), Identity({"PRINT_CONFIG": False}), HOTA()]
    reference = best_of(lambda: [m.eval_sequence(data) for m in metrics])
    print(f"TrackEval CLEAR + Identity + HOTA: {reference:.3f} s CPU (IoU matrices precomputed)")


if __name__ == "__main__":
    main()
