"""The detector strategy protocol.

A detector turns one :class:`~rgbd_eval.types.Frame` into world-frame
:class:`~rgbd_eval.types.Detection` s. It may keep state from frame to frame
(basso2012 keeps its ground plane), so feed it the frames of one sequence in
order and create a fresh detector per sequence; given the same frames in the
same order it must return the same detections, bit for bit.

Detectors register with :func:`rgbd_eval.plugins.register_detector` (name, config
model, factory, the streams they read, their detection contract, their stages);
:func:`rgbd_eval.components.create_detector` makes one by name.
Stage timing is part of the protocol: after each call, ``last_timings`` holds the
seconds of each named stage (empty when the detector does not split its work), so
``bench`` lists any detector's stages.

A detector whose state across frames is a small value that a cheaper pass over
the frames can compute may say so (:class:`ResumableDetector`): a sweep then
detects one recording in frame chunks on several workers, each chunk from the
state a chain of those cheap passes hands it (:mod:`rgbd_eval.chunked`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Protocol, runtime_checkable

from rgbd_eval.types import Detection, Frame


class Detector(Protocol):
    """Frames in, detections (world frame) out."""

    @property
    def last_timings(self) -> Mapping[str, float]:
        """Seconds of each stage of the last :meth:`detect` call (may be empty)."""
        ...

    def detect(self, frame: Frame) -> list[Detection]:
        """Detect the people in one frame."""
        ...


@runtime_checkable
class ResumableDetector(Detector, Protocol):
    """A detector that can start at any frame from the state it had there.

    Contract: for a fresh detector A fed frames ``0..n-1`` with :meth:`detect`, and a
    fresh detector B fed frames ``0..k-1`` with :meth:`advance`, then
    ``C.restore_state(B.carry_state())`` on a fresh C fed frames ``k..n-1`` with
    :meth:`detect`, C returns the very detections A returned for those frames, bit
    for bit (tests/test_chunked.py checks basso2012). It may also declare
    ``advance_cost``, :meth:`advance`'s time per frame as a fraction of :meth:`detect`'s,
    to balance the chunks of a split detection (:func:`rgbd_eval.chunked.advance_cost`).
    """

    @property
    def advance_reads(self) -> frozenset[str]:
        """The roles whose images :meth:`advance` reads (the others are left undecoded)."""
        ...

    def carry_state(self) -> object:
        """The state carried to the next frame (picklable, a copy)."""
        ...

    def restore_state(self, state: object) -> None:
        """Continue from a state :meth:`carry_state` returned."""
        ...

    def advance(self, frame: Frame) -> None:
        """Update the carried state over ``frame`` exactly as :meth:`detect` would, without detecting."""
        ...
