"""The detector strategy protocol.

A detector turns one :class:`~rgbd_eval.types.Frame` into world-frame
:class:`~rgbd_eval.types.Detection` s. It may keep state from frame to frame
(basso2012 keeps its ground plane), so feed it the frames of one sequence in
order and create a fresh detector per sequence; given the same frames in the
same order it must return the same detections, bit for bit.

Detectors register with :func:`rgbd_eval.plugins.register_detector` (name, config
model, factory, the streams they read, their detection contract, their stages).
Stage timing is part of the protocol: after each call, ``last_timings`` holds the
seconds of each named stage (empty when the detector does not split its work), so
``bench`` lists any detector's stages.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Protocol

from rgbd_eval.config import RunConfig
from rgbd_eval.plugins import detector_spec
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


def create_detector(config: RunConfig) -> Detector:
    """A new detector for ``config.detector`` (ConfigError for an unknown name)."""
    return detector_spec(config.detector.name).factory(config.detector)
