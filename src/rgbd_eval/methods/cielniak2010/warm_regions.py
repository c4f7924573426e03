"""Person-shaped warm regions of a thermal image: where the sequential detector starts filters.

Seed 004 (introduction, section 3): "A sequential detector initialises an independent
tracking filter for each new person appearing in the image, using thermal information."
The snippets do not say how it proposes a state; ours segments the pixels in the band of
human surface temperatures (warmer than the room by ``min_contrast_k``, the room being the
image's median, and cooler than ``max_temp_c``, which leaves out radiators and lamps),
removes pixels within ``hot_margin_px`` of hotter pixels (the blurred rim of a radiator
would join a person standing in front of it), takes the 8-connected components, and
keeps those shaped like a standing person: at least
``min_height_px`` tall, ``min_elongation`` times taller than wide, and filling
``min_fill`` of their box. The proposal's state is the component's box. The tracker also reports, for a
filter that overlaps one component alone, that component's box (the extent of the warm
pixels: a walker's stride is wider than the silhouette's legs). The tracking
filter's likelihood stays unthresholded (section 3); only the proposal thresholds.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

F64 = NDArray[np.float64]
_EIGHT = np.ones((3, 3), dtype=bool)
_EIGHT_U8 = np.ones((3, 3), dtype=np.uint8)


@dataclass(frozen=True)
class WarmRegionParams:
    """Segmentation band and shape tests (values and sources in the method config)."""

    min_contrast_k: float = 3.0
    max_temp_c: float = 40.0
    min_height_px: float = 20.0
    min_elongation: float = 1.5
    min_fill: float = 0.3
    hot_margin_px: int = 2

    def __post_init__(self) -> None:
        if self.min_contrast_k <= 0.0:
            raise ValueError(f"min_contrast_k={self.min_contrast_k} must be positive")
        if self.min_height_px <= 0.0 or self.min_elongation <= 0.0:
            raise ValueError(
                f"min_height_px={self.min_height_px}, min_elongation={self.min_elongation}"
                " must be positive"
            )
        if self.hot_margin_px < 0:
            raise ValueError(f"hot_margin_px={self.hot_margin_px} must not be negative")
        if not 0.0 <= self.min_fill <= 1.0:
            raise ValueError(f"min_fill={self.min_fill} must be in [0, 1]")


@dataclass(frozen=True)
class WarmRegions:
    """Boxes ``(u0, v0, u1, v1)`` (pixel edges) of all warm components, and which of them
    are shaped like a standing person."""

    boxes: F64
    person: NDArray[np.bool_]


def room_median(temperature: NDArray[np.float32]) -> float:
    """The room's temperature: the median of the image."""
    return float(np.median(temperature))


def _dilated(mask: NDArray[np.bool_], iterations: int) -> NDArray[np.bool_]:
    """``mask`` grown by ``iterations`` pixels, 8-connected (``ndimage.binary_dilation`` with
    a 3x3 structure and no pixels beyond the border; OpenCV's is some 40 times faster)."""
    out = cv2.dilate(mask.astype(np.uint8), _EIGHT_U8, iterations=iterations)
    return np.asarray(out, dtype=bool)


def warm_regions(
    temperature: NDArray[np.floating], params: WarmRegionParams, room: float | None = None
) -> WarmRegions:
    """The warm components of a temperature image (deg C) and their shape test.

    ``room``: the image's median (:func:`room_median`) when the caller has it already.
    """
    t = np.asarray(temperature, dtype=np.float32)
    if room is None:
        room = room_median(t)
    hot = t >= params.max_temp_c
    mask = t > room + params.min_contrast_k
    mask &= ~hot
    if params.hot_margin_px > 0 and hot.any():
        mask &= ~_dilated(hot, params.hot_margin_px)
    labels, _ = ndimage.label(mask, structure=_EIGHT)
    boxes = []
    person = []
    for index, sl in enumerate(ndimage.find_objects(labels), start=1):
        if sl is None:
            continue
        rows, cols = sl
        h = rows.stop - rows.start
        w = cols.stop - cols.start
        fill = float(np.count_nonzero(labels[sl] == index)) / float(h * w)
        boxes.append((cols.start, rows.start, cols.stop, rows.stop))
        person.append(
            h >= params.min_height_px and h >= params.min_elongation * w and fill >= params.min_fill
        )
    return WarmRegions(
        np.asarray(boxes, dtype=np.float64).reshape(-1, 4), np.asarray(person, dtype=bool)
    )
