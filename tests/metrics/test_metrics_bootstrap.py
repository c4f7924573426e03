"""The block bootstrap: its variance against the known one, determinism, exact replicates."""

from __future__ import annotations

import io
import math
import zipfile
from pathlib import Path

import numpy as np
import pytest
from metrics_builders import gt, track
from scipy.optimize import linear_sum_assignment

from rgbd_eval.config import EvaluationConfig
from rgbd_eval.io.tracks import align, read_mot_gt, read_mot_tracks
from rgbd_eval.metrics import bootstrap as boot
from rgbd_eval.metrics import evaluate_sequence, summarize
from rgbd_eval.metrics.frames import FrameTable
from rgbd_eval.metrics.hota import ALPHAS

PEOPLE = 10


def _table(misses: np.ndarray) -> FrameTable:
    """A sequence of ``len(misses)`` frames with 10 people each, ``misses[f]`` of them missed
    in frame f (the others matched by a track of their own id; no false positive)."""
    gts, tracks = [], []
    for missed in misses.tolist():
        boxes = [(30.0 * k, 0.0, 10.0, 10.0) for k in range(PEOPLE)]
        gts.append([gt(k, box) for k, box in enumerate(boxes)])
        tracks.append([track(k, box) for k, box in enumerate(boxes) if k >= missed])
    return evaluate_sequence(gts, tracks, EvaluationConfig()).table


def _known_variance(x: np.ndarray, block: int) -> float:
    """The circular block bootstrap's variance of the mean of ``x`` (n a multiple of
    ``block``): ``(1/n) sum_{|h|<L} (1 - |h|/L) c(h)``, ``c`` the circular autocovariance."""
    n = len(x)
    d = x - x.mean()
    c = [float(np.mean(d * np.roll(d, -h))) for h in range(block)]
    return (c[0] + 2 * sum((1 - h / block) * c[h] for h in range(1, block))) / n


def _fn_rate_variance(table: FrameTable, block: int) -> float:
    reps = boot.replicates(table, "synthetic", count=4000, block=block)
    return float(np.var(boot.replicate_metrics(reps)["fn_rate"]))


def test_independent_frames_the_variance_of_the_ordinary_bootstrap() -> None:
    rng = np.random.default_rng(1)
    misses = rng.binomial(PEOPLE, 0.3, size=400)
    # FN rate = mean over frames of misses / 10 (10 people per frame): with blocks of one
    # frame the bootstrap's variance is the sample variance over n, here about 5.2e-5.
    known = _known_variance(misses / PEOPLE, 1)
    assert known == pytest.approx(np.var(misses / PEOPLE) / 400)
    assert _fn_rate_variance(_table(misses), 1) == pytest.approx(known, rel=0.1)


def test_correlated_frames_need_blocks() -> None:
    rng = np.random.default_rng(2)
    # Runs of 20 frames with the same number of misses: strongly correlated frames.
    misses = np.repeat(rng.binomial(PEOPLE, 0.3, size=20), 20)
    table = _table(misses)
    blocked = _fn_rate_variance(table, 20)
    assert blocked == pytest.approx(_known_variance(misses / PEOPLE, 20), rel=0.1)
    # One-frame blocks take the frames as independent: far too small an interval.
    assert _fn_rate_variance(table, 1) < 0.2 * blocked
    # The automatic rule sees the correlation; white noise gets short blocks.
    assert boot.block_length(misses) >= 10
    assert boot.block_length(rng.binomial(PEOPLE, 0.3, size=400)) <= 3


