"""Pairing of RGB and depth messages by nearest header stamp."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray


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
