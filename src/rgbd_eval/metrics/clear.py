"""CLEAR MOT scoring of one sequence (Bernardin & Stiefelhagen 2008; seed 000, 7.3).

The matching follows one of two references exactly, chosen by
``EvaluationConfig.convention`` (see :mod:`rgbd_eval.metrics.matching`):
``motchallenge`` (the official devkit, as TrackEval reproduces it) or
``motmetrics`` (py-motmetrics 1.4). The conventions also differ in two counts:

- MT/PT/ML: ``motchallenge`` counts an object as mostly tracked when it is
  matched in more than 80 % of its frames, ``motmetrics`` at 80 % or more; both
  count mostly lost below 20 %.
- Fragmentations: ``motchallenge`` counts, per object, the tracked stretches after
  the first one, where a stretch breaks at any frame (with ground truth and
  tracks) in which the object is not matched, absent frames included;
  ``motmetrics`` counts the returns from missed to tracked over the frames the
  object is present in.

IDF1 (Ristani et al. 2016) is the optimal one-to-one assignment of ground-truth
ids to track ids over the sequence, counting the frames in which a pair is
inside the gate; HOTA is computed as TrackEval does (:mod:`rgbd_eval.metrics.hota`).
The thesis' Main Tr., the similarity sum and Pinto's recall errors come from the
same matches.

A recall error (seed 001, V-C: "ID switches that occurred by initializing a track
with an ID that was previously associated with a different person") is an id
switch onto a track id that was last matched to a different person and was absent
from the scored tracks of the previous frame: an id given up, then handed back to
someone else. A swap of two ids that stay on screen is not one, and a person's
first match is never an id switch, hence never a recall error.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import NamedTuple

import numpy as np
from scipy.optimize import linear_sum_assignment

from rgbd_eval.config import Convention, EvaluationConfig, Gating
from rgbd_eval.errors import ScoringError
from rgbd_eval.metrics.counts import Counts, Summary, summarize
from rgbd_eval.metrics.frames import FrameTable, build_table, empty_table
from rgbd_eval.metrics.gating import gate, similarity_from_measure
from rgbd_eval.metrics.hota import hota_counts
from rgbd_eval.metrics.matching import (
    IntArray,
    MotChallengeMatcher,
    MotMetricsMatcher,
)
from rgbd_eval.metrics.selection import FrameSelection, select_frames
from rgbd_eval.types import GroundTruthObject, TrackOutput


class Match(NamedTuple):
    """One ground-truth object matched to one track in one frame.

    ``similarity`` is IoU (IoU gating) or distance in metres (metric gating).
    """

    gt_id: int
    track_id: int
    similarity: float
    id_switch: bool
    recall_error: bool


@dataclass(frozen=True)
class FrameEvents:
    """The scoring events of one frame (for reports and drawings)."""

    frame: int
    matches: tuple[Match, ...]
    misses: tuple[int, ...]
    false_positives: tuple[int, ...]
    ignored_gt: tuple[int, ...]
    ignored_tracks: tuple[int, ...]


@dataclass(frozen=True)
class SequenceScores:
    """The counts of one sequence, its per-frame events and, with dense ids, the per-frame
    contributions behind the counts (:class:`~rgbd_eval.metrics.frames.FrameTable`)."""

    counts: Counts
    frames: tuple[FrameEvents, ...]
    table: FrameTable = field(default_factory=empty_table, compare=False, repr=False)

    def summary(self) -> Summary:
        """The derived measures (:func:`rgbd_eval.metrics.counts.summarize`)."""
        return summarize(self.counts)

    def placed(self, first: int, total: int) -> SequenceScores:
        """These scores of frames ``first..`` of a ``total``-frame sequence, the frames before
        and after given empty events (not scored): frame ``k`` here is ``first + k`` there.
        The per-frame table stays that of the scored frames (its frame ``k`` is ``first + k``)."""
        if first == 0 and len(self.frames) == total:
            return self
        scored = {first + e.frame: replace(e, frame=first + e.frame) for e in self.frames}
        frames = tuple(scored.get(k) or FrameEvents(k, (), (), (), (), ()) for k in range(total))
        return SequenceScores(self.counts, frames, self.table)


def evaluate_sequence(
    gt_frames: Sequence[Sequence[GroundTruthObject]],
    track_frames: Sequence[Sequence[TrackOutput]],
    config: EvaluationConfig,
) -> SequenceScores:
    """Score one sequence: ``gt_frames[i]`` and ``track_frames[i]`` belong to frame ``i``.

    Raises :class:`~rgbd_eval.errors.ScoringError` when the two are not equally
    long, when an id repeats within a frame, or when an object lacks what the
    gating needs (see :mod:`rgbd_eval.metrics.selection`). An empty sequence
    gives empty counts.
    """
    if len(gt_frames) != len(track_frames):
        raise ScoringError(
            f"ground truth has {len(gt_frames)} frames but the tracker output has "
            f"{len(track_frames)}; they must be index-aligned"
        )
    threshold = config.effective_threshold()
    selections = select_frames(
        gt_frames, track_frames, config.gating, threshold, config.min_visibility
    )
    return score_selections(selections, config)


def _dense(per_frame: Sequence[Sequence[int]]) -> tuple[list[IntArray], IntArray]:
    """Per-frame ids as dense indices ``0..K-1`` (in sorted id order), and the K ids."""
    flat = np.fromiter(
        (i for ids in per_frame for i in ids), dtype=np.int64, count=sum(map(len, per_frame))
    )
    unique, inverse = np.unique(flat, return_inverse=True)
    bounds = np.cumsum([len(ids) for ids in per_frame])[:-1]
    return np.split(inverse.astype(np.int64), bounds), unique


def score_selections(
    selections: Sequence[FrameSelection], config: EvaluationConfig
) -> SequenceScores:
    """Score frames already split by :func:`~rgbd_eval.metrics.selection.select_frame`."""
    gating, convention = config.gating, config.convention
    threshold = config.effective_threshold()
    if not selections:
        return SequenceScores(Counts.empty(gating, threshold, convention), ())
    gts, gt_ids = _dense([s.gt_ids for s in selections])
    num_gt = len(gt_ids)
    # Present tracks include the dropped ones; the scored tracks are their subset.
    n = len(selections)
    both, track_ids = _dense(
        [s.track_ids for s in selections] + [sorted(s.present_track_ids) for s in selections]
    )
    num_tracks = len(track_ids)
    tracks, present = both[:n], both[n:]
    trackeval = convention is Convention.MOTCHALLENGE
    mc = MotChallengeMatcher(num_gt)
    mm = MotMetricsMatcher(num_gt, num_tracks)
    last_person = np.full(num_tracks, -1, dtype=np.int64)
    was_present = np.zeros(num_tracks, dtype=bool)
    similarities = []
    potential: list[IntArray] = []
    matched_gt: list[IntArray] = []
    matched_pairs: list[IntArray] = []
    matched_tracks: list[IntArray] = []
    switches: list[np.ndarray] = []
    recalls: list[np.ndarray] = []
    matched_values: list[np.ndarray] = []
    frames: list[FrameEvents] = []
    similarity_sum = 0.0
    id_switches = recall_errors = 0
    for i, (sel, g, t) in enumerate(zip(selections, gts, tracks, strict=True)):
        measure = sel.measure
        similarity = similarity_from_measure(gating, measure, threshold)
        similarities.append(similarity)
        valid = gate(gating, measure, similarity, threshold, exact_trackeval=trackeval)
        if trackeval:
            match = mc.step(g, t, similarity, valid)
        else:
            distance = 1.0 - measure if gating is Gating.IOU else measure
            match = mm.step(g, t, distance, valid)
        rows, cols = np.nonzero(valid)
        potential.append(g[rows] * num_tracks + t[cols])
        mg, mt = g[match.rows], t[match.cols]
        values = measure[match.rows, match.cols]
        recall = match.switch & (last_person[mt] >= 0) & (last_person[mt] != mg)
        recall &= ~was_present[mt]
        last_person[mt] = mg
        if i:
            was_present[present[i - 1]] = False
        was_present[present[i]] = True
        similarity_sum += float(values.sum())
        id_switches += int(match.switch.sum())
        recall_errors += int(recall.sum())
        matched_gt.append(mg)
        matched_pairs.append(mg * num_tracks + mt)
        matched_tracks.append(mt)
        switches.append(match.switch)
        recalls.append(recall)
        matched_values.append(values)
        frames.append(_frame_events(i, sel, match.rows, match.cols, values, match.switch, recall))
    all_gt = np.concatenate(gts)
    all_matched = np.concatenate(matched_gt)
    ratio = np.bincount(all_matched, minlength=num_gt) / np.maximum(
        1, np.bincount(all_gt, minlength=num_gt)
    )
    mostly = ratio > 0.8 if trackeval else ratio >= 0.8
    partly = ~mostly & (ratio >= 0.2)
    pair_keys, pair_counts = np.unique(np.concatenate(matched_pairs), return_counts=True)
    main = np.zeros(num_gt, dtype=np.int64)
    np.maximum.at(main, pair_keys // max(num_tracks, 1), pair_counts)
    idtp = _idtp(np.concatenate(potential), num_tracks)
    num_gt_instances = len(all_gt)
    num_track_instances = sum(len(x) for x in tracks)
    hota_pairs: list[tuple[int, IntArray, IntArray, np.ndarray]] = []
    hota = hota_counts(gts, tracks, similarities, num_gt, num_tracks, hota_pairs)
    counts = Counts(
        gating=gating,
        threshold=threshold,
        convention=convention,
        num_frames=len(selections),
        num_gt=num_gt_instances,
        num_tracks=num_track_instances,
        num_matches=len(all_matched),
        fp=num_track_instances - len(all_matched),
        fn=num_gt_instances - len(all_matched),
        id_switches=id_switches,
        fragmentations=mc.fragmentations() if trackeval else mm.frags,
        similarity_sum=similarity_sum,
        num_gt_tracks=num_gt,
        mostly_tracked=int(mostly.sum()),
        partly_tracked=int(partly.sum()),
        mostly_lost=int(num_gt - mostly.sum() - partly.sum()),
        main_tr_matches=int(main.sum()),
        idtp=idtp,
        idfp=num_track_instances - idtp,
        idfn=num_gt_instances - idtp,
        recall_errors=recall_errors,
        ignored_gt=sum(len(s.ignored_gt_ids) for s in selections),
        ignored_tracks=sum(len(s.dropped_track_ids) for s in selections),
        hota=hota,
    )
    table = build_table(
        gt_ids,
        track_ids,
        gts,
        tracks,
        matched_gt,
        matched_tracks,
        switches,
        recalls,
        matched_values,
        potential,
        hota_pairs,
    )
    return SequenceScores(counts, tuple(frames), table)


def _idtp(pair_keys: IntArray, num_tracks: int) -> int:
    """Identity true positives: the best one-to-one id assignment by frames inside the gate."""
    if len(pair_keys) == 0:
        return 0
    keys, counts = np.unique(pair_keys, return_counts=True)
    g_rows, g = np.unique(keys // num_tracks, return_inverse=True)
    t_cols, t = np.unique(keys % num_tracks, return_inverse=True)
    weights = np.zeros((len(g_rows), len(t_cols)))
    weights[g, t] = counts
    rows, cols = linear_sum_assignment(weights, maximize=True)
    return int(weights[rows, cols].sum())


def _frame_events(
    index: int,
    sel: FrameSelection,
    rows: IntArray,
    cols: IntArray,
    values: np.ndarray,
    switch: np.ndarray,
    recall: np.ndarray,
) -> FrameEvents:
    matched_rows = set(rows.tolist())
    matched_cols = set(cols.tolist())
    return FrameEvents(
        frame=index,
        matches=tuple(
            map(
                Match,
                [sel.gt_ids[r] for r in rows.tolist()],
                [sel.track_ids[c] for c in cols.tolist()],
                values.tolist(),
                switch.tolist(),
                recall.tolist(),
            )
        ),
        misses=tuple(x for k, x in enumerate(sel.gt_ids) if k not in matched_rows),
        false_positives=tuple(x for k, x in enumerate(sel.track_ids) if k not in matched_cols),
        ignored_gt=tuple(sel.ignored_gt_ids),
        ignored_tracks=tuple(sel.dropped_track_ids),
    )
