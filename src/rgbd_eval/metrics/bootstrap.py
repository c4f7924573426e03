"""95 % intervals by a circular block bootstrap over frames, and the paired bootstrap of ``compare``.

Frames of a tracking sequence are not independent (a person missed in one frame is
likely missed in the next), so a replicate resamples *blocks* of consecutive frames:
the circular block bootstrap (Politis & Romano 1992) draws ``ceil(n / L)`` block starts
uniformly from the ``n`` frames, takes ``L`` frames from each (wrapping at the end) and
keeps the first ``n``. A replicate is then a weight per frame (how often it was drawn),
and every summable count of the replicate is the weighted sum of the per-frame
contributions recorded by the scorer (:class:`~rgbd_eval.metrics.frames.FrameTable`).
IDF1 and HOTA have a global step, solved again for every replicate: IDF1's id assignment
on the replicate's weighted gate-pair counts (exactly: the Hungarian algorithm, or all
maximal matchings of a sparse part, :class:`_AssignmentPart`), Main Tr.'s best track per
person, and HOTA's association (its alignment of ids over the sequence) from the weighted
pair, ground-truth and track counts. The ratios of a replicate come from its
sums by :func:`replicate_metrics`, the formulas of
:func:`rgbd_eval.metrics.counts.summarize`; the interval is the 2.5th and 97.5th
percentile of the replicates (the order statistics, no interpolation).

What a replicate takes from the full sequence (is conditioned on): each frame's CLEAR
matching with its ID-switch and recall-error flags, and HOTA's per-frame pairs. Scoring
the glued blocks anew would run the CLEAR matching across every seam between blocks,
frames that are not consecutive: a switch would appear at each seam that the tracker
never made, and a match kept from "the previous frame" would be one of another moment,
artefacts of the resampling rather than of the tracker. Keeping what the tracker's real
history gave each frame resamples the frames' contributions, whose correlation the
blocks keep; this is the usual way to block-bootstrap a statistic with a sequential step.
HOTA's per-frame pairs would move only where a frame is ambiguous (two candidates whose
global association scores change with the replicate). Where every frame's matching is
unambiguous, a replicate equals scoring its resampled frames anew exactly in every metric
but ID switches, recall errors and MOTA (tested: ``test_replicates_equal_rescoring_the_
resampled_frames``); those three count the full sequence's switches in the frames drawn.

Block length ``L``: chosen per sequence from its series of errors per frame (FN + FP +
ID switches, the numerator of MOTA) by the automatic rule of Politis & White (2004, with
the correction of Patton, Politis & White 2009) for the circular block bootstrap, at
least 1 and at most ``ceil(min(3 sqrt(n), n / 3))``; a series without correlation gives
``L = 1`` (the ordinary bootstrap). Several sequences: each is resampled on its own (its
blocks, its length) and a replicate of the overall row is the sum of the sequences'
replicates (a stratified bootstrap), ratios again from the sums.

Deterministic for a seed (:data:`DEFAULT_SEED`, ``evaluation.bootstrap_seed``): each
sequence draws from ``numpy.random.default_rng([seed, crc32(name)])`` (PCG64, integer
arithmetic). The sums are of integer counts (exact in float64, in any order, so the
sparse matrix products may use any order); the float sums, the similarity behind MOTP
and HOTA's association over its pairs, are added in a fixed order, never by BLAS (see
:mod:`rgbd_eval.exact`). A replicate's sums, Main Tr., IDF1's assignment (but for the
parts left to the Hungarian) and HOTA's association are one loop compiled with numba
(:func:`_replicate_stats`), without fast-math: nothing reordered or fused.

``compare``'s paired bootstrap draws one set of replicate weights per sequence and
applies it to both reports' tables (the same frames of the same sequence), so a
replicate of a metric's change is the change on the same resampled frames. The change is
outside its interval when 0 is not between the 2.5th and 97.5th percentiles.
"""

from __future__ import annotations

import math
import zlib
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field

import numba
import numpy as np
from numpy.lib.stride_tricks import sliding_window_view
from numpy.typing import NDArray
from scipy import sparse
from scipy.optimize import linear_sum_assignment

from rgbd_eval import exact
from rgbd_eval.metrics.frames import FloatArray, FrameTable, IntArray
from rgbd_eval.metrics.hota import ALPHAS

#: Replicates per interval (``evaluation.bootstrap_replicates``).
DEFAULT_REPLICATES = 1000
#: The seed of every interval (``evaluation.bootstrap_seed``) and of ``compare``'s bootstrap.
DEFAULT_SEED = 33
#: The coverage of every interval.
CONFIDENCE = 0.95
#: Frame weights summed at once at most (replicates x frames): small arrays stay in the
#: allocator's heap (large fresh ones cost page faults, more than the arithmetic).
GROUP_WEIGHTS = 1 << 16
#: The largest table of block counts (columns x 2 frames) prepared to sum replicates by
#: their blocks (:meth:`_SequenceSums.chunk`); larger tables sum the frame weights.
BLOCK_SUMS_MAX = 1 << 20

#: The metrics that get an interval: those :func:`replicate_metrics` derives.
INTERVAL_METRICS = (
    "mota",
    "motp",
    "fp_rate",
    "fn_rate",
    "id_switches",
    "recall_errors",
    "main_tr",
    "all_tr",
    "idf1",
    "hota",
    "deta",
    "assa",
)

_N_ALPHA = len(ALPHAS)
#: Frame-level integer columns of every replicate, before the caller's extra columns.
BASE_COLUMNS = (
    "num_gt",
    "num_tracks",
    "num_matches",
    "id_switches",
    "recall_errors",
    *(f"hota_tp_{a}" for a in range(_N_ALPHA)),
)


# ----------------------------------------------------------------------------- block length


