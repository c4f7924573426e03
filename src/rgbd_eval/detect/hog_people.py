"""OpenCV's Dalal-Triggs HOG people detector scanning the whole image: the no-weights fallback.

``HOGDescriptor.detectMultiScale`` with the default INRIA people SVM returns 64x128 windows
in which the person is about 96 px tall and centred (see :mod:`rgbd_eval.detect.hog`); the
returned boxes are shrunk to that body extent so the localiser's depth region is the person.
The image is scanned at ``scale_factor`` up to ``max_width`` pixels wide (smaller is faster).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from rgbd_eval.detect.hog import PERSON_HEIGHT_IN_WINDOW, WINDOW_HEIGHT, WINDOW_WIDTH
from rgbd_eval.detect.person2d import ColourImage, PersonBox, nms, to_person_boxes
from rgbd_eval.errors import ConfigError

#: Width of a person inside the 64 px window in the INRIA crops (about 40 px of 64).
PERSON_WIDTH_IN_WINDOW = 40.0


@dataclass(frozen=True)
class HogParams:
    """Scan parameters of ``detectMultiScale``."""

    hit_threshold: float = 0.0
    scale_factor: float = 1.05
    win_stride: int = 8
    max_width: int = 640
    nms_iou: float = 0.45

    def __post_init__(self) -> None:
        if not self.scale_factor > 1.0:
            raise ConfigError(f"hog scale_factor={self.scale_factor} must be > 1")
        if self.win_stride < 1:
            raise ConfigError(f"hog win_stride={self.win_stride} must be >= 1")
        if self.max_width < WINDOW_WIDTH:
            raise ConfigError(f"hog max_width={self.max_width} must be >= {WINDOW_WIDTH}")
        if not 0.0 < self.nms_iou <= 1.0:
            raise ConfigError(f"hog nms_iou={self.nms_iou} must be in (0, 1]")


class HogPeopleDetector:
    """:class:`~rgbd_eval.detect.person2d.PersonDetector2D` with the OpenCV people SVM."""

    def __init__(self, params: HogParams | None = None) -> None:
        self.params = params or HogParams()
        self._hog = cv2.HOGDescriptor()
        svm = np.asarray(cv2.HOGDescriptor.getDefaultPeopleDetector(), dtype=np.float32)
        self._hog.setSVMDetector(svm)

    def detect(self, image: ColourImage) -> list[PersonBox]:
        p = self.params
        rgb = image.rgb
        h, w = rgb.shape[:2]
        scale = min(1.0, p.max_width / w)
        scan = rgb if scale == 1.0 else cv2.resize(rgb, (round(w * scale), round(h * scale)))
        rects, weights = self._hog.detectMultiScale(
            scan,
            hitThreshold=p.hit_threshold,
            winStride=(p.win_stride, p.win_stride),
            scale=p.scale_factor,
        )
        if len(rects) == 0:
            return []
        r = np.asarray(rects, dtype=np.float64).reshape(-1, 4) / scale
        s = np.asarray(weights, dtype=np.float64).ravel()
        # Window -> body: keep the centred 40/64 of the width and 96/128 of the height.
        fw, fh = PERSON_WIDTH_IN_WINDOW / WINDOW_WIDTH, PERSON_HEIGHT_IN_WINDOW / WINDOW_HEIGHT
        cx, cy = r[:, 0] + r[:, 2] / 2, r[:, 1] + r[:, 3] / 2
        bw, bh = r[:, 2] * fw, r[:, 3] * fh
        xyxy = np.stack([cx - bw / 2, cy - bh / 2, cx + bw / 2, cy + bh / 2], axis=1)
        keep = nms(xyxy, s, p.nms_iou)
        return to_person_boxes(xyxy[keep], s[keep], w, h)
