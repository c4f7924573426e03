"""The tracker protocol.

A tracker is fed once per frame, in stamp order, with that frame's detections. A
tracker registered with ``needs_frame=True`` (:class:`rgbd_eval.plugins.TrackerSpec`)
also gets the frame itself (track-before-detect, template search, blob images);
the others get ``None`` and can be replayed from cached detections. Like detectors,
trackers report the seconds of their named stages in ``last_timings``;
:func:`rgbd_eval.components.create_tracker` makes one by name.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Protocol

from rgbd_eval.types import Detection, Frame, TrackOutput


class Tracker(Protocol):
    """A multi-person tracker fed once per frame, in stamp order."""

    @property
    def last_timings(self) -> Mapping[str, float]:
        """Seconds of each stage of the last :meth:`update` call (may be empty)."""
        ...

    def update(
        self, stamp_ns: int, detections: Sequence[Detection], frame: Frame | None = None
    ) -> list[TrackOutput]:
        """Consume one frame's detections (possibly none); return every maintained track."""
        ...
