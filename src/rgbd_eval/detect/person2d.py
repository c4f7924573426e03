"""The 2D person detector protocol, and box helpers shared by its backends (seed 001, III-B).

A 2D person detector turns one colour image into scored person boxes in that image's
pixels. Backends: :mod:`.yolo_onnx` (a YOLO model file), :mod:`.ssdlite` (the built-in
default), :mod:`.hog_people` (OpenCV's Dalal-Triggs detector), :mod:`.recorded`
(detections stored beside the recording).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import cv2
import numpy as np
from numpy.typing import NDArray

from rgbd_eval.types import Box2D

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class ColourImage:
    """One colour image of a sequence: position in the sequence, stamp, ``HxWx3`` RGB."""

    index: int
    stamp_ns: int
    rgb: NDArray[np.uint8]


@dataclass(frozen=True)
class PersonBox:
    """A scored person box in image pixels."""

    box: Box2D
    score: float


class PersonDetector2D(Protocol):
    """Colour image in, person boxes out."""

    def detect(self, image: ColourImage) -> list[PersonBox]:
        """The people in one image, best first."""
        ...


@dataclass(frozen=True)
class Letterbox:
    """How an image was fitted into a network input: ``input = image * scale + (pad_x, pad_y)``."""

    scale: float
    pad_x: float
    pad_y: float

    def to_image(self, boxes_xyxy: FloatArray) -> FloatArray:
        """Boxes ``(N, 4)`` (x1, y1, x2, y2) in input pixels -> image pixels."""
        out = boxes_xyxy.astype(np.float64, copy=True)
        out[:, [0, 2]] = (out[:, [0, 2]] - self.pad_x) / self.scale
        out[:, [1, 3]] = (out[:, [1, 3]] - self.pad_y) / self.scale
        return out


def letterbox(
    rgb: NDArray[np.uint8], width: int, height: int, fill: int = 114
) -> tuple[NDArray[np.uint8], Letterbox]:
    """Resize keeping the aspect ratio and pad (centred) to ``width x height`` (YOLO's letterbox)."""
    h, w = rgb.shape[:2]
    scale = min(width / w, height / h)
    new_w, new_h = round(w * scale), round(h * scale)
    resized = cv2.resize(rgb, (new_w, new_h), interpolation=cv2.INTER_LINEAR)
    pad_x, pad_y = (width - new_w) / 2.0, (height - new_h) / 2.0
    left, top = round(pad_x - 0.1), round(pad_y - 0.1)
    out = np.full((height, width, rgb.shape[2]), fill, dtype=np.uint8)
    out[top : top + new_h, left : left + new_w] = resized
    return out, Letterbox(scale, float(left), float(top))


def iou_xyxy(box: FloatArray, boxes: FloatArray) -> FloatArray:
    """IoU of one ``(4,)`` box with ``(N, 4)`` boxes, all (x1, y1, x2, y2)."""
    x1 = np.maximum(box[0], boxes[:, 0])
    y1 = np.maximum(box[1], boxes[:, 1])
    x2 = np.minimum(box[2], boxes[:, 2])
    y2 = np.minimum(box[3], boxes[:, 3])
    inter = np.clip(x2 - x1, 0, None) * np.clip(y2 - y1, 0, None)
    area = (box[2] - box[0]) * (box[3] - box[1])
    areas = (boxes[:, 2] - boxes[:, 0]) * (boxes[:, 3] - boxes[:, 1])
    union = area + areas - inter
    return np.asarray(np.where(union > 0, inter / np.where(union > 0, union, 1), 0.0))


def nms(boxes_xyxy: FloatArray, scores: FloatArray, iou_threshold: float) -> list[int]:
    """Greedy non-maximum suppression; indices kept, best score first (stable on ties)."""
    order = list(np.argsort(-scores, kind="stable"))
    keep: list[int] = []
    while order:
        i = order.pop(0)
        keep.append(int(i))
        if not order:
            break
        rest = np.asarray(order)
        overlaps = iou_xyxy(boxes_xyxy[i], boxes_xyxy[rest])
        order = [int(j) for j, o in zip(rest, overlaps, strict=True) if o <= iou_threshold]
    return keep


def to_person_boxes(
    boxes_xyxy: FloatArray, scores: FloatArray, width: int, height: int
) -> list[PersonBox]:
    """Clip ``(x1, y1, x2, y2)`` boxes to the image and keep those with positive area."""
    out: list[PersonBox] = []
    for (x1, y1, x2, y2), s in zip(boxes_xyxy, scores, strict=True):
        cx1, cy1 = min(max(float(x1), 0.0), width), min(max(float(y1), 0.0), height)
        cx2, cy2 = min(max(float(x2), 0.0), width), min(max(float(y2), 0.0), height)
        if cx2 > cx1 and cy2 > cy1:
            out.append(PersonBox(Box2D(cx1, cy1, cx2 - cx1, cy2 - cy1), float(s)))
    return out