def _sum(values: FloatArray) -> float:
    return float(np.add.reduce(values))


def block_length(series: NDArray[np.float64] | NDArray[np.int64]) -> int:
    """The circular block bootstrap's block length for ``series`` (see the module docstring)."""
    x = np.asarray(series, dtype=np.float64)
    n = len(x)
    if n < 4:
        return 1
    x = x - _sum(x) / n
    acv0 = _sum(x * x) / n
    if acv0 <= 0.0:
        return 1
    kn = max(5, len(str(n)) - 1)  # max(5, floor(log10 n)), without libm
    m_max = math.isqrt(n - 1) + 1 + kn  # ceil(sqrt n) + K_n
    m_max = min(m_max, n - 1)
    cv = 2.0 * math.sqrt(exact.log(float(n)) / exact.log(10.0) / n)
    acv = np.array([acv0] + [_sum(x[k:] * x[: n - k]) / n for k in range(1, m_max + 1)])
    small = np.abs(acv / acv0) < cv
    m_hat = None
    for m in range(0, m_max - kn + 1):
        if small[m + 1 : m + kn + 1].all():
            m_hat = m
            break
    big_m = m_max if m_hat is None else min(2 * max(m_hat, 1), m_max)
    g = 0.0
    lrv = acv0
    for k in range(1, big_m + 1):
        ratio = k / big_m
        lam = 1.0 if ratio <= 0.5 else 2.0 * (1.0 - ratio)
        g += 2.0 * lam * k * float(acv[k])
        lrv += 2.0 * lam * float(acv[k])
    if g == 0.0 or lrv <= 0.0:
        return 1
    d_cb = 4.0 / 3.0 * lrv * lrv
    length = exact.power(2.0 * g * g / d_cb, 1.0 / 3.0) * exact.power(float(n), 1.0 / 3.0)
    b_max = math.ceil(min(3.0 * math.sqrt(n), n / 3.0))
    return int(max(1, min(b_max, math.floor(length + 0.5))))


def frame_errors(table: FrameTable) -> IntArray:
    """FN + FP + ID switches of every frame (the series the block length is chosen on)."""
    gt = table.per_frame(table.gt_frame)
    tracks = table.per_frame(table.track_frame)
    matches = table.per_frame(table.match_frame)
    switches = table.per_frame(table.match_frame[table.match_switch])
    errors: IntArray = gt + tracks - 2 * matches + switches
    return errors


# ----------------------------------------------------------------------------- replicate weights


def sequence_rng(seed: int, name: str) -> np.random.Generator:
    """The generator of one sequence's replicates: PCG64 seeded by ``[seed, crc32(name)]``."""
    return np.random.default_rng([int(seed), zlib.crc32(name.encode("utf-8"))])


