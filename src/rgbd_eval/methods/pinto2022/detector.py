"""The pinto2022 detector (seed 001, III-B): 2D person boxes -> localiser -> re-ID embedding.

Per frame: a 2D person detector on the colour image (the seed uses YOLOv3; here any
:class:`~rgbd_eval.detect.person2d.PersonDetector2D`), the people localiser on the depth
image (:mod:`.localise`), and an appearance embedding of each localised box
(:mod:`.reid`). Each :class:`~rgbd_eval.types.Detection` carries the world position, the
box, the detector's score and the embedding; ``dropped_without_depth`` counts the boxes the
localiser dropped over the detector's life.

``last_timings`` holds the seconds of the last call's stages: ``person2d``, ``localise``,
``embed``.
"""

from __future__ import annotations

import time
from collections.abc import Mapping

from rgbd_eval.detect.hog_people import HogParams, HogPeopleDetector
from rgbd_eval.detect.localise import DepthView, localise
from rgbd_eval.detect.person2d import ColourImage, PersonDetector2D
from rgbd_eval.detect.recorded import RecordedDetector, RecordedParams
from rgbd_eval.detect.reid import (
    ColourTextureEmbedder,
    Embedder,
    OnnxEmbedder,
    OnnxEmbedderParams,
    builtin_mobilenet,
)
from rgbd_eval.detect.ssdlite import SsdLiteDetector, SsdParams
from rgbd_eval.detect.yolo_onnx import OnnxYoloDetector, YoloLayout, YoloParams
from rgbd_eval.errors import ConfigError
from rgbd_eval.methods.pinto2022.detector_config import (
    PersonBackend,
    PersonDetectorConfig,
    Pinto2022DetectorConfig,
    ReidBackend,
    ReidConfig,
)
from rgbd_eval.plugins import DetectionContract, DetectorSpec, StreamSpec, register_detector
from rgbd_eval.types import Detection, Frame

STAGES = ("person2d", "localise", "embed")


class Pinto2022Detector:
    """Detector protocol implementation composing the three stages of III-B."""

    def __init__(self, person: PersonDetector2D, embedder: Embedder) -> None:
        self.person = person
        self.embedder = embedder
        self.dropped_without_depth = 0
        self._timings: dict[str, float] = dict.fromkeys(STAGES, 0.0)

    @property
    def last_timings(self) -> Mapping[str, float]:
        return self._timings

    def detect(self, frame: Frame) -> list[Detection]:
        t0 = time.perf_counter()
        boxes = self.person.detect(ColourImage(frame.index, frame.stamp_ns, frame.rgb))
        t1 = time.perf_counter()
        view = DepthView(
            depth=frame.depth,
            depth_camera=frame.depth_camera,
            rgb_camera=frame.rgb_camera,
            depth_to_rgb=frame.depth_to_rgb,
            camera_pose=frame.camera_pose,
        )
        located = localise(view, [b.box for b in boxes])
        self.dropped_without_depth += located.dropped
        t2 = time.perf_counter()
        embeddings = self.embedder.embed(frame.rgb, [lb.box for lb in located.boxes])
        t3 = time.perf_counter()
        self._timings = {"person2d": t1 - t0, "localise": t2 - t1, "embed": t3 - t2}
        return [
            Detection(
                position=lb.position,
                height=lb.height,
                confidence=boxes[i].score,
                box2d=lb.box,
                distance=lb.depth,
                appearance=embeddings[k],
            )
            for k, (i, lb) in enumerate(zip(located.kept, located.boxes, strict=True))
        ]


def build_person_detector(config: PersonDetectorConfig, threads: int = 1) -> PersonDetector2D:
    """The 2D person detector a config names."""
    b = config.backend
    if b is PersonBackend.SSDLITE:
        return SsdLiteDetector(
            config.model, SsdParams(config.score_threshold, config.nms_iou, threads)
        )
    if b is PersonBackend.ONNX:
        if config.model is None:  # the config model refuses this; kept for the type checker
            raise ConfigError("detector.person.model is required for backend 'onnx'")
        params = YoloParams(
            config.score_threshold,
            config.nms_iou,
            config.person_class,
            YoloLayout(config.layout),
            config.input_size,
            threads,
        )
        return OnnxYoloDetector(config.model, params)
    if b is PersonBackend.HOG:
        return HogPeopleDetector(HogParams(scale_factor=config.hog_scale, nms_iou=config.nms_iou))
    if config.source is None:
        raise ConfigError("detector.person.source is required for backend 'recorded'")
    recorded = RecordedParams(
        tuple(config.classes), config.score_threshold, round(config.max_gap_ms * 1e6)
    )
    if config.source.suffix == ".txt":
        return RecordedDetector.from_det_txt(config.source, recorded)
    return RecordedDetector.from_topic(config.source, config.topic or "", recorded)


def build_embedder(config: ReidConfig, threads: int = 1) -> Embedder:
    """The re-ID embedder a config names."""
    if config.backend is ReidBackend.COLOUR_TEXTURE:
        return ColourTextureEmbedder()
    if config.backend is ReidBackend.MOBILENET:
        return builtin_mobilenet(threads)
    if config.model is None:
        raise ConfigError("detector.reid.model is required for backend 'onnx'")
    params = OnnxEmbedderParams(
        input_width=config.input_width,
        input_height=config.input_height,
        mean=config.mean,
        std=config.std,
        l2_normalise=config.l2_normalise,
        threads=threads,
    )
    return OnnxEmbedder(config.model, params)


def _build(config: Pinto2022DetectorConfig) -> Pinto2022Detector:
    return Pinto2022Detector(
        build_person_detector(config.person, config.threads),
        build_embedder(config.reid, config.threads),
    )


def _contract(config: Pinto2022DetectorConfig) -> DetectionContract:
    """Detections carry a world position, the box and an embedding of the configured kind."""
    sizes = {
        ReidBackend.COLOUR_TEXTURE: ColourTextureEmbedder().dimension,
        ReidBackend.MOBILENET: 1280,
    }
    size = sizes.get(config.reid.backend, 0)  # an ONNX file's size is known once it is loaded
    return DetectionContract(appearance=config.appearance_kind(), appearance_size=size)


SPEC = register_detector(
    DetectorSpec(
        name="pinto2022",
        config_model=Pinto2022DetectorConfig,
        factory=_build,
        streams=(StreamSpec("colour"), StreamSpec("depth")),
        contract=_contract,
        stages=STAGES,
        summary="2D CNN person detector, depth localiser (25th percentile), re-ID embedding "
        "(seed 001, III-B)",
    )
)
