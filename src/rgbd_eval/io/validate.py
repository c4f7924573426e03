"""Checks of decoded frames that keep garbage from being scored silently.

A 1x1 image or a depth frame without one valid pixel decodes fine, and the
pipeline would score its (empty) detections as if the people were missed. The
reader refuses images too small to hold a person and reports depth frames with
no valid pixel (all NaN or zero, e.g. a sensor's first frames); a recording whose
every depth frame is empty is refused.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

#: Smallest image accepted (width, height): a tenth of the thesis' smallest depth
#: resolution, 160x120 (seed 000, Table 7.1); 192 pixels still exceed the 30 points a
#: cluster needs (Table 5.1, ~cluster/min_points).
MIN_IMAGE_SIZE = (16, 12)
#: Frame indices listed in a warning before the rest are counted.
MAX_LISTED = 10


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


def empty_depth_warning(indices: Sequence[int], total: int) -> str | None:
    """One warning line naming the frames whose depth is empty (None when there are none)."""
    if not indices:
        return None
    shown = ", ".join(str(i) for i in indices[:MAX_LISTED])
    more = f" and {len(indices) - MAX_LISTED} more" if len(indices) > MAX_LISTED else ""
    return (
        f"{len(indices)} of {total} depth frames hold no valid pixel (all NaN or zero; "
        f"no detections possible): frames {shown}{more}"
    )
