"""MOT17 files end to end against TrackEval's own MOTChallenge loader and preprocessing.

Random crowded sequences with every ground-truth kind (scored pedestrians, the
distractor classes, other classes, pedestrians with consider flag 0) are written
as MOTChallenge text; TrackEval's ``MotChallenge2DBox`` reads and preprocesses them
(distractor matching included) and its CLEAR/Identity/HOTA score them; we read the
same files with :mod:`rgbd_eval.io.tracks` and must agree exactly.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from trackeval_parity import assert_counts_equal_trackeval

from rgbd_eval.config import Convention, EvaluationConfig, Gating
from rgbd_eval.io.tracks import align, read_mot_gt, read_mot_tracks
from rgbd_eval.metrics import evaluate_sequence

datasets = pytest.importorskip("trackeval.datasets")

N_FRAMES = 30
# Pedestrian (1) most often; person on vehicle 2, car 3, static person 7, distractor 8,
# reflection 12.
CLASSES = [1, 1, 1, 1, 2, 3, 7, 8, 12]


def _write_sequence(root: Path, seed: int) -> tuple[Path, Path]:
    rng = np.random.default_rng(seed)
    gt_rows, tr_rows = [], []
    for f in range(1, N_FRAMES + 1):
        ids = rng.choice(12, size=rng.integers(0, 9), replace=False) + 1
        for oid in ids:
            x, y = rng.integers(0, 60), rng.integers(0, 4)
            cls = CLASSES[int(oid) % len(CLASSES)]
            consider = 0 if rng.random() < 0.1 else 1
            gt_rows.append(f"{f},{oid},{x},{y},20,40,{consider},{cls},{rng.random():.2f}")
        for tid in rng.choice(15, size=rng.integers(0, 9), replace=False) + 1:
            x, y = rng.integers(0, 60), rng.integers(0, 4)
            tr_rows.append(f"{f},{tid},{x},{y},{rng.integers(18, 23)},40,1,-1,-1,-1")
    gt = root / "gt" / "SEQ" / "gt" / "gt.txt"
    gt.parent.mkdir(parents=True)
    gt.write_text("\n".join(gt_rows) + "\n")
    tracks = root / "trackers" / "t" / "data" / "SEQ.txt"
    tracks.parent.mkdir(parents=True)
    tracks.write_text("\n".join(tr_rows) + "\n")
    return gt, tracks


@pytest.mark.parametrize("seed", range(12))
def test_mot17_files_equal_trackeval(tmp_path: Path, seed: int) -> None:
    gt_path, tracks_path = _write_sequence(tmp_path, seed)
    dataset = datasets.MotChallenge2DBox(
        {
            "GT_FOLDER": str(tmp_path / "gt"),
            "TRACKERS_FOLDER": str(tmp_path / "trackers"),
            "BENCHMARK": "MOT17",
            "TRACKERS_TO_EVAL": ["t"],
            "SEQ_INFO": {"SEQ": N_FRAMES},
            "SKIP_SPLIT_FOL": True,
            "PRINT_CONFIG": False,
        }
    )
    data = dataset.get_preprocessed_seq_data(dataset.get_raw_seq_data("t", "SEQ"), "pedestrian")
    aligned = align(read_mot_gt(gt_path), read_mot_tracks(tracks_path), 0, N_FRAMES)
    config = EvaluationConfig(gating=Gating.IOU, convention=Convention.MOTCHALLENGE)
    c = evaluate_sequence(aligned.gt, aligned.tracks, config).counts
    assert_counts_equal_trackeval(c, data)
