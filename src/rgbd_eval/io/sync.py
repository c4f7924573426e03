"""Synchronisation: each stream's messages paired with the reference stream's by nearest
header stamp, how they paired, and, for a stream that does not pair, the sync gap that
would pair it."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from rgbd_eval.config import IoConfig
from rgbd_eval.errors import SyncError


@dataclass(frozen=True)
class Pairing:
    """One-to-one RGB/depth pairs (indices into the stamp arrays), sorted by RGB stamp."""

    pairs: tuple[tuple[int, int], ...]
    rgb_unpaired: int
    depth_unpaired: int
    worst_gap_ns: int
    mean_gap_ns: float


def first_non_increasing(stamps: NDArray[np.int64]) -> int | None:
    """Index of the first stamp that is not strictly greater than its predecessor, or None."""
    bad = np.nonzero(np.diff(stamps) <= 0)[0]
    return int(bad[0]) + 1 if bad.size else None


def pair_nearest(rgb: NDArray[np.int64], depth: NDArray[np.int64], max_gap_ns: int) -> Pairing:
    """Pair each stamp with its nearest partner within ``max_gap_ns``, one to one.

    Candidates are every stamp's nearest neighbours on either side in the other
    stream; they are accepted greedily by increasing gap, so the closest pairs win
    a conflict. Both inputs must be sorted ascending.
    """
    rgb = np.asarray(rgb, dtype=np.int64)
    depth = np.asarray(depth, dtype=np.int64)
    if rgb.size == 0 or depth.size == 0:
        return Pairing((), int(rgb.size), int(depth.size), 0, 0.0)
    cand: list[NDArray[np.int64]] = []
    j = np.searchsorted(depth, rgb)
    for off in (-1, 0):
        k = j + off
        ok = (k >= 0) & (k < depth.size)
        cand.append(np.stack([np.nonzero(ok)[0], k[ok]], axis=1))
    i = np.searchsorted(rgb, depth)
    for off in (-1, 0):
        k = i + off
        ok = (k >= 0) & (k < rgb.size)
        cand.append(np.stack([k[ok], np.nonzero(ok)[0]], axis=1))
    pairs = np.unique(np.concatenate(cand), axis=0)
    gaps = np.abs(rgb[pairs[:, 0]] - depth[pairs[:, 1]])
    keep = gaps <= max_gap_ns
    pairs, gaps = pairs[keep], gaps[keep]
    order = np.lexsort((pairs[:, 0], gaps))
    used_r = np.zeros(rgb.size, dtype=bool)
    used_d = np.zeros(depth.size, dtype=bool)
    chosen: list[tuple[int, int]] = []
    chosen_gaps: list[int] = []
    for idx in order:
        r, d = int(pairs[idx, 0]), int(pairs[idx, 1])
        if not used_r[r] and not used_d[d]:
            used_r[r] = used_d[d] = True
            chosen.append((r, d))
            chosen_gaps.append(int(gaps[idx]))
    chosen.sort()
    return Pairing(
        tuple(chosen),
        int(rgb.size - len(chosen)),
        int(depth.size - len(chosen)),
        max(chosen_gaps, default=0),
        float(np.mean(chosen_gaps)) if chosen_gaps else 0.0,
    )


@dataclass(frozen=True)
class StreamSync:
    """How one stream paired with the reference stream."""

    role: str
    topic: str
    messages: int
    dropped: int
    worst_gap_ms: float
    mean_gap_ms: float


@dataclass(frozen=True)
class SyncProblem:
    """A stream none of whose messages pairs with the reference stream within the sync gap.

    ``smallest_gap_ms`` is the smallest offset between the two streams' stamps and
    ``needed_gap_ms`` the smallest sync gap at which as many messages pair as can;
    ``accept_with`` sets ``option`` to it, which pairs ``pairs_accepted`` reference
    messages. Without a role: no frame has every stream.
    """

    message: str
    role: str | None = None
    topic: str | None = None
    smallest_gap_ms: float | None = None
    needed_gap_ms: float | None = None
    option: str = "io.max_sync_gap_ms"
    accept_with: str | None = None
    pairs_accepted: int | None = None


@dataclass(frozen=True)
class SyncStats:
    """How the streams pair up: per stream, against the reference (the first stream)."""

    reference: str
    streams: tuple[StreamSync, ...]
    frames: int
    no_pose_dropped: int
    max_gap_ms: float
    #: Why nothing pairs (only with ``open_recording(..., unpaired_ok=True)``).
    problems: tuple[SyncProblem, ...] = ()

    @property
    def worst_gap_ms(self) -> float:
        return max((s.worst_gap_ms for s in self.streams), default=0.0)


def pair_streams(
    path: Path,
    io: IoConfig,
    chosen: Mapping[str, str],
    stamps: Mapping[str, NDArray[np.int64]],
    unpaired_ok: bool,
) -> tuple[dict[str, dict[int, int]], list[StreamSync], list[SyncProblem]]:
    """Pair every stream with the reference (the first of ``chosen``, role -> topic).

    Returns, per other role, its partner of each paired reference message (reference
    index -> the role's index), how each stream paired, and the problems of streams that
    do not pair at all (a :class:`SyncError` unless ``unpaired_ok``).
    """
    reference = next(iter(chosen))
    max_gap_ns = int(io.max_sync_gap_ms * 1e6)
    partner: dict[str, dict[int, int]] = {}
    stream_sync = []
    problems: list[SyncProblem] = []
    for role in list(chosen)[1:]:
        pairing: Pairing = pair_nearest(stamps[reference], stamps[role], max_gap_ns)
        if not pairing.pairs:
            problem = unpaired_problem(io, reference, role, chosen, stamps)
            if not unpaired_ok:
                raise SyncError(path, problem.message)
            problems.append(problem)
        partner[role] = dict(pairing.pairs)
        stream_sync.append(
            StreamSync(
                role,
                chosen[role],
                int(stamps[role].size),
                pairing.depth_unpaired,
                pairing.worst_gap_ns / 1e6,
                pairing.mean_gap_ns / 1e6,
            )
        )
    return partner, stream_sync, problems


def _neighbour_gaps_ns(a: NDArray[np.int64], b: NDArray[np.int64]) -> NDArray[np.int64]:
    """The offsets of each a_i to its neighbours in b on either side (both sorted, non-empty)."""
    j = np.searchsorted(b, a)
    before, after = j > 0, j < b.size
    return np.concatenate([a[before] - b[j[before] - 1], b[j[after]] - a[after]]).astype(np.int64)


def unpaired_problem(
    io: IoConfig,
    reference: str,
    role: str,
    chosen: Mapping[str, str],
    stamps: Mapping[str, NDArray[np.int64]],
) -> SyncProblem:
    """Why ``role`` pairs with no ``reference`` message, and the sync gap that would pair them.

    That gap is the smallest at which as many messages pair as at any gap: the
    candidates :func:`pair_nearest` weighs are every stamp's neighbours in the other
    stream, and the pairs it keeps only grow with the gap, so a bisection over those
    neighbours' offsets finds it.
    """
    ref, other = stamps[reference], stamps[role]
    counts = f"({chosen[reference]}: {ref.size} messages, {chosen[role]}: {other.size})"
    head = f"{reference} and {role} do not pair: no pair within {io.max_sync_gap_ms} ms {counts}"
    if ref.size == 0 or other.size == 0:
        return SyncProblem(f"{head}; a stream has no message", role, chosen[role])
    gaps = np.unique(
        np.concatenate([_neighbour_gaps_ns(ref, other), _neighbour_gaps_ns(other, ref)])
    )

    def pairs_within(gap_ns: int) -> int:
        return len(pair_nearest(ref, other, gap_ns).pairs)

    most = pairs_within(int(gaps[-1]))
    lo, hi = 0, gaps.size - 1  # the first gap at which ``most`` pair is in gaps[lo:hi + 1]
    while lo < hi:
        mid = (lo + hi) // 2
        if pairs_within(int(gaps[mid])) == most:
            hi = mid
        else:
            lo = mid + 1
    smallest, needed = float(gaps[0]) / 1e6, float(gaps[lo]) / 1e6
    accept = math.ceil(needed + 1)
    setting = f"--set {SyncProblem.option}={accept}"
    return SyncProblem(
        f"{head}; the smallest offset is {smallest:.1f} ms, and as many as can pair do within "
        f"{needed:.1f} ms: accept them with {setting} (pairs {most} of {ref.size} "
        f"{reference} messages)",
        role,
        chosen[role],
        smallest,
        needed,
        accept_with=setting,
        pairs_accepted=most,
    )
