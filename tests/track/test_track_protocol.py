"""The plug-in registry (rgbd_eval.plugins): names, config models, pairing contracts."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Literal

import pytest

from rgbd_eval import plugins
from rgbd_eval.components import create_tracker
from rgbd_eval.config import ComponentConfig, build_config
from rgbd_eval.errors import ConfigError
from rgbd_eval.types import Detection, Frame, TrackOutput, Visibility


class EchoConfig(ComponentConfig):
    name: Literal["test-echo"] = "test-echo"
    offset: int = 0


class _Echo:
    """Outputs one track per detection, ids by order: enough to see the registry work."""

    last_timings: Mapping[str, float] = {}

    def __init__(self, config: EchoConfig, contract: plugins.DetectionContract) -> None:
        self.config = config
        self.contract = contract

    def update(
        self, stamp_ns: int, detections: Sequence[Detection], frame: Frame | None = None
    ) -> list[TrackOutput]:
        return [
            TrackOutput(
                i + self.config.offset,
                d.position[0],
                d.position[1],
                d.height,
                d.box2d,
                Visibility.VISIBLE,
            )
            for i, d in enumerate(detections)
        ]


def _needs_histograms(_cfg: EchoConfig, contract: plugins.DetectionContract) -> str | None:
    return None if contract.appearance == "rgb_histogram" else "needs colour histograms"


def test_register_create_and_reject_duplicates() -> None:
    spec = plugins.TrackerSpec("test-echo", EchoConfig, _Echo, check=_needs_histograms)
    try:
        plugins.register_tracker(spec)
        plugins.register_tracker(spec)  # the same spec again is fine
        assert "test-echo" in plugins.known("trackers")
        config = build_config({"tracker": {"name": "test-echo", "offset": 3}})
        assert isinstance(config.tracker, EchoConfig) and config.tracker.offset == 3
        tracker = create_tracker(config)
        assert isinstance(tracker, _Echo)
        # basso2012's detector states its histograms: 8 bins per channel -> 512 values.
        assert tracker.contract.appearance_size == 512
        with pytest.raises(ValueError, match="already registered"):
            plugins.register_tracker(plugins.TrackerSpec("test-echo", EchoConfig, _Echo))
        # unknown keys of the selected model are refused, naming the key
        with pytest.raises(ConfigError, match=r"tracker\.gate: unknown key"):
            build_config({"tracker": {"name": "test-echo", "gate": 1}})
        # a switch of tracker by --set starts the section afresh (basso2012's keys do not apply)
        cfg = build_config({"tracker": {"min_confidence": 0.1}}, [("tracker.name", "test-echo")])
        assert cfg.tracker.name == "test-echo"
    finally:
        plugins._REGISTRY.trackers.pop("test-echo", None)


def test_bad_registrations() -> None:
    with pytest.raises(ValueError, match="non-empty"):
        plugins.register_tracker(plugins.TrackerSpec(" ", EchoConfig, _Echo))
    with pytest.raises(ValueError, match="must default name to 'other'"):
        plugins.register_tracker(plugins.TrackerSpec("other", EchoConfig, _Echo))
    with pytest.raises(ValueError, match="stream role 'sonar'"):
        plugins.StreamSpec("sonar")


def test_unknown_names_list_the_known_ones() -> None:
    with pytest.raises(ConfigError, match=r"unknown method 'x' \(known: .*basso2012"):
        build_config({"method": "x"})
    with pytest.raises(ConfigError, match=r"unknown tracker 'x' \(known: .*basso2012"):
        build_config({"tracker": {"name": "x"}})


def test_pairing_is_refused_where_the_contract_does_not_allow() -> None:
    """basso2012's classifier learns colour histograms: a detector without them cannot feed it."""

    class PlainConfig(ComponentConfig):
        name: Literal["test-plain"] = "test-plain"

    spec = plugins.DetectorSpec(
        "test-plain",
        PlainConfig,
        factory=lambda _c: None,  # type: ignore[arg-type,return-value]
        streams=(plugins.StreamSpec("depth"),),
        contract=lambda _c: plugins.DetectionContract(appearance=None),
    )
    try:
        plugins.register_detector(spec)
        with pytest.raises(ConfigError, match=r"cannot feed tracker 'basso2012'.*classifier=false"):
            build_config({"detector": {"name": "test-plain"}})
        cfg = build_config({"detector": {"name": "test-plain"}, "tracker": {"classifier": False}})
        assert cfg.detector.name == "test-plain"
    finally:
        plugins._REGISTRY.detectors.pop("test-plain", None)
