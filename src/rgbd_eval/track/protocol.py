"""The tracker protocol and the name registry trackers are created from."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Protocol, TypeVar

from rgbd_eval.config import RunConfig
from rgbd_eval.errors import ConfigError
from rgbd_eval.types import Detection, TrackOutput


class Tracker(Protocol):
    """A multi-person tracker fed once per frame, in stamp order."""

    def update(self, stamp_ns: int, detections: Sequence[Detection]) -> list[TrackOutput]:
        """Consume one frame's detections (possibly none); return every maintained track."""
        ...


TrackerFactory = Callable[[RunConfig], Tracker]
F = TypeVar("F", bound=TrackerFactory)

_REGISTRY: dict[str, TrackerFactory] = {}


def register_tracker(name: str) -> Callable[[F], F]:
    """Class/function decorator registering a tracker factory under ``name``."""
    if not name or not name.strip():
        raise ValueError(f"tracker name must be a non-empty string, got {name!r}")

    def decorator(factory: F) -> F:
        if name in _REGISTRY and _REGISTRY[name] is not factory:
            raise ValueError(f"tracker name {name!r} is already registered")
        _REGISTRY[name] = factory
        return factory

    return decorator


def known_trackers() -> list[str]:
    """Registered tracker names, sorted."""
    return sorted(_REGISTRY)


def create_tracker(name: str, config: RunConfig) -> Tracker:
    """A new tracker by registered name, configured by ``config``."""
    try:
        factory = _REGISTRY[name]
    except KeyError:
        known = ", ".join(known_trackers()) or "none"
        raise ConfigError(f"unknown tracker {name!r} (known: {known})") from None
    return factory(config)
