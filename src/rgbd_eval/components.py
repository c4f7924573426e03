"""A run config's detector and tracker, made through the registry of names.

The registry (:mod:`rgbd_eval.plugins`) maps each name to its factory, so nothing here
imports a method: a method's package registers, the pipeline, sweeps, ``bench`` and
``reproduce`` create by name.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from rgbd_eval.plugins import detector_spec, tracker_spec

if TYPE_CHECKING:
    from rgbd_eval.config import RunConfig
    from rgbd_eval.detect.protocol import Detector
    from rgbd_eval.track.protocol import Tracker


def create_detector(config: RunConfig) -> Detector:
    """A new detector for ``config.detector`` (ConfigError for an unknown name)."""
    return detector_spec(config.detector.name).factory(config.detector)


def create_tracker(config: RunConfig) -> Tracker:
    """A new tracker for ``config.tracker``, told what ``config.detector`` produces."""
    contract = detector_spec(config.detector.name).contract(config.detector)
    return tracker_spec(config.tracker.name).factory(config.tracker, contract)


def needs_frame(config: RunConfig) -> bool:
    """Whether the configured tracker reads frames (no replay from cached detections)."""
    return tracker_spec(config.tracker.name).needs_frame
