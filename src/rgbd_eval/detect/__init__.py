"""Detectors: the strategy protocol and one module per method (registered on import)."""

from rgbd_eval.detect.protocol import Detector, create_detector

__all__ = ["Detector", "create_detector"]
