"""The detector strategy protocol and its name registry.

A detector turns one :class:`~rgbd_eval.types.Frame` into world-frame
:class:`~rgbd_eval.types.Detection` s. It may keep state from frame to frame
(basso2012 keeps its ground plane), so feed it the frames of one sequence in
order and create a fresh detector per sequence; given the same frames in the
same order it must return the same detections, bit for bit.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol, runtime_checkable

from rgbd_eval.config import RunConfig
from rgbd_eval.errors import ConfigError
from rgbd_eval.types import Detection, Frame


@runtime_checkable
class Detector(Protocol):
    """Frames in, detections (world frame) out."""

    def detect(self, frame: Frame) -> list[Detection]:
        """Detect the people in one frame."""
        ...


#: Builds a detector from a run config.
DetectorFactory = Callable[[RunConfig], Detector]

_REGISTRY: dict[str, DetectorFactory] = {}


def register_detector(name: str) -> Callable[[DetectorFactory], DetectorFactory]:
    """Class/function decorator registering a detector factory under ``name``."""
    if not name or not name.strip():
        raise ValueError(f"detector name must be a non-empty string, got {name!r}")

    def decorate(factory: DetectorFactory) -> DetectorFactory:
        existing = _REGISTRY.get(name)
        if existing is not None and existing is not factory:
            raise ValueError(f"detector name {name!r} is already registered to {existing!r}")
        _REGISTRY[name] = factory
        return factory

    return decorate


def known_detectors() -> list[str]:
    """The registered detector names, sorted."""
    _load_builtin_detectors()
    return sorted(_REGISTRY)


def create_detector(name: str, config: RunConfig) -> Detector:
    """A new detector by name; :class:`ConfigError` for an unknown name."""
    _load_builtin_detectors()
    factory = _REGISTRY.get(name)
    if factory is None:
        known = ", ".join(sorted(_REGISTRY)) or "none"
        raise ConfigError(f"unknown detector {name!r} (known: {known})")
    return factory(config)


def _load_builtin_detectors() -> None:
    """Import the modules whose import registers the built-in detectors."""
    from rgbd_eval.detect import basso2012  # noqa: F401
