"""The tracker name registry."""

from __future__ import annotations

from collections.abc import Sequence

import pytest

from rgbd_eval.config import RunConfig
from rgbd_eval.errors import ConfigError
from rgbd_eval.track import protocol
from rgbd_eval.types import Detection, TrackOutput, Visibility


class _Echo:
    """Outputs one track per detection, ids by order: enough to see the registry work."""

    def __init__(self, config: RunConfig) -> None:
        self.config = config

    def update(self, stamp_ns: int, detections: Sequence[Detection]) -> list[TrackOutput]:
        return [
            TrackOutput(i, d.position[0], d.position[1], d.height, d.box2d, Visibility.VISIBLE)
            for i, d in enumerate(detections)
        ]


def test_register_create_and_reject_duplicates() -> None:
    name = "test-echo"
    try:
        assert protocol.register_tracker(name)(_Echo) is _Echo
        assert protocol.register_tracker(name)(_Echo) is _Echo  # same factory again is fine
        assert name in protocol.known_trackers()
        config = RunConfig()
        tracker = protocol.create_tracker(name, config)
        assert isinstance(tracker, _Echo) and tracker.config is config
        with pytest.raises(ValueError, match="already registered"):
            protocol.register_tracker(name)(lambda c: _Echo(c))
    finally:
        protocol._REGISTRY.pop(name, None)
    assert name not in protocol.known_trackers()


def test_bad_names() -> None:
    with pytest.raises(ValueError, match="non-empty"):
        protocol.register_tracker(" ")
    with pytest.raises(ConfigError, match="unknown tracker 'x'"):
        protocol.create_tracker("x", RunConfig())
