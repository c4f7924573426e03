"""Parity with TrackEval (the ``motchallenge`` convention) on random sequences.

The reference is PyPI's ``trackeval`` 1.3.0 (a packaging of Luiten's TrackEval; its
``CLEAR``, ``HOTA`` and ``Identity`` ``eval_sequence`` bodies were compared line by
line with github.com/JonathonLuiten/TrackEval and are the same algorithm). It is
installed without its dependencies (opencv-python would shadow our headless
OpenCV); see the Makefile. Its metrics get exactly the similarity matrices we
score, so any difference is in the matching and counting.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from metrics_builders import gt, track

from rgbd_eval.config import Convention, EvaluationConfig, Gating
from rgbd_eval.metrics import evaluate_sequence
from rgbd_eval.metrics.gating import iou_matrix
from rgbd_eval.types import GroundTruthObject, TrackOutput

trackeval = pytest.importorskip("trackeval.metrics")

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


def _trackeval_data(
    gts: list[list[GroundTruthObject]], tracks: list[list[TrackOutput]], gating: Gating
) -> dict[str, object]:
    """TrackEval's per-sequence ``data`` dict, ids relabelled densely as its datasets do."""
    gt_map: dict[int, int] = {}
    tr_map: dict[int, int] = {}
    gt_ids, tr_ids, sims = [], [], []
    for frame_gt, frame_tr in zip(gts, tracks, strict=True):
        gt_ids.append(
            np.array([gt_map.setdefault(g.object_id, len(gt_map)) for g in frame_gt], dtype=int)
        )
        tr_ids.append(
            np.array([tr_map.setdefault(t.track_id, len(tr_map)) for t in frame_tr], dtype=int)
        )
        if gating is Gating.IOU:
            a = np.array([g.box2d.as_tuple() for g in frame_gt if g.box2d]).reshape(-1, 4)
            b = np.array([t.box2d.as_tuple() for t in frame_tr if t.box2d]).reshape(-1, 4)
            sims.append(iou_matrix(a, b))
        else:
            a = np.array([g.world_xyz[:2] for g in frame_gt if g.world_xyz]).reshape(-1, 2)
            b = np.array([(t.x, t.y) for t in frame_tr]).reshape(-1, 2)
            # TrackEval's _calculate_euclidean_similarity with its default zero distance 2 m.
            dist = np.linalg.norm(a[:, None] - b[None, :], axis=2)
            sims.append(np.maximum(0, 1 - dist / 2.0))
    return {
        "num_timesteps": len(gts),
        "num_gt_ids": len(gt_map),
        "num_tracker_ids": len(tr_map),
        "num_gt_dets": sum(len(f) for f in gts),
        "num_tracker_dets": sum(len(f) for f in tracks),
        "gt_ids": gt_ids,
        "tracker_ids": tr_ids,
        "similarity_scores": sims,
    }


@pytest.mark.parametrize("gating", list(Gating))
@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=sequences())
def test_counts_equal_trackeval(gating: Gating, data: Frames) -> None:
    gts, tracks = data
    config = EvaluationConfig(gating=gating, convention=Convention.MOTCHALLENGE)
    c = evaluate_sequence(gts, tracks, config).counts
    ref_data = _trackeval_data(gts, tracks, gating)
    clear = trackeval.CLEAR({"PRINT_CONFIG": False}).eval_sequence(ref_data)
    ident = trackeval.Identity({"PRINT_CONFIG": False}).eval_sequence(ref_data)
    hota = trackeval.HOTA().eval_sequence(ref_data)
    assert c.num_matches == clear["CLR_TP"]
    assert c.fn == clear["CLR_FN"]
    assert c.fp == clear["CLR_FP"]
    assert c.id_switches == clear["IDSW"]
    assert (c.mostly_tracked, c.partly_tracked, c.mostly_lost) == (
        clear["MT"],
        clear["PT"],
        clear["ML"],
    )
    assert c.fragmentations == clear["Frag"]
    assert (c.idtp, c.idfn, c.idfp) == (ident["IDTP"], ident["IDFN"], ident["IDFP"])
    if gating is Gating.IOU:  # MOTP sums IoU; under metric gating it sums metres instead
        assert c.similarity_sum == pytest.approx(clear["MOTP_sum"], abs=1e-9)
    assert list(c.hota.tp) == list(hota["HOTA_TP"])
    assert list(c.hota.fn) == list(hota["HOTA_FN"])
    assert list(c.hota.fp) == list(hota["HOTA_FP"])
    ours = c.hota.summary()
    if ours["hota"] is not None:
        assert ours["hota"] == pytest.approx(float(np.mean(hota["HOTA"])), abs=1e-12)
        assert ours["deta"] == pytest.approx(float(np.mean(hota["DetA"])), abs=1e-12)
        assert ours["assa"] == pytest.approx(float(np.mean(hota["AssA"])), abs=1e-12)
        assert ours["loca"] == pytest.approx(float(np.mean(hota["LocA"])), abs=1e-12)


def test_iou_equals_trackeval_boxes() -> None:
    from trackeval.datasets._base_dataset import _BaseDataset

    rng = np.random.default_rng(0)
    a = rng.uniform(0, 50, (20, 4))
    b = rng.uniform(0, 50, (30, 4))
    ref = _BaseDataset._calculate_box_ious(a.copy(), b.copy(), box_format="xywh")
    assert np.array_equal(iou_matrix(a, b), ref)  # bit for bit
