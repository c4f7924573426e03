"""The tracker protocol.

A tracker is fed once per frame, in stamp order, with that frame's detections. A
tracker registered with ``needs_frame=True`` (:class:`rgbd_eval.plugins.TrackerSpec`)
also gets the frame itself (track-before-detect, template search, blob images);
the others get ``None`` and can be replayed from cached detections. Like detectors,
trackers report the seconds of their named stages in ``last_timings``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Protocol

from rgbd_eval.config import RunConfig
from rgbd_eval.plugins import detector_spec, tracker_spec
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


def create_tracker(config: RunConfig) -> Tracker:
    """A new tracker for ``config.tracker``, told what ``config.detector`` produces."""
    contract = detector_spec(config.detector.name).contract(config.detector)
    return tracker_spec(config.tracker.name).factory(config.tracker, contract)


def needs_frame(config: RunConfig) -> bool:
    """Whether the configured tracker reads frames (no replay from cached detections)."""
    return tracker_spec(config.tracker.name).needs_frame