def _draw_starts(num_frames: int, block: int, count: int, rng: np.random.Generator) -> IntArray:
    """``count`` replicates' block starts ``(count, ceil(n / block))``."""
    return rng.integers(0, num_frames, size=(count, -(-num_frames // block)))


def _weights(num_frames: int, block: int, starts: IntArray) -> FloatArray:
    """Frame weights ``(replicates, frames)`` (integer-valued floats) of block starts: each
    block's frames (wrapping at the end), the first ``num_frames`` of a replicate, counted.

    A block adds 1 to its run of frames: +1 where it starts, -1 after it ends (a block
    that wraps also +1 at frame 0), summed along the frames."""
    n, (count, k) = num_frames, starts.shape
    ends = starts + block
    ends[:, -1] -= k * block - n  # the last block is cut to the first n frames
    wraps = ends > n
    width = n + 1
    offsets = np.arange(count, dtype=np.int64) * width
    up = np.concatenate([(starts + offsets[:, None]).ravel(), offsets[np.nonzero(wraps)[0]]])
    down = (np.where(wraps, ends - n, ends) + offsets[:, None]).ravel()
    size = count * width
    steps = np.bincount(up, minlength=size) - np.bincount(down, minlength=size)
    out: FloatArray = np.cumsum(steps.reshape(count, width)[:, :n], axis=1).astype(np.float64)
    return out


def weights(num_frames: int, block: int, count: int, rng: np.random.Generator) -> FloatArray:
    """``count`` replicates' frame weights ``(count, num_frames)`` (integer-valued floats)."""
    if num_frames == 0:
        return np.zeros((count, 0))
    block = max(1, min(block, num_frames))
    return _weights(num_frames, block, _draw_starts(num_frames, block, count, rng))


def start_chunks(
    num_frames: int, block: int, replicates: int, rng: np.random.Generator, width: int
) -> Iterator[IntArray]:
    """The replicates' block starts ``(replicates, ceil(n / block))``, in groups of about
    :data:`GROUP_WEIGHTS` values, ``width`` per replicate. They are drawn at once, in
    replicate order (a generator's integers come in the same order whatever the size of
    the draws: the grouping does not change them). ``0 < block <= num_frames``."""
    starts = _draw_starts(num_frames, block, replicates, rng)
    per_group = max(1, GROUP_WEIGHTS // max(width, 1))
    for done in range(0, replicates, per_group):
        yield starts[done : done + per_group]


def _window_sums(values: FloatArray, lengths: IntArray) -> FloatArray:
    """``(len(lengths) * n, columns)``: for each length L (``1 <= L <= n``), row ``s`` of its
    ``n`` rows holds the sums of the rows ``s .. s + L - 1`` of ``values`` ``(n, columns)``
    (wrapping). A running sum (compiled, :data:`_window_sums_kernel`): integer counts, exact."""
    n, width = values.shape
    out = np.empty((lengths.shape[0] * n, width))
    run = np.zeros(width)
    for k in range(lengths.shape[0]):
        run[:] = 0.0
        for f in range(lengths[k]):
            x = values[f]
            for c in range(width):
                run[c] += x[c]
        for start in range(n):
            out[k * n + start] = run
            x, y = values[(start + lengths[k]) % n], values[start]
            for c in range(width):
                run[c] += x[c] - y[c]
    return out


_window_sums_kernel: Callable[[FloatArray, IntArray], FloatArray] = numba.njit(cache=True)(
    _window_sums
)


# ----------------------------------------------------------------------------- replicate sums


@dataclass(frozen=True, eq=False)
class Replicates:
    """Summable sums of ``B`` replicates of one or more sequences.

    ``ints`` holds the frame-level integer counts ``(B, K)`` named by ``columns``;
    ``similarity`` the MOTP numerator, ``main_tr`` Main Tr.'s matches, ``idtp`` IDF1's
    identity true positives and ``hota_ass`` HOTA's association sums ``(B, 19)``.
    """

    columns: tuple[str, ...]
    ints: FloatArray
    similarity: FloatArray
    main_tr: FloatArray
    idtp: FloatArray
    hota_ass: FloatArray
    block_lengths: tuple[int, ...] = field(default=())
    _index: dict[str, int] = field(default_factory=dict, repr=False, compare=False)

    def column(self, name: str) -> FloatArray:
        """The replicates' sums of one frame-level column."""
        return self.ints[:, self._position(name)]

    def sums(self, names: Sequence[str]) -> FloatArray:
        """The replicates' sums of several frame-level columns ``(B, len(names))``."""
        return self.ints[:, [self._position(name) for name in names]]

    def _position(self, name: str) -> int:
        if not self._index:
            self._index.update((c, k) for k, c in enumerate(self.columns))
        return self._index[name]

    def __add__(self, other: Replicates) -> Replicates:
        if self.columns != other.columns or len(self.ints) != len(other.ints):
            raise ValueError("replicates of different columns or counts cannot be added")
        return Replicates(
            self.columns,
            self.ints + other.ints,
            self.similarity + other.similarity,
            self.main_tr + other.main_tr,
            self.idtp + other.idtp,
            self.hota_ass + other.hota_ass,
            self.block_lengths + other.block_lengths,
        )


#: Parts of IDF1's pair graph with at most this many maximal matchings are solved by
#: trying them all (at once for every replicate); larger ones by the Hungarian algorithm.
EXHAUSTIVE = 512
#: Rows (the smaller side) beyond which a part is not enumerated (the Hungarian instead).
_EXHAUSTIVE_ROWS = 64


def maximal_matchings(
    rows: IntArray, cols: IntArray, num_rows: int, limit: int = EXHAUSTIVE
) -> list[list[int]] | None:
    """Every maximal matching of the bipartite graph of edges ``(rows[i], cols[i])``, as
    lists of edge indices; None when there are more than ``limit`` (or the search would be
    long). With non-negative edge weights a best assignment is one of them: a matching
    that is not maximal can take one more edge without losing weight.

    Row by row, each row takes a free column of its edges or none; a row left without
    one needs each of its columns taken by a later row, else the branch is cut."""
    if num_rows > _EXHAUSTIVE_ROWS:
        return None
    edges: list[list[tuple[int, int]]] = [[] for _ in range(num_rows)]
    last: dict[int, int] = {}  # per column, the last row with an edge to it
    col_rows: dict[int, list[int]] = {}  # per column, its rows
    for e, (r, c) in enumerate(zip(rows.tolist(), cols.tolist(), strict=True)):
        edges[r].append((e, c))
        last[c] = max(last.get(c, r), r)
        col_rows.setdefault(c, []).append(r)
    # Per row, the columns it is the last row of, with their rows.
    closing: list[list[tuple[int, list[int]]]] = [[] for _ in range(num_rows)]
    for c, r in last.items():
        closing[r].append((c, col_rows[c]))
    found: list[list[int]] = []
    chosen: list[int] = []
    used: set[int] = set()
    skipped = [False] * num_rows
    budget = 4 * limit  # search steps: a dense part ends the search early

    def search(r: int) -> bool:
        nonlocal budget
        budget -= 1
        if budget < 0 or len(found) > limit:
            return False
        # A row left unmatched needs its free columns taken by a row from r on. The search
        # got here through r - 1, whose own check held: only the columns whose last row is
        # r - 1 can fail it now.
        for c, ks in closing[r - 1] if r else ():
            if c not in used:
                for k in ks:
                    if skipped[k]:
                        return True
        if r == num_rows:
            found.append(list(chosen))
            return True
        for e, c in edges[r]:
            if c not in used:
                used.add(c)
                chosen.append(e)
                ok = search(r + 1)
                chosen.pop()
                used.discard(c)
                if not ok:
                    return False
        skipped[r] = True
        ok = search(r + 1)
        skipped[r] = False
        return ok

    if not search(0) or len(found) > limit:
        return None
    return found


class _AssignmentPart:
    """One connected part of IDF1's pair graph, as columns ``pairs`` of the pair counts.

    A part with one ground-truth id or one track id is solved by its largest count, one
    with few maximal matchings (:func:`maximal_matchings`) by trying them all, the others by
    a Hungarian assignment per replicate. Counts are non-negative, so a best assignment is
    a maximal matching. Sums of integer counts: exact whichever way they are added.
    """

    def __init__(self, pairs: IntArray, rows: IntArray, cols: IntArray) -> None:
        self.pairs = pairs
        rows, cols = _dense_ids(rows), _dense_ids(cols)
        shape = (int(rows.max()) + 1, int(cols.max()) + 1)
        if shape[0] > shape[1]:  # rows <= columns: the solver then returns rows 0, 1, ...
            rows, cols, shape = cols, rows, (shape[1], shape[0])
        self.rows, self.cols, self.shape = rows, cols, shape
        #: The maximal matchings as lists of edges (indices into ``pairs``); None: the
        #: Hungarian. ``matchings``: the same as rows of 1 for their edges ``(matchings, edges)``.
        self.options: list[list[int]] | None = None
        self.matchings: FloatArray | None = None
        if shape[0] > 1:
            self.options = maximal_matchings(self.rows, self.cols, shape[0])
            if self.options is not None:
                sizes = [len(edges) for edges in self.options]
                self.matchings = np.zeros((len(sizes), len(pairs)))
                which = np.repeat(np.arange(len(sizes)), sizes)
                self.matchings[which, [e for edges in self.options for e in edges]] = 1.0

    def best(self, counts: FloatArray) -> FloatArray:
        """The best assignment's total of every replicate (columns of ``counts``)."""
        values = counts[self.pairs]
        if self.shape[0] == 1:
            star: FloatArray = values.max(axis=0)
            return star
        if self.matchings is not None:
            exhaustive: FloatArray = (self.matchings @ values).max(axis=0)
            return exhaustive
        count = values.shape[1]
        dense = np.zeros((count, *self.shape))
        dense[:, self.rows, self.cols] = values.T
        rows = np.arange(self.shape[0])
        picked = np.stack([linear_sum_assignment(m, maximize=True)[1] for m in dense])
        out: FloatArray = dense[np.arange(count)[:, None], rows[None, :], picked].sum(axis=1)
        return out


def _dense_ids(ids: IntArray) -> IntArray:
    """Each id's rank among the distinct ids (``numpy.unique``'s inverse), for a few ids."""
    values = ids.tolist()
    rank = {v: k for k, v in enumerate(sorted(set(values)))}
    return np.array([rank[v] for v in values], dtype=np.int64)


def _assignment_parts(rows: IntArray, cols: IntArray) -> list[_AssignmentPart]:
    """The connected parts of the bipartite graph of pairs ``(rows[i], cols[i])``, in the
    order of their smallest node (rows first), each with its pairs in order."""
    if not len(rows):
        return []
    row_list, col_list = rows.tolist(), cols.tolist()
    num_rows = max(row_list) + 1
    parent = list(range(num_rows + max(col_list) + 1))

    def root(node: int) -> int:
        while parent[node] != node:
            parent[node] = parent[parent[node]]
            node = parent[node]
        return node

    for r, c in zip(row_list, col_list, strict=True):
        a, b = root(r), root(num_rows + c)
        if a != b:
            parent[max(a, b)] = min(a, b)
    members: dict[int, list[int]] = {}
    for i, r in enumerate(row_list):
        members.setdefault(root(r), []).append(i)
    parts = []
    for p in sorted(members):
        index = np.array(members[p], dtype=np.int64)
        parts.append(_AssignmentPart(index, rows[index], cols[index]))
    return parts


# ----------------------------------------------------------------------------- compiled kernel

#: Replicates the kernel works on at once: their column sums (a column per replicate)
#: stay in cache while every loop runs along them.
_TILE = 16


def _replicate_stats(
    rows: IntArray,
    blocks: FloatArray,
    sums: FloatArray,
    spans: IntArray,
    main_starts: IntArray,
    extra_from: IntArray,
    extra_to: IntArray,
    part_starts: IntArray,
    option_starts: IntArray,
    option_pairs: IntArray,
    level_pair: IntArray,
    level_rows: IntArray,
    pair_gt: IntArray,
    pair_track: IntArray,
    num_columns: int,
    kept: IntArray,
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
    """What :meth:`_SequenceSums.chunk` derives from each replicate's column sums, compiled
    (:data:`_replicate_stats_kernel`), :data:`_TILE` replicates at a time.

    A replicate's column sums are those of its blocks, the rows ``rows[r]`` of ``blocks``
    added, or (``rows`` without columns) ``sums[r]``. Returns the frame-level integer
    columns ``(num_columns, replicates)``, Main Tr.'s matches, IDF1's IDTP of the parts
    solved here, HOTA's association sums ``(19, replicates)`` and the sums of the columns
    ``kept`` ``(len(kept), replicates)`` (for the parts left to the Hungarian).

    ``spans``: the first and end column of the ground-truth counts, of the track counts and
    of the matches per pair, the column of ID switches (recall errors next) and the first
    (level, pair) column. ``main_starts``: the first match column of each ground-truth id,
    and the end. ``extra_from`` -> ``extra_to``: the caller's columns. IDF1: part ``p`` is
    the best of its options ``part_starts[p]`` to ``part_starts[p + 1] - 1``, option ``o``
    the sum of the columns ``option_pairs[option_starts[o]:option_starts[o + 1]]`` (a
    maximal matching, or one pair of a part with one row). HOTA: the (level, pair) columns
    sorted by level, ``level_rows[l]`` to ``level_rows[l + 1] - 1`` those of level ``l``,
    ``level_pair`` their pair, whose ground-truth and track count columns are ``pair_gt``
    and ``pair_track``.

    Every sum is of integer counts (exact in any order) but HOTA's association, whose
    terms (each one IEEE division) are added pair after pair, as numpy's ``add.reduce``
    over the pairs adds them. Loops run along the replicates (one replicate per lane of
    the vector instructions, its own operations in the same order): no fast-math, nothing
    reordered within a replicate, the same bits on every CPU.
    """
    from_blocks = rows.shape[1] > 0
    count = rows.shape[0] if from_blocks else sums.shape[0]
    width = blocks.shape[1] if from_blocks else sums.shape[1]
    n_alpha = level_rows.shape[0] - 2
    num_pairs = pair_gt.shape[0]
    ints = np.zeros((num_columns, count))
    main_tr = np.zeros(count)
    idtp = np.zeros(count)
    ass = np.zeros((n_alpha, count))
    kept_sums = np.zeros((kept.shape[0], count))
    tile = np.zeros((width, _TILE))
    one = np.zeros(width)
    best = np.zeros(_TILE)
    total = np.zeros(_TILE)
    both = np.zeros((num_pairs, _TILE))
    reach = np.zeros((num_pairs, _TILE))
    term = np.zeros((num_pairs, _TILE))
    for first in range(0, count, _TILE):
        m = min(_TILE, count - first)
        # The tile's column sums, one column per replicate.
        for j in range(m):
            if from_blocks:
                one[:] = 0.0
                for i in range(rows.shape[1]):
                    x = blocks[rows[first + j, i]]
                    for c in range(width):
                        one[c] += x[c]
            else:
                one[:] = sums[first + j]
            tile[:, j] = one
        # (Inner loops over the tile's replicates ``j`` read rows of 2-d arrays as 1-d views:
        # those loops are vectorised.)
        for k in range(3):  # ground truth, tracks, matches: totals
            out = ints[k, first : first + m]
            for c in range(spans[2 * k], spans[2 * k + 1]):
                x = tile[c]
                for j in range(m):
                    out[j] += x[j]
        for k in range(2):  # ID switches, recall errors
            ints[3 + k, first : first + m] = tile[spans[6] + k, :m]
        for i in range(extra_from.shape[0]):
            ints[extra_to[i], first : first + m] = tile[extra_from[i], :m]
        for i in range(kept.shape[0]):
            kept_sums[i, first : first + m] = tile[kept[i], :m]
        # Main Tr.: each ground-truth id's best track.
        out = main_tr[first : first + m]
        for g in range(main_starts.shape[0] - 1):
            best[:] = 0.0
            for c in range(main_starts[g], main_starts[g + 1]):
                x = tile[c]
                for j in range(m):
                    best[j] = max(best[j], x[j])
            for j in range(m):
                out[j] += best[j]
        # IDF1: each part's best option.
        out = idtp[first : first + m]
        for p in range(part_starts.shape[0] - 1):
            best[:] = 0.0
            for o in range(part_starts[p], part_starts[p + 1]):
                total[:] = 0.0
                for i in range(option_starts[o], option_starts[o + 1]):
                    x = tile[option_pairs[i]]
                    for j in range(m):
                        total[j] += x[j]
                for j in range(m):
                    best[j] = max(best[j], total[j])
            for j in range(m):
                out[j] += best[j]
        # HOTA, one threshold at a time from the highest: a pair reaches threshold a with
        # its matches of the levels above a; its term reach^2 / max(1, gt + track - reach)
        # changes only where its reach does; the terms summed in pair order.
        for q in range(num_pairs):
            x, y, z = tile[pair_gt[q]], tile[pair_track[q]], both[q]
            for j in range(m):
                z[j] = x[j] + y[j]
        reach[:] = 0.0
        term[:] = 0.0
        total[:] = 0.0  # the matches reaching the threshold: HOTA's TP
        for a in range(n_alpha - 1, -1, -1):
            lo, hi = level_rows[a + 1], level_rows[a + 2]
            out = ass[a, first : first + m]
            if hi > lo or a == n_alpha - 1:
                for i in range(lo, hi):
                    q = level_pair[i]
                    x, z, held, t = tile[spans[7] + i], both[q], reach[q], term[q]
                    for j in range(m):
                        total[j] += x[j]
                        v = held[j] + x[j]
                        held[j] = v
                        t[j] = v * v / max(z[j] - v, 1.0)
                for q in range(num_pairs):
                    t = term[q]
                    for j in range(m):
                        out[j] += t[j]
            else:
                out[:] = ass[a + 1, first : first + m]
            ints[5 + a, first : first + m] = total[:m]
    return ints, main_tr, idtp, ass, kept_sums


_replicate_stats_kernel: Callable[
    ..., tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]
] = numba.njit(cache=True)(_replicate_stats)


class _Design:
    """Columns of per-frame event counts: ``matrix @ W.T`` sums them for every replicate."""

    def __init__(self, num_frames: int) -> None:
        self.num_frames = num_frames
        self.rows: list[IntArray] = []
        self.cols: list[IntArray] = []
        self.data: list[FloatArray] = []
        self.width = 0

    def add(self, frames: IntArray, columns: IntArray | int, width: int) -> slice:
        """Count each event ``(frames[i], columns[i])`` in its column of a new group."""
        frames = np.asarray(frames, dtype=np.int64)
        self.rows.append(frames)
        if isinstance(columns, int):
            self.cols.append(np.full(len(frames), self.width + columns, dtype=np.int64))
        else:
            self.cols.append(self.width + np.asarray(columns, dtype=np.int64))
        self.data.append(np.ones(len(frames)))
        out = slice(self.width, self.width + width)
        self.width += width
        return out

    def add_series(self, values: IntArray) -> slice:
        """Columns holding integers per frame: ``values`` is ``(columns, frames)``."""
        values = np.asarray(values, dtype=np.int64).reshape(len(values), self.num_frames)
        cols, frames = np.nonzero(values)
        self.rows.append(frames.astype(np.int64))
        self.cols.append(self.width + cols.astype(np.int64))
        self.data.append(values[cols, frames].astype(np.float64))
        out = slice(self.width, self.width + len(values))
        self.width += len(values)
        return out

    def dense(self) -> FloatArray:
        """The design frame by frame, dense ``(frames, columns)``: :meth:`matrix`
        transposed (integer counts added: exact)."""
        rows = np.concatenate(self.rows) if self.rows else np.zeros(0, dtype=np.int64)
        cols = np.concatenate(self.cols) if self.cols else np.zeros(0, dtype=np.int64)
        data = np.concatenate(self.data) if self.data else np.zeros(0)
        size = self.width * self.num_frames
        flat = np.bincount(rows * self.width + cols, weights=data, minlength=size)
        out: FloatArray = flat.astype(np.float64, copy=False).reshape(self.num_frames, self.width)
        return out

    def matrix(self) -> sparse.csr_matrix:
        """The transposed design ``(columns, frames)``; repeated events add up (exact)."""
        rows = np.concatenate(self.rows) if self.rows else np.zeros(0, dtype=np.int64)
        cols = np.concatenate(self.cols) if self.cols else np.zeros(0, dtype=np.int64)
        data = np.concatenate(self.data) if self.data else np.zeros(0)
        shape = (self.width, self.num_frames)
        return sparse.coo_matrix((data, (cols, rows)), shape=shape).tocsr()


class _SequenceSums:
    """What one table's replicates need, prepared once: one sparse matrix of per-frame counts.

    Sums are kept as ``(column, replicate)`` arrays, so that every step runs on contiguous
    rows. Each event is counted once: ground truth and tracks per id, matches per pair,
    HOTA's pairs by level (how many localisation thresholds their similarity reaches,
    0..19); the totals are sums of those.
    """

    def __init__(self, table: FrameTable, extra: Mapping[str, IntArray]) -> None:
        t = table
        design = _Design(t.num_frames)
        self.columns = (*BASE_COLUMNS, *extra)
        num_tracks = max(t.num_tracks, 1)
        self.gt_count = design.add(t.gt_frame, t.gt_index, t.num_gt_tracks)
        self.track_count = design.add(t.track_frame, t.track_index, t.num_tracks)
        switches = design.add(t.match_frame[t.match_switch], 0, 1)
        recalls = design.add(t.match_frame[t.match_recall], 0, 1)
        self.flags = slice(switches.start, recalls.stop)
        # The caller's series; those all zero (a band nobody is in) need no column.
        series = np.zeros((len(extra), t.num_frames), dtype=np.int64)
        for k, values in enumerate(extra.values()):
            series[k] = values
        self.extra_columns = len(BASE_COLUMNS) + np.flatnonzero(series.any(axis=1))
        self.extra = design.add_series(series[series.any(axis=1)])
        # Main Tr.: matches per (gt, track) pair; the best track per gt.
        keys = t.match_gt * num_tracks + t.match_track
        pairs, inverse = np.unique(keys, return_inverse=True)
        self.main = design.add(t.match_frame, inverse.ravel(), len(pairs))
        self.main_gt_starts = np.unique(pairs // num_tracks, return_index=True)[1]
        # IDF1: frames inside the gate per (gt, track) pair.
        keys = t.potential_gt * num_tracks + t.potential_track
        pairs, inverse = np.unique(keys, return_inverse=True)
        self.potential = design.add(t.potential_frame, inverse.ravel(), len(pairs))
        self.id_parts = _assignment_parts(pairs // num_tracks, pairs % num_tracks)
        # HOTA: per pair its matches by level, a column for each (level, pair) that occurs.
        keys = t.hota_gt * num_tracks + t.hota_track
        pairs, inverse = np.unique(keys, return_inverse=True)
        self.num_hota_pairs = len(pairs)
        levels = np.unique(t.hota_levels() * len(pairs) + inverse.ravel(), return_inverse=True)
        self.pair_levels = design.add(t.hota_frame, levels[1].ravel(), len(levels[0]))
        self.level_pair = levels[0] % max(len(pairs), 1)  # sorted by level, then pair
        self.level_rows = np.searchsorted(levels[0] // max(len(pairs), 1), np.arange(_N_ALPHA + 2))
        self.hota_pair_gt = pairs // num_tracks
        self.hota_pair_track = pairs % num_tracks
        self.similarity = t.per_frame(t.match_frame, t.match_value).astype(np.float64)
        self._design = design
        self._matrix: sparse.csr_matrix | None = None
        self.num_columns = design.width
        self.num_frames = t.num_frames
        self._block_counts: dict[tuple[int, int], FloatArray] = {}
        self._block_similarity: dict[tuple[int, int], FloatArray] = {}
        self._layout, self._hungarian = self._kernel_layout()

    def _kernel_layout(self) -> tuple[tuple[IntArray | int, ...], list[int]]:
        """:func:`_replicate_stats`' arguments after ``sums`` (the columns it reads), and the
        IDF1 parts it leaves to the Hungarian (their indices in ``id_parts``)."""
        spans = [self.gt_count, self.track_count, self.main]
        flat = [x for span in spans for x in (span.start, span.stop)]
        part_starts, option_starts, option_pairs, hungarian = [0], [0], [], []
        for k, part in enumerate(self.id_parts):
            columns = (self.potential.start + part.pairs).tolist()
            if part.shape[0] == 1:
                options = [[c] for c in columns]
            elif part.options is not None:
                options = [[columns[e] for e in edges] for edges in part.options]
            else:
                hungarian.append(k)
                continue
            for option in options:
                option_pairs += option
                option_starts.append(len(option_pairs))
            part_starts.append(len(option_starts) - 1)
        # The Hungarian parts take the pair counts (all of them: their ``pairs`` index those).
        kept = range(self.potential.start, self.potential.stop) if hungarian else ()
        main_starts = [*self.main_gt_starts.tolist(), self.main.stop - self.main.start]

        def ints(values: Sequence[int] | range | IntArray) -> IntArray:
            return np.asarray(values, dtype=np.int64)

        layout = (
            ints([*flat, self.flags.start, self.pair_levels.start]),
            self.main.start + ints(main_starts if len(self.main_gt_starts) else [0]),
            ints(range(self.extra.start, self.extra.stop)),
            ints(self.extra_columns),
            ints(part_starts),
            ints(option_starts),
            ints(option_pairs),
            ints(self.level_pair),
            ints(self.level_rows),
            ints(self.gt_count.start + self.hota_pair_gt),
            ints(self.track_count.start + self.hota_pair_track),
            len(self.columns),
            ints(kept),
        )
        return layout, hungarian

    def _last(self, block: int, k: int) -> int:
        """The length of a replicate's last block of ``k`` (cut to the first n frames)."""
        return self.num_frames - (k - 1) * block

    def _rows(self, starts: IntArray) -> IntArray:
        """Per replicate the rows of its blocks in :meth:`_blocks`' tables: ``start`` for a
        full block, ``n + start`` for the last, cut one."""
        rows = starts.astype(np.int64)
        rows[:, -1] += self.num_frames
        return rows

    def by_blocks(self) -> bool:
        """Whether replicates are summed over their blocks (each block's counts, prepared
        once: the table of :meth:`_blocks` fits :data:`BLOCK_SUMS_MAX`), else over the frame
        weights (every event of the table times each replicate's weights). Measured on the
        TUD sequences and the demo, blocks of 1 to 40 frames, the blocks are never slower."""
        return bool(self.num_columns * 2 * self.num_frames <= BLOCK_SUMS_MAX)

    def width(self, by_blocks: bool) -> int:
        """The values held per replicate while it is summed (:func:`start_chunks`): over
        the frame weights, its weights and its column sums; over the blocks, next to
        nothing (the kernel sums a few replicates at a time)."""
        return 1 if by_blocks else self.num_columns + self.num_frames

    def _blocks(self, block: int, k: int, by_blocks: bool | None) -> FloatArray | None:
        """The counts of the run of ``block`` frames from each frame, and of the last block's
        run ``(2 n, columns)`` (:func:`_window_sums`), when summing those is the cheaper way
        (``by_blocks`` None; True or False: that way); None: by frame weights."""
        if by_blocks is None:
            by_blocks = self.by_blocks()
        if not by_blocks:
            return None
        key = (block, k)
        if key not in self._block_counts:
            lengths = (block, self._last(block, k))
            self._block_counts[key] = _window_sums_kernel(
                self._design.dense(), np.array(lengths, dtype=np.int64)
            )
        return self._block_counts[key]

    def _similarities(self, block: int, k: int) -> FloatArray:
        """The MOTP similarity summed over each run, as :meth:`_blocks` (``(2 n,)``), each
        sum in numpy's fixed order."""
        key = (block, k)
        if key not in self._block_similarity:
            twice = np.concatenate([self.similarity, self.similarity])
            n = self.num_frames
            runs = [
                np.add.reduce(sliding_window_view(twice, length)[:n], axis=1)
                for length in (block, self._last(block, k))
            ]
            self._block_similarity[key] = np.concatenate(runs)
        return self._block_similarity[key]

    def chunk(
        self, starts: IntArray, block: int, by_blocks: bool | None = None
    ) -> tuple[FloatArray, ...]:
        """The sums ``(replicate, ...)`` of the replicates whose block starts are ``starts``
        (:func:`_weights`). The counts are summed over the frame weights (the table's events
        times each replicate's weights) or over the blocks (each block's counts, prepared
        once per start), whichever is cheaper (``by_blocks``: that way): integer sums, the
        same either way. The similarity behind MOTP is summed over the blocks."""
        count, k = starts.shape
        rows = self._rows(starts)
        blocks = self._blocks(block, k, by_blocks)
        if blocks is None:
            # Integer counts with integer weights: exact in any summation order.
            w = _weights(self.num_frames, block, starts)
            if self._matrix is None:
                self._matrix = self._design.matrix()
            sums = np.ascontiguousarray(np.asarray(self._matrix @ w.T).T)  # (replicates, columns)
            picked, blocks = np.zeros((count, 0), dtype=np.int64), np.zeros((0, 0))
        else:
            picked, sums = rows, np.zeros((0, 0))
        ints, main_tr, idtp, ass, potential = _replicate_stats_kernel(
            picked, blocks, sums, *self._layout
        )
        for index in self._hungarian:
            idtp += self.id_parts[index].best(potential)
        similarity = np.add.reduce(self._similarities(block, k)[rows], axis=1)
        # Transposed views, the layout the replicates have always had: ``replicate_metrics``
        # averages HOTA over the thresholds along their rows, and numpy adds a row's values
        # in an order that depends on the layout (the same layout, the same bits).
        return ints.T, similarity, main_tr, idtp, ass.T


def replicates(
    table: FrameTable,
    name: str,
    count: int = DEFAULT_REPLICATES,
    seed: int = DEFAULT_SEED,
    extra: Mapping[str, IntArray] | None = None,
    block: int | None = None,
) -> Replicates:
    """``count`` replicates of one sequence (block length by :func:`block_length` unless given).

    ``extra`` adds per-frame integer series (``num_frames`` long) as further columns.
    """
    sums = _SequenceSums(table, extra or {})
    length = block_length(frame_errors(table)) if block is None else block
    n, used = table.num_frames, max(1, min(length, table.num_frames))
    by_blocks = sums.by_blocks()
    rng = sequence_rng(seed, name)
    draws = start_chunks(n, used, count, rng, sums.width(by_blocks)) if n else iter(())
    parts = [sums.chunk(starts, used, by_blocks) for starts in draws]
    return _assemble(sums.columns, parts, count, (length,))


def paired_replicates(
    tables: tuple[FrameTable, FrameTable],
    name: str,
    block: int,
    count: int = DEFAULT_REPLICATES,
    seed: int = DEFAULT_SEED,
) -> tuple[Replicates, Replicates]:
    """Replicates of two tables of the same frames on the same draws (``compare``)."""
    if tables[0].num_frames != tables[1].num_frames:
        raise ValueError(
            f"sequence {name!r}: {tables[0].num_frames} frames against {tables[1].num_frames}"
        )
    first, second = _SequenceSums(tables[0], {}), _SequenceSums(tables[1], {})
    parts_a, parts_b = [], []
    n, used = tables[0].num_frames, max(1, min(block, tables[0].num_frames))
    ways = (first.by_blocks(), second.by_blocks())
    width = max(first.width(ways[0]), second.width(ways[1]))
    rng = sequence_rng(seed, name)
    for starts in start_chunks(n, used, count, rng, width) if n else iter(()):
        parts_a.append(first.chunk(starts, used, ways[0]))
        parts_b.append(second.chunk(starts, used, ways[1]))
    return (
        _assemble(first.columns, parts_a, count, (block,)),
        _assemble(second.columns, parts_b, count, (block,)),
    )


def _assemble(
    columns: tuple[str, ...],
    parts: Sequence[tuple[FloatArray, ...]],
    count: int,
    blocks: tuple[int, ...],
) -> Replicates:
    if not parts:
        return Replicates(
            columns,
            np.zeros((count, len(columns))),
            np.zeros(count),
            np.zeros(count),
            np.zeros(count),
            np.zeros((count, _N_ALPHA)),
            blocks,
        )
    if len(parts) == 1:  # as they are: the layout a concatenation would give
        ints, sim, main, idtp, ass = parts[0]
    else:
        ints, sim, main, idtp, ass = (np.concatenate(p, axis=0) for p in zip(*parts, strict=True))
    return Replicates(columns, ints, sim, main, idtp, ass, blocks)


# ----------------------------------------------------------------------------- metrics, intervals


def _ratio(numerator: FloatArray, denominator: FloatArray) -> FloatArray:
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(
            denominator > 0, numerator / np.where(denominator > 0, denominator, 1), np.nan
        )


def replicate_metrics(r: Replicates) -> dict[str, FloatArray]:
    """:data:`INTERVAL_METRICS` of every replicate (NaN where a denominator is 0).

    The formulas of :func:`rgbd_eval.metrics.counts.summarize` and
    :meth:`rgbd_eval.metrics.hota.HotaCounts.summary`, on arrays.
    """
    gt, tracks = r.column("num_gt"), r.column("num_tracks")
    matches, switches = r.column("num_matches"), r.column("id_switches")
    fn, fp = gt - matches, tracks - matches
    tp = r.sums([f"hota_tp_{a}" for a in range(_N_ALPHA)])
    det = tp / np.maximum(1.0, gt[:, None] + tracks[:, None] - tp)
    ass = r.hota_ass / np.maximum(1.0, tp)
    scored = (gt + tracks) > 0
    nan = np.full(len(gt), np.nan)
    return {
        "mota": 1.0 - _ratio(fn + fp + switches, gt),
        "motp": _ratio(r.similarity, matches),
        "fp_rate": _ratio(fp, gt),
        "fn_rate": _ratio(fn, gt),
        "id_switches": switches,
        "recall_errors": r.column("recall_errors"),
        "main_tr": _ratio(r.main_tr, gt),
        "all_tr": _ratio(matches, gt),
        "idf1": _ratio(2.0 * r.idtp, gt + tracks),
        "hota": np.where(scored, np.sqrt(det * ass).mean(axis=1), nan),
        "deta": np.where(scored, det.mean(axis=1), nan),
        "assa": np.where(scored, ass.mean(axis=1), nan),
    }


def _ends(n: int) -> tuple[int, int]:
    """The ranks (1-based) of an interval's ends among ``n`` sorted values."""
    tail = (1.0 - CONFIDENCE) / 2.0
    return max(1, math.ceil(round(tail * n, 9))), max(1, math.ceil(round((1.0 - tail) * n, 9)))


def interval(values: FloatArray) -> tuple[float, float] | None:
    """The :data:`CONFIDENCE` percentile interval of replicate values (None if all are NaN).

    The ends are order statistics (numpy's ``inverted_cdf`` quantiles): of ``N`` values
    sorted, the ``ceil(0.025 N)``-th and the ``ceil(0.975 N)``-th.
    """
    finite = np.sort(values[~np.isnan(values)])
    n = len(finite)
    if not n:
        return None
    lo, hi = _ends(n)
    return float(finite[lo - 1]), float(finite[hi - 1])


def intervals_of(values: Mapping[str, FloatArray]) -> dict[str, tuple[float, float] | None]:
    """:func:`interval` of each series, all at once: the series without NaN partitioned
    around the two ranks (the values a sort puts there, without sorting), the others sorted."""
    if not values:
        return {}
    names = list(values)
    series = np.stack([values[k] for k in names])
    finite = (~np.isnan(series)).sum(axis=1)
    full = finite == series.shape[1]
    ordered = np.empty_like(series)
    if full.any() and series.shape[1]:
        lo, hi = _ends(series.shape[1])
        ordered[full] = np.partition(series[full], (lo - 1, hi - 1), axis=1)
    if not full.all():
        ordered[~full] = np.sort(series[~full], axis=1)  # NaN last
    out: dict[str, tuple[float, float] | None] = {}
    for name, row, n in zip(names, ordered, finite.tolist(), strict=True):
        if not n:
            out[name] = None
            continue
        lo, hi = _ends(n)
        out[name] = (float(row[lo - 1]), float(row[hi - 1]))
    return out


def intervals(r: Replicates) -> dict[str, tuple[float, float] | None]:
    """Every :data:`INTERVAL_METRICS` interval of a set of replicates."""
    return intervals_of(replicate_metrics(r))


def total_replicates(items: Sequence[Replicates]) -> Replicates:
    """The replicates of several sequences summed (the overall row)."""
    result = items[0]
    for item in items[1:]:
        result = result + item
    return result
