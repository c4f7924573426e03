"""What the pictures show, derived from the scorer's per-frame events.

Counts here equal those of :class:`rgbd_eval.metrics.Counts`: the FP, FN and
id switches of :func:`frame_errors` sum to ``fp``, ``fn`` and ``id_switches``, and
the fragmentation markers of :func:`markers` number ``fragmentations`` (motmetrics'
definition: within the span from an object's first to its last match, each change
from matched to missed).
"""

from __future__ import annotations

import enum
import itertools
from collections.abc import Sequence
from dataclasses import dataclass

from rgbd_eval.metrics import FrameEvents


@dataclass(frozen=True)
class FrameErrors:
    """The errors of one frame."""

    frame: int
    fp: int
    fn: int
    id_switches: int

    @property
    def total(self) -> int:
        """All errors of the frame (the numerator of MOTA's error share)."""
        return self.fp + self.fn + self.id_switches


class MarkerKind(enum.Enum):
    ID_SWITCH = "id switch"
    FRAGMENTATION = "fragmentation"


@dataclass(frozen=True)
class Marker:
    """An id switch or a fragmentation of one ground-truth object in one frame."""

    frame: int
    gt_id: int
    kind: MarkerKind


def frame_errors(frames: Sequence[FrameEvents]) -> list[FrameErrors]:
    """FP, FN and id switches of every frame."""
    return [
        FrameErrors(
            frame=f.frame,
            fp=len(f.false_positives),
            fn=len(f.misses),
            id_switches=sum(m.id_switch for m in f.matches),
        )
        for f in frames
    ]


def markers(frames: Sequence[FrameEvents]) -> list[Marker]:
    """Id switches (at the switching match) and fragmentations (at the first missed frame)."""
    out = [
        Marker(f.frame, m.gt_id, MarkerKind.ID_SWITCH)
        for f in frames
        for m in f.matches
        if m.id_switch
    ]
    # Per object, its scored frames in order: (frame, matched?).
    history: dict[int, list[tuple[int, bool]]] = {}
    for f in frames:
        for m in f.matches:
            history.setdefault(m.gt_id, []).append((f.frame, True))
        for gt_id in f.misses:
            history.setdefault(gt_id, []).append((f.frame, False))
    for gt_id, states in history.items():
        matched_at = [i for i, (_, matched) in enumerate(states) if matched]
        if not matched_at:
            continue
        span = states[matched_at[0] : matched_at[-1] + 1]
        for (_, before), (frame, now) in itertools.pairwise(span):
            if before and not now:
                out.append(Marker(frame, gt_id, MarkerKind.FRAGMENTATION))
    return sorted(out, key=lambda m: (m.frame, m.gt_id, m.kind.value))


def worst_frames(errors: Sequence[FrameErrors], count: int) -> list[int]:
    """Up to ``count`` frames with the most errors, spread over the sequence, in frame order.

    Frames are taken greedily by error count (earliest first on ties), skipping any
    within ``len(errors) // (4 * count)`` frames of one already taken, so that one
    long failure does not fill the whole strip. Frames without errors are never taken.
    """
    if count < 1:
        return []
    separation = len(errors) // (4 * count)
    chosen: list[int] = []
    for e in sorted(errors, key=lambda e: (-e.total, e.frame)):
        if e.total == 0 or len(chosen) == count:
            break
        if all(abs(e.frame - c) > separation for c in chosen):
            chosen.append(e.frame)
    return sorted(chosen)
