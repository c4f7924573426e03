"""A YOLO-family person detector from an ONNX file (seed 001, III-B uses YOLOv3).

Input: the image letterboxed to the network size (grey 114 padding), RGB, scaled to
[0, 1], NCHW float32. Output layouts (one output tensor, batch 1):

- ``v5``: ``(1, N, 5 + C)`` rows ``cx, cy, w, h, objectness, class scores``: YOLOv3/v5/v7 as
  exported by their reference repositories; score = objectness x class score;
- ``v8``: ``(1, 4 + C, N)`` columns ``cx, cy, w, h, class scores`` (no objectness):
  YOLOv8/v11 exports.

``auto`` takes ``v8`` when the second axis is shorter than the third, else ``v5``.
Boxes of the person class above ``score_threshold`` go through greedy NMS at ``nms_iou``.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from rgbd_eval.detect.onnx_session import open_session
from rgbd_eval.detect.person2d import ColourImage, PersonBox, letterbox, nms, to_person_boxes
from rgbd_eval.errors import ConfigError

FloatArray = NDArray[np.float64]


class YoloLayout(enum.Enum):
    """Output tensor layout of a YOLO export."""

    AUTO = "auto"
    V5 = "v5"
    V8 = "v8"


@dataclass(frozen=True)
class YoloParams:
    """Decoding parameters; defaults are the usual YOLO ones (COCO person class 0)."""

    score_threshold: float = 0.25
    nms_iou: float = 0.45
    person_class: int = 0
    layout: YoloLayout = YoloLayout.AUTO
    input_size: int = 640  # used when the model's input size is dynamic
    threads: int = 1

    def __post_init__(self) -> None:
        if not 0.0 <= self.score_threshold <= 1.0:
            raise ConfigError(f"yolo score_threshold={self.score_threshold} must be in [0, 1]")
        if not 0.0 < self.nms_iou <= 1.0:
            raise ConfigError(f"yolo nms_iou={self.nms_iou} must be in (0, 1]")
        if self.person_class < 0:
            raise ConfigError(f"yolo person_class={self.person_class} must be >= 0")
        if self.input_size < 32 or self.input_size % 32:
            raise ConfigError(f"yolo input_size={self.input_size} must be a multiple of 32")


def decode(output: NDArray[np.floating], params: YoloParams) -> tuple[FloatArray, FloatArray]:
    """Person boxes ``(N, 4)`` (x1, y1, x2, y2, input pixels) and scores from one raw output."""
    out = np.asarray(output, dtype=np.float64)
    if out.ndim == 3:
        if out.shape[0] != 1:
            raise ConfigError(f"yolo output batch is {out.shape[0]}, expected 1")
        out = out[0]
    if out.ndim != 2:
        raise ConfigError(f"yolo output has shape {output.shape}, expected (1, rows, cols)")
    layout = params.layout
    if layout is YoloLayout.AUTO:
        layout = YoloLayout.V8 if out.shape[0] < out.shape[1] else YoloLayout.V5
    if layout is YoloLayout.V8:
        rows = out.T
        first_class = 4
        classes = rows[:, first_class:]
        objectness = np.ones(rows.shape[0])
    else:
        rows = out
        first_class = 5
        classes = rows[:, first_class:]
        objectness = rows[:, 4] if rows.shape[1] > 4 else np.ones(0)
    if params.person_class >= classes.shape[1]:
        raise ConfigError(
            f"yolo person_class={params.person_class} but the {layout.value} output "
            f"has {classes.shape[1]} classes (shape {output.shape})"
        )
    scores = objectness * classes[:, params.person_class]
    # A box counts as a person only if person is its best class (as YOLO's own NMS does).
    best = classes.argmax(axis=1) == params.person_class
    keep = best & (scores >= params.score_threshold)
    cx, cy, w, h = (rows[keep, k] for k in range(4))
    boxes = np.stack([cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2], axis=1)
    return boxes.reshape(-1, 4), scores[keep]


class OnnxYoloDetector:
    """:class:`~rgbd_eval.detect.person2d.PersonDetector2D` running a YOLO ONNX file."""

    def __init__(self, path: Path, params: YoloParams | None = None) -> None:
        self.params = params or YoloParams()
        self._session = open_session(path, self.params.threads)
        inputs = self._session.get_inputs()
        if len(inputs) != 1 or len(inputs[0].shape) != 4:
            raise ConfigError(f"model file {path}: expected one NCHW image input")
        self._input_name = inputs[0].name
        _, _, h, w = inputs[0].shape
        size = self.params.input_size
        self.input_height = h if isinstance(h, int) and h > 0 else size
        self.input_width = w if isinstance(w, int) and w > 0 else size

    def detect(self, image: ColourImage) -> list[PersonBox]:
        rgb = image.rgb
        tile, lb = letterbox(rgb, self.input_width, self.input_height)
        blob = (tile.astype(np.float32) / np.float32(255.0)).transpose(2, 0, 1)[None]
        (raw, *_rest) = self._session.run(None, {self._input_name: np.ascontiguousarray(blob)})
        boxes, scores = decode(raw, self.params)
        keep = nms(boxes, scores, self.params.nms_iou)
        return to_person_boxes(lb.to_image(boxes[keep]), scores[keep], rgb.shape[1], rgb.shape[0])
