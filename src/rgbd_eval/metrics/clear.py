"""CLEAR MOT scoring of one sequence (Bernardin & Stiefelhagen 2008; seed 000, 7.3).

Matching convention (that of ``motmetrics.MOTAccumulator``): in every frame, a
ground-truth object keeps the track it was last matched to whenever that pair is
still inside the gate, even if the object was unmatched or absent in between and
even if another track is closer; only the remaining objects and tracks are
matched by the Hungarian algorithm on the gated distances. A match whose track
differs from the last track matched to the object, however long ago, is an id
switch. (TrackEval differs: it favours only the pairs matched in the immediately
previous frame, so a pair interrupted for one frame may be replaced by a closer
track there.)

Standard measures (matches, FP, FN, switches, fragmentations, MT/PT/ML, the IDF1
counts) come from ``motmetrics``; the thesis' Main Tr., the similarity sum and
Pinto's recall errors are computed here from the same accumulator events.

A recall error (seed 001, V-C: "ID switches that occurred by initializing a track
with an ID that was previously associated with a different person") is an id
switch onto a track id that was last matched to a different person and was absent
from the scored tracks of the previous frame: an id given up, then handed back to
someone else. A swap of two ids that stay on screen is not one, and a person's
first match is never an id switch, hence never a recall error.
"""

from __future__ import annotations

import functools
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple

import motmetrics as mm

from rgbd_eval.config import EvaluationConfig, Gating
from rgbd_eval.errors import ScoringError
from rgbd_eval.metrics.counts import Counts, Summary, summarize
from rgbd_eval.metrics.gating import distance_matrix, similarity
from rgbd_eval.metrics.selection import FrameSelection, select_frame
from rgbd_eval.types import GroundTruthObject, TrackOutput

_SOLVER = "scipy"
#: The motmetrics measures read into :class:`Counts`.
_STANDARD_METRICS = (
    "num_frames",
    "num_objects",
    "num_predictions",
    "num_matches",
    "num_switches",
    "num_false_positives",
    "num_misses",
    "num_fragmentations",
    "num_unique_objects",
    "mostly_tracked",
    "partially_tracked",
    "mostly_lost",
    "idtp",
    "idfp",
    "idfn",
)


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
    """The counts of one sequence and its per-frame events."""

    counts: Counts
    frames: tuple[FrameEvents, ...]

    def summary(self) -> Summary:
        """The derived measures (:func:`rgbd_eval.metrics.counts.summarize`)."""
        return summarize(self.counts)


@functools.cache
def _metrics_host() -> Any:
    return mm.metrics.create()


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
    gating = config.gating
    threshold = config.effective_threshold()
    if not gt_frames:
        return SequenceScores(Counts.empty(gating, threshold), ())
    # Pin the assignment solver: motmetrics otherwise takes the first one installed
    # (lapsolver, lap, scipy, ...), and solvers may break ties differently.
    with mm.lap.set_default_solver(_SOLVER):
        accumulator = mm.MOTAccumulator(auto_id=True)
        selections: list[FrameSelection] = []
        for index, (gt_objects, tracks) in enumerate(zip(gt_frames, track_frames, strict=True)):
            selection = select_frame(
                index, gt_objects, tracks, gating, threshold, config.min_visibility
            )
            distances = distance_matrix(
                gating, selection.gt_values, selection.track_values, threshold
            )
            accumulator.update(selection.gt_ids, selection.track_ids, distances)
            selections.append(selection)
        standard = _metrics_host().compute(
            accumulator, metrics=list(_STANDARD_METRICS), return_dataframe=False
        )
    frames, extras = _read_events(accumulator, selections, gating)
    counts = Counts(
        gating=gating,
        threshold=threshold,
        num_frames=int(standard["num_frames"]),
        num_gt=int(standard["num_objects"]),
        num_tracks=int(standard["num_predictions"]),
        num_matches=int(standard["num_matches"] + standard["num_switches"]),
        fp=int(standard["num_false_positives"]),
        fn=int(standard["num_misses"]),
        id_switches=int(standard["num_switches"]),
        fragmentations=int(standard["num_fragmentations"]),
        similarity_sum=extras.similarity_sum,
        num_gt_tracks=int(standard["num_unique_objects"]),
        mostly_tracked=int(standard["mostly_tracked"]),
        partly_tracked=int(standard["partially_tracked"]),
        mostly_lost=int(standard["mostly_lost"]),
        main_tr_matches=extras.main_tr_matches,
        idtp=round(float(standard["idtp"])),
        idfp=round(float(standard["idfp"])),
        idfn=round(float(standard["idfn"])),
        recall_errors=extras.recall_errors,
        ignored_gt=sum(len(s.ignored_gt_ids) for s in selections),
        ignored_tracks=sum(len(s.dropped_track_ids) for s in selections),
    )
    return SequenceScores(counts, frames)


class _Extras(NamedTuple):
    similarity_sum: float
    main_tr_matches: int
    recall_errors: int


def _read_events(
    accumulator: Any, selections: list[FrameSelection], gating: Gating
) -> tuple[tuple[FrameEvents, ...], _Extras]:
    """Per-frame events plus the counts motmetrics does not provide."""
    events = accumulator.mot_events
    events = events[events["Type"].isin(("MATCH", "SWITCH", "MISS", "FP"))]
    frame_ids = events.index.get_level_values(0).tolist()
    rows = zip(
        frame_ids,
        events["Type"].astype(str).tolist(),
        events["OId"].tolist(),
        events["HId"].tolist(),
        events["D"].tolist(),
        strict=True,
    )
    matches: list[list[Match]] = [[] for _ in selections]
    misses: list[list[int]] = [[] for _ in selections]
    false_positives: list[list[int]] = [[] for _ in selections]
    pair_frames: Counter[tuple[int, int]] = Counter()
    last_person: dict[int, int] = {}
    similarity_sum = 0.0
    recall_errors = 0
    for frame, kind, oid, hid, distance in rows:
        if kind == "MISS":
            misses[frame].append(int(oid))
            continue
        if kind == "FP":
            false_positives[frame].append(int(hid))
            continue
        gt_id, track_id = int(oid), int(hid)
        switch = kind == "SWITCH"
        previous = last_person.get(track_id)
        recall = (
            switch
            and previous is not None
            and previous != gt_id
            and track_id not in selections[frame - 1].present_track_ids
        )
        last_person[track_id] = gt_id
        recall_errors += recall
        value = similarity(gating, float(distance))
        similarity_sum += value
        pair_frames[gt_id, track_id] += 1
        matches[frame].append(Match(gt_id, track_id, value, switch, recall))
    main_frames: dict[int, int] = {}
    for (gt_id, _), count in pair_frames.items():
        main_frames[gt_id] = max(main_frames.get(gt_id, 0), count)
    frames = tuple(
        FrameEvents(
            frame=i,
            matches=tuple(matches[i]),
            misses=tuple(misses[i]),
            false_positives=tuple(false_positives[i]),
            ignored_gt=tuple(s.ignored_gt_ids),
            ignored_tracks=tuple(s.dropped_track_ids),
        )
        for i, s in enumerate(selections)
    )
    return frames, _Extras(similarity_sum, sum(main_frames.values()), recall_errors)
