"""HOG people-detector confidence on a full-body box (seed 000, 5.3 and 5.4.2).

The thesis scores each cluster with the Dalal-Triggs HOG + linear SVM people
detector applied to the cluster's *theoretical* bounding box (head to ground),
rather than scanning the whole image. Here OpenCV 4.x's ``HOGDescriptor`` with
its default people detector (trained on INRIA, 64x128 windows) plays that role.

Window placement follows the INRIA training set: the person is about 96 px tall
in the 128 px window, centred, with 16 px margins above and below, and the
window's aspect (64:128) fixes its width. The region is cropped with border
replication where it leaves the image, resized to the window, and the SVM score
``w . x + b`` is returned: exactly what ``HOGDescriptor.detect`` reports as the
window's weight (gradients at the window's edge see one pixel of context).
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache

import cv2
import numpy as np
from numpy.typing import NDArray

from rgbd_eval.types import Box2D

#: The detection window of the default people detector (Dalal & Triggs 2005).
WINDOW_WIDTH = 64
WINDOW_HEIGHT = 128
#: Height of a person inside the 128 px window in the INRIA training crops.
PERSON_HEIGHT_IN_WINDOW = 96.0
#: Pixels of context kept around the window so border gradients match ``detect()``.
CONTEXT_PX = 1

_TILE_W = WINDOW_WIDTH + 2 * CONTEXT_PX
_TILE_H = WINDOW_HEIGHT + 2 * CONTEXT_PX


class _PeopleHog:
    """One reusable descriptor plus the SVM weights split into ``w`` and ``b``."""

    def __init__(self) -> None:
        self.descriptor = cv2.HOGDescriptor()
        detector = np.asarray(cv2.HOGDescriptor.getDefaultPeopleDetector(), dtype=np.float64)
        size = int(self.descriptor.getDescriptorSize())
        if detector.shape != (size + 1,):
            raise RuntimeError(
                f"OpenCV people detector has {detector.shape[0]} values, expected {size + 1}"
            )
        self.descriptor.setSVMDetector(detector.astype(np.float32))
        self.weights = detector[:size]
        self.bias = float(detector[size])


@lru_cache(maxsize=1)
def _people_hog() -> _PeopleHog:
    return _PeopleHog()


def window_region(box: Box2D) -> tuple[float, float, float, float]:
    """The image region ``(left, top, width, height)`` mapped onto the 64x128 window.

    The full-body ``box`` takes 96 of the window's 128 px in height, centred; the
    width follows from the window's 1:2 aspect, centred on the box.
    """
    if not (box.height > 0):
        raise ValueError(f"box height must be positive, got {box.height}")
    scale = box.height / PERSON_HEIGHT_IN_WINDOW  # image pixels per window pixel
    height = WINDOW_HEIGHT * scale
    width = WINDOW_WIDTH * scale
    cx = box.left + 0.5 * box.width
    cy = box.top + 0.5 * box.height
    return (cx - 0.5 * width, cy - 0.5 * height, width, height)


def _crop_replicated(
    image: NDArray[np.uint8], left: int, top: int, width: int, height: int
) -> NDArray[np.uint8]:
    """``image[top:top+height, left:left+width]`` with border replication outside the image."""
    img_h, img_w = image.shape[:2]
    x0, y0 = max(left, 0), max(top, 0)
    x1, y1 = min(left + width, img_w), min(top + height, img_h)
    if x0 >= x1 or y0 >= y1:
        # Entirely outside: replicate the nearest pixel row/column.
        rows = np.clip(np.arange(top, top + height), 0, img_h - 1)
        cols = np.clip(np.arange(left, left + width), 0, img_w - 1)
        return np.ascontiguousarray(image[np.ix_(rows, cols)])
    crop = image[y0:y1, x0:x1]
    pads = (y0 - top, top + height - y1, x0 - left, left + width - x1)
    if any(pads):
        return np.asarray(
            cv2.copyMakeBorder(crop, *pads, borderType=cv2.BORDER_REPLICATE), dtype=np.uint8
        )
    return np.asarray(crop, dtype=np.uint8)


def window_tile(rgb: NDArray[np.uint8], box: Box2D) -> NDArray[np.uint8]:
    """The ``(130, 66, C)`` tile: the 64x128 window for ``box`` plus one pixel of context."""
    if rgb.ndim not in (2, 3) or rgb.dtype != np.uint8:
        raise ValueError(f"rgb must be an HxW or HxWxC uint8 image, got {rgb.dtype} {rgb.shape}")
    left, top, width, _height = window_region(box)
    scale = width / WINDOW_WIDTH
    ext_left = left - CONTEXT_PX * scale
    ext_top = top - CONTEXT_PX * scale
    ext_w = max(1, round(_TILE_W * scale))
    ext_h = max(1, round(_TILE_H * scale))
    crop = _crop_replicated(rgb, round(ext_left), round(ext_top), ext_w, ext_h)
    shrinking = ext_w > _TILE_W
    interpolation = cv2.INTER_AREA if shrinking else cv2.INTER_LINEAR
    tile = cv2.resize(crop, (_TILE_W, _TILE_H), interpolation=interpolation)
    if tile.ndim == 2 and rgb.ndim == 3:
        tile = tile[..., None]
    return np.asarray(tile, dtype=np.uint8)


def hog_confidences(rgb: NDArray[np.uint8], boxes: Sequence[Box2D]) -> NDArray[np.float64]:
    """SVM scores ``w . x + b`` of the people detector for many full-body boxes at once.

    The tiles are stacked into one image and described in a single OpenCV call.
    """
    if len(boxes) == 0:
        return np.zeros(0, dtype=np.float64)
    hog = _people_hog()
    tiles = [window_tile(rgb, box) for box in boxes]
    strip = np.ascontiguousarray(np.concatenate(tiles, axis=0))
    locations = [(CONTEXT_PX, CONTEXT_PX + i * _TILE_H) for i in range(len(tiles))]
    raw = hog.descriptor.compute(strip, winStride=(8, 8), padding=(0, 0), locations=locations)
    features = np.asarray(raw, dtype=np.float64).reshape(len(tiles), -1)
    scores: NDArray[np.float64] = features @ hog.weights + hog.bias
    return scores


def hog_confidence(rgb: NDArray[np.uint8], box: Box2D) -> float:
    """SVM score of the people detector for one full-body box (head to ground)."""
    return float(hog_confidences(rgb, [box])[0])
