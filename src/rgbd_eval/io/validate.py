"""Checks of decoded frames, and bounds of the values read from inputs, that keep garbage
from being scored silently.

A 1x1 image or a depth frame without one valid pixel decodes fine, and the
pipeline would score its (empty) detections as if the people were missed. The
reader refuses images too small to hold a person and reports depth frames with
no valid pixel (all NaN or zero, e.g. a sensor's first frames); a recording whose
every depth frame is empty is refused. Depth mostly beyond any RGB-D camera's range
(a wrong ``is_bigendian`` flag, millimetres in a 32FC1 image, a saturated 65535) is
implausible: the frame's depth is dropped with a warning, and a recording with no
plausible depth frame is refused.

Positions, box coordinates and frame numbers read from any input are bounded
(:data:`MAX_POSITION_M`, :data:`MAX_PIXELS`, :data:`MAX_FRAME`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

#: Smallest image accepted (width, height): a tenth of the thesis' smallest depth
#: resolution, 160x120 (seed 000, Table 7.1); 192 pixels still exceed the 30 points a
#: cluster needs (Table 5.1, ~cluster/min_points).
MIN_IMAGE_SIZE = (16, 12)
#: Frame indices listed in a warning before the rest are counted.
MAX_LISTED = 10

#: Largest magnitude of a position read from an input (metres: odometry, tf, ground truth,
#: tracks): 10,000 km holds any UTM coordinate; 1e30 m made the tracker's Kalman algebra fail.
MAX_POSITION_M = 1e7
#: Largest magnitude of an image coordinate read from an input (pixels: boxes); a box at
#: 1e300 overflowed the drawing code.
MAX_PIXELS = 1e6
#: Largest frame number read from an input (92 hours at 30 fps).
MAX_FRAME = 10_000_000


def box_problem(values: Sequence[float]) -> str | None:
    """Why ``(left, top, width, height)`` is not a box in an image (None when it is)."""
    if not all(math.isfinite(v) for v in values):
        return f"box {tuple(values)} is not finite"
    width, height = values[2], values[3]
    if math.copysign(1.0, width) < 0 or math.copysign(1.0, height) < 0:  # -0 too
        return f"box size {width}x{height} is negative"
    if width == 0 or height == 0:
        return f"box size {width}x{height} is empty (leave the box out when there is none)"
    if any(abs(v) > MAX_PIXELS for v in values):
        return f"box {tuple(values)} lies beyond {MAX_PIXELS:g} pixels"
    return None


def position_problem(values: Sequence[float]) -> str | None:
    """Why a position in metres is not one (None when it is)."""
    if not all(math.isfinite(v) for v in values):
        return f"position {tuple(values)} is not finite"
    if any(abs(v) > MAX_POSITION_M for v in values):
        return f"position {tuple(values)} lies beyond {MAX_POSITION_M:g} m"
    return None


def image_size_problem(image: NDArray[np.generic]) -> str | None:
    """Why an image is too small to evaluate on (None when it is not)."""
    height, width = image.shape[:2]
    min_w, min_h = MIN_IMAGE_SIZE
    if width < min_w or height < min_h:
        return f"image is {width}x{height}, smaller than the {min_w}x{min_h} minimum"
    return None


def depth_is_empty(depth: NDArray[np.float32]) -> bool:
    """True when no pixel holds a valid depth (decoded depth marks invalid pixels NaN)."""
    return not bool(np.any(np.isfinite(depth) & (depth > 0)))


#: Farthest depth (m) an RGB-D camera reports with any use: Kinect v2 4.5 m, RealSense D455
#: and ZED 2 about 20 m. A 16-bit millimetre image byte-swapped spreads over 0-65 m.
MAX_DEPTH_M = 20.0


def implausible_depth(depth: NDArray[np.float32]) -> str | None:
    """Why a depth frame cannot be metres from an RGB-D camera (None when it can, or holds
    no valid pixel): more than half of its valid pixels lie beyond :data:`MAX_DEPTH_M`."""
    valid = int(np.count_nonzero(depth > 0))  # NaN compares False
    far = int(np.count_nonzero(depth > MAX_DEPTH_M))
    if valid == 0 or 2 * far <= valid:
        return None
    return (
        f"{100 * far / valid:.0f}% of its valid pixels lie beyond {MAX_DEPTH_M:g} m "
        "(a wrong unit or is_bigendian flag, or a saturated sensor)"
    )


def implausible_depth_warning(indices: Sequence[int], total: int, problem: str) -> str | None:
    """One warning line naming the frames whose depth was dropped (None when there are none)."""
    if not indices:
        return None
    return (
        f"{len(indices)} of {total} depth frames hold implausible depth, dropped "
        f"(first: {problem}): frames {_listed(indices)}"
    )


def empty_depth_warning(indices: Sequence[int], total: int) -> str | None:
    """One warning line naming the frames whose depth is empty (None when there are none)."""
    if not indices:
        return None
    return (
        f"{len(indices)} of {total} depth frames hold no valid pixel (all NaN or zero; "
        f"no detections possible): frames {_listed(indices)}"
    )


def _listed(indices: Sequence[int]) -> str:
    """The first MAX_LISTED indices, and how many more."""
    shown = ", ".join(str(i) for i in indices[:MAX_LISTED])
    more = f" and {len(indices) - MAX_LISTED} more" if len(indices) > MAX_LISTED else ""
    return shown + more
