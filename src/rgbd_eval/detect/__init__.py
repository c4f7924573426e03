"""Detectors: the strategy protocol, its name registry, and one module per method."""

from rgbd_eval.detect.hog import hog_confidence, hog_confidences
from rgbd_eval.detect.protocol import (
    Detector,
    create_detector,
    known_detectors,
    register_detector,
)

__all__ = [
    "Detector",
    "create_detector",
    "hog_confidence",
    "hog_confidences",
    "known_detectors",
    "register_detector",
]
