"""What the pictures show, derived from the scorer's per-frame events.

Counts here equal those of :class:`rgbd_eval.metrics.Counts`: the FP, FN and
id switches of :func:`frame_errors` sum to ``fp``, ``fn`` and ``id_switches``, and
the fragmentation markers of :func:`markers` number ``fragmentations`` under either
convention (see :mod:`rgbd_eval.metrics.clear`):

- ``motchallenge``: an object's tracked stretches after its first; a stretch breaks
  at any scored frame (one with ground truth and tracks) where the object is not
  matched, absent included. Marked where a later stretch starts.
- ``motmetrics``: over the frames the object is present in, each return from missed
  to matched. Marked at the return.
"""

from __future__ import annotations

import enum
import itertools
from collections.abc import Sequence
from dataclasses import dataclass

from rgbd_eval.config import Convention
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


def markers(frames: Sequence[FrameEvents], convention: Convention) -> list[Marker]:
    """Id switches (at the switching match) and fragmentations (at the frame that resumes)."""
    out = [
        Marker(f.frame, m.gt_id, MarkerKind.ID_SWITCH)
        for f in frames
        for m in f.matches
        if m.id_switch
    ]
    if convention is Convention.MOTCHALLENGE:
        out += _motchallenge_fragmentations(frames)
    else:
        out += _motmetrics_fragmentations(frames)
    return sorted(out, key=lambda m: (m.frame, m.gt_id, m.kind.value))


def _motchallenge_fragmentations(frames: Sequence[FrameEvents]) -> list[Marker]:
    out = []
    previous: set[int] = set()  # objects matched in the previous scored frame
    started: set[int] = set()  # objects tracked at least once
    for f in frames:
        if not (f.matches or f.misses) or not (f.matches or f.false_positives):
            continue  # no scored ground truth or no scored track: the matcher skips the frame
        matched = {m.gt_id for m in f.matches}
        for gt_id in sorted(matched - previous):
            if gt_id in started:
                out.append(Marker(f.frame, gt_id, MarkerKind.FRAGMENTATION))
            started.add(gt_id)
        previous = matched
    return out


def _motmetrics_fragmentations(frames: Sequence[FrameEvents]) -> list[Marker]:
    out = []
    tracked: set[int] = set()  # objects matched at least once
    lost: set[int] = set()  # of those, missed since their last match
    for f in frames:
        for m in f.matches:
            if m.gt_id in lost:
                out.append(Marker(f.frame, m.gt_id, MarkerKind.FRAGMENTATION))
                lost.discard(m.gt_id)
            tracked.add(m.gt_id)
        lost |= tracked.intersection(f.misses)
    return out


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


def busiest_frames(tracks: Sequence[int], count: int) -> list[int]:
    """Up to ``count`` frames spread over the sequence, each with the most tracks of its stretch.

    ``tracks`` is the number of tracks of every frame. The sequence is cut into ``count``
    equal stretches; of each, the frame with the most tracks is taken (on ties the one
    nearest the stretch's middle, then the earlier), so a frame without tracks is taken
    only from a stretch that has none, to show the scene.
    """
    n = len(tracks)
    bounds = [round(k * n / count) for k in range(count + 1)] if count > 0 else []
    chosen = []
    for start, stop in itertools.pairwise(bounds):
        if start < stop:
            middle = (start + stop - 1) / 2
            chosen.append(min(range(start, stop), key=lambda i: (-tracks[i], abs(i - middle), i)))
    return chosen
