"""cielniak2010 detector: none. The method is track-before-detect (seed 004, section 3):
its tracker reads the thermal image and starts filters itself (a sequential detector),
so this stage passes the frame on without detections."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Literal

from rgbd_eval.config import ComponentConfig
from rgbd_eval.plugins import DetectionContract, DetectorSpec, StreamSpec, register_detector
from rgbd_eval.types import Detection, Frame


class Cielniak2010DetectorConfig(ComponentConfig):
    name: Literal["cielniak2010"] = "cielniak2010"


class Cielniak2010Detector:
    """Returns no detections; the tracker detects in the thermal image."""

    def __init__(self, config: Cielniak2010DetectorConfig) -> None:
        self.cfg = config
        self.last_timings: Mapping[str, float] = {}

    def detect(self, frame: Frame) -> list[Detection]:
        return []


register_detector(
    DetectorSpec(
        "cielniak2010",
        Cielniak2010DetectorConfig,
        Cielniak2010Detector,
        streams=(StreamSpec("thermal"), StreamSpec("colour")),
        contract=lambda _c: DetectionContract(world_position=False, box2d=False),
        summary="none: track-before-detect, the tracker reads the thermal image",
    )
)
