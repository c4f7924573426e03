"""Parity on real data: TUD-Campus and TUD-Stadtmitte as shipped in the motmetrics 1.4 wheel.

``motmetrics`` convention: the expected values are those stated by motmetrics'
own ``tests/test_metrics.py::test_motchallenge_files`` (IoU gate 0.5, tolerance
1e-3 there; counts must be equal here). ``motchallenge`` convention: TrackEval's
metrics on the same files.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from trackeval_parity import assert_counts_equal_trackeval, trackeval_data

from rgbd_eval.config import Convention, EvaluationConfig, Gating
from rgbd_eval.io.tracks import align, read_mot_gt, read_mot_tracks
from rgbd_eval.metrics import Counts, evaluate_sequence, summarize, total

mm = pytest.importorskip("motmetrics")
DATA = Path(mm.__file__).parent / "data"

# motmetrics' test_motchallenge_files: idf1, idp, idr, recall, precision, GT tracks, MT, PT,
# ML, FP, FN, IDsw, Frag, MOTA, MOTP (mean 1 - IoU), per sequence and overall.
EXPECTED = {
    "TUD-Campus": (
        0.557659,
        0.729730,
        0.451253,
        0.582173,
        0.941441,
        8,
        1,
        6,
        1,
        13,
        150,
        7,
        7,
        0.526462,
        0.277201,
    ),
    "TUD-Stadtmitte": (
        0.644619,
        0.819760,
        0.531142,
        0.608997,
        0.939920,
        10,
        5,
        4,
        1,
        45,
        452,
        7,
        6,
        0.564014,
        0.345904,
    ),
    "overall": (
        0.624296,
        0.799176,
        0.512211,
        0.602640,
        0.940268,
        18,
        6,
        10,
        2,
        58,
        602,
        14,
        13,
        0.555116,
        0.330177,
    ),
}


def _score(name: str, convention: Convention) -> Counts:
    gt = read_mot_gt(DATA / name / "gt.txt")
    tracks = read_mot_tracks(DATA / name / "test.txt")
    aligned = align(gt, tracks, max_gap_ns=0)
    config = EvaluationConfig(gating=Gating.IOU, threshold=0.5, convention=convention)
    return evaluate_sequence(aligned.gt, aligned.tracks, config).counts


@pytest.mark.parametrize("name", list(EXPECTED))
def test_tud_equals_motmetrics_expected_values(name: str) -> None:
    if name == "overall":
        c = total(_score(n, Convention.MOTMETRICS) for n in ("TUD-Campus", "TUD-Stadtmitte"))
    else:
        c = _score(name, Convention.MOTMETRICS)
    s = summarize(c)
    idf1, idp, idr, recall, precision, n_gt, mt, pt, ml, fp, fn, idsw, frag, mota, motp = EXPECTED[
        name
    ]
    assert (c.num_gt_tracks, c.mostly_tracked, c.partly_tracked, c.mostly_lost) == (
        n_gt,
        mt,
        pt,
        ml,
    )
    assert (c.fp, c.fn, c.id_switches, c.fragmentations) == (fp, fn, idsw, frag)
    for ours, theirs in (
        (s["idf1"], idf1),
        (s["idp"], idp),
        (s["idr"], idr),
        (s["all_tr"], recall),
        (s["precision"], precision),
        (s["mota"], mota),
        (1.0 - float(s["motp"] or 0.0), motp),  # ours is mean IoU, theirs mean 1 - IoU
    ):
        assert ours == pytest.approx(theirs, abs=1e-6)


@pytest.mark.parametrize("name", ["TUD-Campus", "TUD-Stadtmitte"])
def test_tud_equals_trackeval(name: str) -> None:
    pytest.importorskip("trackeval.metrics")
    gt = read_mot_gt(DATA / name / "gt.txt")
    tracks = read_mot_tracks(DATA / name / "test.txt")
    aligned = align(gt, tracks, max_gap_ns=0)
    c = _score(name, Convention.MOTCHALLENGE)
    assert_counts_equal_trackeval(c, trackeval_data(aligned.gt, aligned.tracks, Gating.IOU))
