"""HOTA, DetA, AssA and LocA as TrackEval's ``HOTA`` metric defines them (Luiten et al. 2021).

For each of the 19 localisation thresholds ``alpha = 0.05, 0.10, ..., 0.95``:
per frame, one Hungarian assignment maximises ``A(g, t) * S(g, t)``, where ``S``
is the similarity (IoU, or the distance form of
:func:`rgbd_eval.metrics.gating.similarity_from_measure`) and ``A`` the global
alignment of the two ids over the sequence; an assigned pair is a true positive at
``alpha`` when ``S >= alpha``. Then ``DetA = TP / (TP + FN + FP)``,
``AssA = sum over TP of A_alpha(g, t) / TP`` and ``HOTA = sqrt(DetA * AssA)``, each
averaged over the alphas; ``LocA`` is the mean similarity of the true positives.

:class:`HotaCounts` holds sums only, so the counts of several sequences add up and
give TrackEval's combined values (its AssA and LocA are averages weighted by TP).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.optimize import linear_sum_assignment

from rgbd_eval.metrics.gating import EPS, FloatArray
from rgbd_eval.metrics.matching import IntArray, distinct_pairs

#: TrackEval's localisation thresholds: ``np.arange(0.05, 0.99, 0.05)``.
ALPHAS: tuple[float, ...] = tuple(float(a) for a in np.arange(0.05, 0.99, 0.05))
_N = len(ALPHAS)


@dataclass(frozen=True)
class HotaCounts:
    """Per-alpha sums: TP/FN/FP, the association sum and the similarity sum of the TP."""

    tp: tuple[int, ...] = (0,) * _N
    fn: tuple[int, ...] = (0,) * _N
    fp: tuple[int, ...] = (0,) * _N
    ass_sum: tuple[float, ...] = (0.0,) * _N
    loc_sum: tuple[float, ...] = (0.0,) * _N

    def __post_init__(self) -> None:
        for name in ("tp", "fn", "fp", "ass_sum", "loc_sum"):
            values = getattr(self, name)
            if not isinstance(values, tuple) or len(values) != _N:
                raise ValueError(f"hota.{name} must be a tuple of {_N} values, got {values!r}")
            for v in values:
                if isinstance(v, bool) or not isinstance(v, int | float) or not v >= 0:
                    raise ValueError(f"hota.{name} holds {v!r}; values must be numbers >= 0")
                if name in ("tp", "fn", "fp") and not isinstance(v, int):
                    raise ValueError(f"hota.{name} holds {v!r}; counts must be integers")

    def __add__(self, other: HotaCounts) -> HotaCounts:
        if not isinstance(other, HotaCounts):
            return NotImplemented
        return HotaCounts(
            *(
                tuple(a + b for a, b in zip(getattr(self, n), getattr(other, n), strict=True))
                for n in ("tp", "fn", "fp", "ass_sum", "loc_sum")
            )
        )

    def to_dict(self) -> dict[str, list[int] | list[float]]:
        return {n: list(getattr(self, n)) for n in ("tp", "fn", "fp", "ass_sum", "loc_sum")}

    @staticmethod
    def from_dict(data: object) -> HotaCounts:
        """Read :meth:`to_dict` back; ``ValueError`` naming what is wrong."""
        names = ("tp", "fn", "fp", "ass_sum", "loc_sum")
        if not isinstance(data, dict) or set(data) != set(names):
            raise ValueError(f"counts: hota must be an object with keys {list(names)}")
        for n in names:
            if not isinstance(data[n], list):
                raise ValueError(f"counts: hota.{n} must be a list")
        return HotaCounts(
            tp=tuple(data["tp"]),
            fn=tuple(data["fn"]),
            fp=tuple(data["fp"]),
            ass_sum=tuple(float(v) for v in data["ass_sum"]),
            loc_sum=tuple(float(v) for v in data["loc_sum"]),
        )

    def summary(self) -> dict[str, float | None]:
        """HOTA, DetA, AssA, LocA averaged over the alphas (None when nothing was scored)."""
        tp = np.array(self.tp, dtype=np.float64)
        fn = np.array(self.fn, dtype=np.float64)
        fp = np.array(self.fp, dtype=np.float64)
        if not (tp + fn + fp).any():
            return {"hota": None, "deta": None, "assa": None, "loca": None}
        det_a = tp / np.maximum(1.0, tp + fn + fp)
        ass_a = np.array(self.ass_sum) / np.maximum(1.0, tp)
        loc_a = np.maximum(1e-10, np.array(self.loc_sum)) / np.maximum(1e-10, tp)
        hota = np.sqrt(det_a * ass_a)
        return {
            "hota": float(hota.mean()),
            "deta": float(det_a.mean()),
            "assa": float(ass_a.mean()),
            "loca": float(loc_a.mean()),
        }


def _sim_iou(similarity: FloatArray) -> FloatArray:
    denominator = similarity.sum(0)[None, :] + similarity.sum(1)[:, None] - similarity
    out = np.zeros_like(similarity)
    mask = denominator > EPS
    out[mask] = similarity[mask] / denominator[mask]
    return out


def hota_counts(
    gt: Sequence[IntArray],
    tracks: Sequence[IntArray],
    similarity: Sequence[FloatArray],
    num_gt: int,
    num_tracks: int,
    pairs: list[tuple[int, IntArray, IntArray, FloatArray]] | None = None,
) -> HotaCounts:
    """HOTA sums of one sequence from dense ids and per-frame similarity matrices.

    ``pairs``, when given, receives each frame's assignment as ``(frame, gt, track,
    similarity)`` (for :mod:`rgbd_eval.metrics.frames`).
    """
    potential = np.zeros((num_gt, num_tracks))
    # Ids are unique within a frame: counting them is counting their frames.
    empty = np.zeros(0, dtype=np.int64)
    gt_count = np.bincount(np.concatenate([empty, *gt]), minlength=num_gt).astype(np.float64)
    track_count = np.bincount(np.concatenate([empty, *tracks]), minlength=num_tracks).astype(
        np.float64
    )
    for g, t, s in zip(gt, tracks, similarity, strict=True):
        if len(g) and len(t):
            potential[g[:, None], t] += _sim_iou(s)
    with np.errstate(divide="ignore", invalid="ignore"):
        alignment = potential / (gt_count[:, None] + track_count[None, :] - potential)
    alpha = np.array(ALPHAS)[:, None] - EPS
    loc = np.zeros(_N)
    pair_keys: list[IntArray] = []
    pair_sims: list[FloatArray] = []
    for frame, (g, t, s) in enumerate(zip(gt, tracks, similarity, strict=True)):
        if len(g) == 0 or len(t) == 0:
            continue
        distinct = distinct_pairs(s > 0)
        if distinct is None:
            rows, cols = linear_sum_assignment(-(alignment[g[:, None], t] * s))
        else:
            rows, cols = distinct
        sims = s[rows, cols]
        matched = sims[None, :] >= alpha  # (alphas, pairs); alpha - eps, as TrackEval
        loc += np.where(matched, sims[None, :], 0.0).sum(axis=1)  # frame by frame, as TrackEval
        pair_keys.append(g[rows] * num_tracks + t[cols])
        pair_sims.append(sims)
        if pairs is not None:
            pairs.append((frame, g[rows], t[cols], sims))
    # The true positives at each alpha are the frames' matched pairs at or above it; every
    # other ground-truth object is a miss, every other track a false positive.
    matched_sims = np.concatenate([np.zeros(0), *pair_sims])
    tp = (matched_sims[None, :] >= alpha).sum(axis=1)
    fn = sum(len(g) for g in gt) - tp
    fp = sum(len(t) for t in tracks) - tp
    ass = np.zeros(_N)
    if pair_keys:
        keys = np.concatenate(pair_keys)
        sims = np.concatenate(pair_sims)
        unique, inverse = np.unique(keys, return_inverse=True)
        g_of, t_of = unique // num_tracks, unique % num_tracks
        denominator = gt_count[g_of] + track_count[t_of]
        for a, value in enumerate(ALPHAS):
            counts = np.bincount(inverse[sims >= value - EPS], minlength=len(unique)).astype(float)
            ass[a] = float(np.sum(counts * counts / np.maximum(1.0, denominator - counts)))
    return HotaCounts(
        tp=tuple(int(v) for v in tp),
        fn=tuple(int(v) for v in fn),
        fp=tuple(int(v) for v in fp),
        ass_sum=tuple(float(v) for v in ass),
        loc_sum=tuple(float(v) for v in loc),
    )
