"""TrackEval as the reference: its per-sequence input and the comparison of our counts with its metrics."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pytest

from rgbd_eval.config import Gating
from rgbd_eval.metrics import Counts
from rgbd_eval.metrics.gating import iou_matrix
from rgbd_eval.types import GroundTruthObject, TrackOutput


def trackeval_data(
    gts: Sequence[Sequence[GroundTruthObject]],
    tracks: Sequence[Sequence[TrackOutput]],
    gating: Gating,
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


def assert_counts_equal_trackeval(
    c: Counts, data: Mapping[str, object], *, similarity_is_iou: bool = True
) -> None:
    """Our counts equal TrackEval's CLEAR, Identity and HOTA on the same sequence ``data``.

    ``similarity_is_iou`` is False under metric gating, where our MOTP sums metres and
    TrackEval's sums its distance-based similarity.
    """
    te = pytest.importorskip("trackeval.metrics")
    clear = te.CLEAR({"PRINT_CONFIG": False}).eval_sequence(data)
    ident = te.Identity({"PRINT_CONFIG": False}).eval_sequence(data)
    hota = te.HOTA().eval_sequence(data)
    assert (c.num_gt, c.num_tracks) == (data["num_gt_dets"], data["num_tracker_dets"])
    assert (c.num_matches, c.fp, c.fn, c.id_switches) == (
        clear["CLR_TP"],
        clear["CLR_FP"],
        clear["CLR_FN"],
        clear["IDSW"],
    )
    assert (c.mostly_tracked, c.partly_tracked, c.mostly_lost, c.fragmentations) == (
        clear["MT"],
        clear["PT"],
        clear["ML"],
        clear["Frag"],
    )
    assert (c.idtp, c.idfn, c.idfp) == (ident["IDTP"], ident["IDFN"], ident["IDFP"])
    if similarity_is_iou:
        assert c.similarity_sum == pytest.approx(clear["MOTP_sum"], abs=1e-9)
    assert list(c.hota.tp) == list(hota["HOTA_TP"])
    assert list(c.hota.fn) == list(hota["HOTA_FN"])
    assert list(c.hota.fp) == list(hota["HOTA_FP"])
    ours = c.hota.summary()
    if ours["hota"] is not None:
        for key, name in (("hota", "HOTA"), ("deta", "DetA"), ("assa", "AssA"), ("loca", "LocA")):
            assert ours[key] == pytest.approx(float(np.mean(hota[name])), abs=1e-12)