def test_weights_resample_every_frame_count() -> None:
    rng = np.random.default_rng(3)
    for n, block in ((150, 19), (71, 6), (10, 3), (5, 5), (7, 1)):
        w = boot.weights(n, block, 40, rng)
        assert w.shape == (40, n) and (w.sum(axis=1) == n).all()
    # Circular blocks of 5 of 10 frames starting at 8 (frames 8, 9, 0, 1, 2: wrapped) and 0.
    starts = np.array([[8, 0]])
    assert boot._weights(10, 5, starts).tolist() == [[2, 2, 2, 1, 1, 0, 0, 0, 1, 1]]
    # Against counting frame by frame: blocks that wrap, the last one cut to n frames.
    for n, block in ((150, 19), (71, 6), (10, 3), (7, 7), (9, 1), (13, 4)):
        starts = rng.integers(0, n, size=(30, -(-n // block)))
        counted = np.zeros((30, n))
        for r, row in enumerate(starts.tolist()):
            frames = [(s + j) % n for s in row for j in range(block)][:n]
            np.add.at(counted[r], frames, 1)
        assert (boot._weights(n, block, starts) == counted).all(), (n, block)


TUD = Path(pytest.importorskip("motmetrics").__file__).parent / "data"


def _tud(name: str) -> tuple[FrameTable, dict]:
    aligned = align(read_mot_gt(TUD / name / "gt.txt"), read_mot_tracks(TUD / name / "test.txt"), 0)
    scores = evaluate_sequence(aligned.gt, aligned.tracks, EvaluationConfig())
    return scores.table, summarize(scores.counts)


@pytest.mark.parametrize("name", ["TUD-Campus", "TUD-Stadtmitte"])
def test_a_replicate_of_every_frame_once_is_the_score(name: str) -> None:
    table, summary = _tud(name)
    sums = boot._SequenceSums(table, {})
    # One block of every frame, from frame 0: each frame once, summed both ways.
    whole = np.zeros((1, 1), dtype=np.int64)
    for by_blocks in (False, True):
        part = sums.chunk(whole, table.num_frames, by_blocks)
        one = boot._assemble(sums.columns, [part], 1, (1,))
        # IDF1's assignment and HOTA's association recomputed from the per-frame table give
        # the scorer's values: integers exactly, the MOTP similarity sum to the last bits.
        for metric, values in boot.replicate_metrics(one).items():
            assert values[0] == pytest.approx(summary[metric], abs=1e-12), metric


@pytest.mark.parametrize("name", ["TUD-Campus", "TUD-Stadtmitte"])
def test_replicates_summed_by_frame_weights_or_by_blocks_are_the_same(name: str) -> None:
    table, _ = _tud(name)
    sums = boot._SequenceSums(table, {"errors": boot.frame_errors(table)})
    rng = np.random.default_rng(6)
    for block in (1, 5, 18, table.num_frames):
        starts = boot._draw_starts(table.num_frames, block, 60, rng)
        weighted = sums.chunk(starts, block, by_blocks=False)
        blocked = sums.chunk(starts, block, by_blocks=True)
        for a, b in zip(weighted, blocked, strict=True):
            assert np.array_equal(a, b), block  # integer sums, and one similarity sum


def _hand_made() -> tuple[list, list]:
    """12 frames, unambiguous (each person with at most one track in the gate, people 30 px
    apart): person 0 tracked by 10 then by 11 from frame 6 (IDF1 must choose), person 1 by
    20 but missed in frames 3-4, person 2 (frames 2-9) by 30 with a box shifted 1 px per
    frame (HOTA's levels differ), a false positive 40 in frames 8-9, and persons 3 and 4
    whose tracks 50 and 51 swap from frame 7 (IDF1's assignment of a 2 x 2 part: a
    replicate with more late frames assigns them the other way)."""
    gts, tracks = [], []
    for f in range(12):
        people = [gt(0, (0.0, 0.0, 10.0, 10.0)), gt(1, (30.0, 0.0, 10.0, 10.0))]
        outs = [track(10 if f < 6 else 11, (0.0, 0.0, 10.0, 10.0))]
        if f not in (3, 4):
            outs.append(track(20, (31.0, 0.0, 10.0, 10.0)))
        if 2 <= f <= 9:
            people.append(gt(2, (60.0, 0.0, 10.0, 10.0)))
            outs.append(track(30, (60.0 + (f - 2) * 0.5, 0.0, 10.0, 10.0)))
        if f in (8, 9):
            outs.append(track(40, (200.0, 0.0, 10.0, 10.0)))
        people += [gt(3, (90.0, 0.0, 10.0, 10.0)), gt(4, (120.0, 0.0, 10.0, 10.0))]
        swapped = f >= 7
        outs.append(track(51 if swapped else 50, (90.0, 0.0, 10.0, 10.0)))
        outs.append(track(50 if swapped else 51, (120.0, 0.0, 10.0, 10.0)))
        gts.append(people)
        tracks.append(outs)
    return gts, tracks


#: Metrics of a replicate that do not depend on the order of its frames: re-scoring the
#: resampled frames gives them exactly when every frame's matching is unambiguous. ID
#: switches, recall errors and so MOTA are taken from the full sequence (the module
#: docstring says why).
ORDER_FREE = ("fp_rate", "fn_rate", "all_tr", "main_tr", "idf1", "hota", "deta", "assa", "motp")


def test_replicates_equal_rescoring_the_resampled_frames() -> None:
    gts, tracks = _hand_made()
    table = evaluate_sequence(gts, tracks, EvaluationConfig()).table
    n = table.num_frames
    sums = boot._SequenceSums(table, {})
    rng = np.random.default_rng(8)
    for block in (1, 4, 5, 12):
        starts = boot._draw_starts(n, block, 25, rng)
        for by_blocks in (False, True):
            part = sums.chunk(starts, block, by_blocks)
            got = boot.replicate_metrics(boot._assemble(sums.columns, [part], 25, (block,)))
            for r, row in enumerate(starts.tolist()):
                # The replicate literally: its blocks' frames glued together, scored anew.
                frames = [(s + j) % n for s in row for j in range(block)][:n]
                scores = evaluate_sequence(
                    [gts[f] for f in frames], [tracks[f] for f in frames], EvaluationConfig()
                )
                brute = summarize(scores.counts)
                for metric in ORDER_FREE:
                    assert got[metric][r] == pytest.approx(brute[metric], abs=1e-12), metric
                # What is conditioned on: each frame's switches as in the full sequence.
                switches = table.per_frame(table.match_frame[table.match_switch])
                assert got["id_switches"][r] == switches[frames].sum()


def test_intervals_are_deterministic_for_a_seed() -> None:
    table, summary = _tud("TUD-Campus")
    first = boot.intervals(boot.replicates(table, "TUD-Campus"))
    assert boot.intervals(boot.replicates(table, "TUD-Campus")) == first
    other = boot.intervals(boot.replicates(table, "TUD-Campus", seed=7))
    assert other != first
    lo, hi = first["mota"] or (0.0, 0.0)
    assert lo < float(summary["mota"] or 0.0) < hi


def test_small_assignments_tried_in_full_equal_the_hungarian() -> None:
    rng = np.random.default_rng(4)
    rows = np.repeat(np.arange(3), 4)
    cols = np.tile(np.arange(4), 3)
    part = boot._AssignmentPart(np.arange(12), rows, cols)
    assert part.matchings is not None  # 4 * 3 * 2 = 24 assignments, tried at once
    assert part.matchings.shape == (24, 12)
    counts = rng.integers(0, 30, size=(12, 200)).astype(float)
    tried = part.best(counts)
    part.matchings = None  # the Hungarian path
    assert (part.best(counts) == tried).all()


def test_sparse_parts_are_tried_in_full_and_equal_the_hungarian() -> None:
    """A sparse part: its maximal matchings, far fewer than the assignments of its shape,
    give the Hungarian's totals (zero counts included: a pair seen in no resampled frame)."""
    rng = np.random.default_rng(5)
    # Rows 0..5 to columns 0..9: a chain (r, r), (r, r + 1) and a few more edges.
    edges = [(r, r) for r in range(6)] + [(r, r + 1) for r in range(6)] + [(0, 9), (5, 8)]
    rows = np.array([r for r, _ in edges])
    cols = np.array([c for _, c in edges])
    part = boot._AssignmentPart(np.arange(len(edges)), rows, cols)
    assert part.matchings is not None and len(part.matchings) < math.perm(10, 6)
    # Each a matching (one edge per row and per column at most), none a subset of another.
    for m in part.matchings.astype(bool):
        assert len(set(rows[m])) == len(set(cols[m])) == m.sum()
    counts = rng.integers(0, 4, size=(len(edges), 300)).astype(float)
    tried = part.best(counts)
    part.matchings = None
    assert (part.best(counts) == tried).all()
    # A dense part has too many: the Hungarian.
    dense_rows, dense_cols = np.repeat(np.arange(8), 12), np.tile(np.arange(12), 8)
    assert boot.maximal_matchings(dense_rows, dense_cols, 8) is None


def test_the_frame_table_saves_and_loads() -> None:
    table, _ = _tud("TUD-Stadtmitte")
    back = FrameTable.load(table.save())
    for name in ("gt_frame", "match_value", "match_switch", "hota_similarity", "track_ids"):
        assert np.array_equal(getattr(back, name), getattr(table, name))
    with pytest.raises(ValueError, match="not a frames table"):
        FrameTable.load(b"not a zip")


def test_the_saved_table_is_what_numpy_savez_writes() -> None:
    """``save`` writes the ZIP itself: the same bytes as ``numpy.savez`` of its arrays (the
    sha256 in ``report.json`` is unchanged), a valid ZIP that ``numpy.load`` reads."""
    table, _ = _tud("TUD-Campus")
    data = table.save()
    with np.load(io.BytesIO(data), allow_pickle=False) as npz:
        arrays = {name: npz[name] for name in npz.files}
    assert list(arrays)[:3] == ["schema", "num_frames", "gt_ids"]
    again = io.BytesIO()
    np.savez(again, **arrays)
    assert again.getvalue() == data
    with zipfile.ZipFile(io.BytesIO(data)) as z:
        assert z.testzip() is None  # every entry's CRC holds


def test_intervals_of_many_series_equal_each_ones_interval() -> None:
    """Partitioned (series without NaN) or sorted (with NaN), the ends are the order
    statistics of :func:`interval`, ties and all-NaN series included."""
    rng = np.random.default_rng(9)
    values = {
        "spread": rng.normal(size=1000),
        "ties": rng.integers(0, 3, size=1000).astype(float),
        "some_nan": np.where(rng.random(1000) < 0.3, np.nan, rng.normal(size=1000)),
        "all_nan": np.full(1000, np.nan),
        "constant": np.full(1000, 0.25),
    }
    assert boot.intervals_of(values) == {k: boot.interval(v) for k, v in values.items()}
    short = {k: v[:37] for k, v in values.items()}
    assert boot.intervals_of(short) == {k: boot.interval(v) for k, v in short.items()}


def _straightforward(
    table: FrameTable, w: np.ndarray, extra: dict[str, np.ndarray]
) -> tuple[np.ndarray, float, float, np.ndarray]:
    """One replicate of frame weights ``w``, from the table event by event: the integer
    columns, Main Tr.'s and IDF1's true positives (a Hungarian assignment on the weighted
    pair counts) and HOTA's association sums, each pair's term ``A^2 / max(1, G + T - A)``
    added in the order of the pairs (ground-truth index, then track index)."""
    t = table
    levels = t.hota_levels()
    ints = [
        w[t.gt_frame].sum(),
        w[t.track_frame].sum(),
        w[t.match_frame].sum(),
        w[t.match_frame[t.match_switch]].sum(),
        w[t.match_frame[t.match_recall]].sum(),
        *(w[t.hota_frame[levels > a]].sum() for a in range(len(ALPHAS))),
        *((w * series).sum() for series in extra.values()),
    ]
    main = np.zeros((t.num_gt_tracks, t.num_tracks))
    np.add.at(main, (t.match_gt, t.match_track), w[t.match_frame])
    gate = np.zeros((t.num_gt_tracks, t.num_tracks))
    np.add.at(gate, (t.potential_gt, t.potential_track), w[t.potential_frame])
    picked = linear_sum_assignment(gate, maximize=True)
    gt_count = np.bincount(t.gt_index, weights=w[t.gt_frame], minlength=t.num_gt_tracks)
    track_count = np.bincount(t.track_index, weights=w[t.track_frame], minlength=t.num_tracks)
    pairs = sorted(set(zip(t.hota_gt.tolist(), t.hota_track.tolist(), strict=True)))
    ass = np.zeros(len(ALPHAS))
    for a in range(len(ALPHAS)):
        total = 0.0
        for g, k in pairs:
            rows = (t.hota_gt == g) & (t.hota_track == k) & (levels > a)
            reach = w[t.hota_frame[rows]].sum()
            total += reach * reach / max(1.0, gt_count[g] + track_count[k] - reach)
        ass[a] = total
    return np.array(ints), main.max(axis=1).sum(), gate[picked].sum(), ass


@pytest.mark.parametrize("case", ["hand-made", "TUD-Campus"])
def test_the_compiled_replicate_sums_equal_the_straightforward_ones(case: str) -> None:
    """The kernel behind :meth:`_SequenceSums.chunk` (blocks summed, IDF1's parts tried
    over their matchings or left to the Hungarian, HOTA's association in place) gives each
    replicate's sums to the last bit of the straightforward computation, both ways of
    summing, the Hungarian forced on every part too."""
    if case == "hand-made":
        gts, tracks = _hand_made()
        table = evaluate_sequence(gts, tracks, EvaluationConfig()).table
    else:
        table, _ = _tud(case)
    n = table.num_frames
    extra = {"errors": boot.frame_errors(table), "none": np.zeros(n, dtype=np.int64)}
    sums = boot._SequenceSums(table, extra)
    hungarian = boot._SequenceSums(table, extra)
    for part in hungarian.id_parts:
        part.options = part.matchings = None
    hungarian._layout, hungarian._hungarian = hungarian._kernel_layout()
    assert hungarian._hungarian == [k for k, p in enumerate(hungarian.id_parts) if p.shape[0] > 1]
    rng = np.random.default_rng(10)
    for block in (1, 4, n):
        starts = boot._draw_starts(n, block, 20, rng)
        weights = boot._weights(n, block, starts)
        for solver, by_blocks in ((sums, True), (sums, False), (hungarian, True)):
            ints, _, main_tr, idtp, ass = solver.chunk(starts, block, by_blocks)
            for r, w in enumerate(weights):
                want = _straightforward(table, w, extra)
                assert ints[r].tolist() == want[0].tolist()
                assert (main_tr[r], idtp[r]) == (want[1], want[2])
                assert ass[r].tolist() == want[3].tolist()
