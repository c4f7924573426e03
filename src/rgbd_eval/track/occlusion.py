"""Which of two overlapping persons is in front (seed 004, sections 5 and 6).

Seed 004 orders overlapping persons with an AdaBoost classifier over pairwise thermal and
colour features (section 5), and uses the order to change the penalising policy between
the filters and to re-identify occluded persons (section 6). The classifier is built on
another branch (ciel-b, whose ``track/occlusion.py`` has these three functions with the
same signatures and replaces this module); :func:`order` is the interface, and until it lands the
stand-in below decides by the lower edge of the thermal boxes: on a level floor seen from
above the feet, the person whose feet are lower in the image stands nearer the camera.
"""

from __future__ import annotations

import functools
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]


class AffineLike(Protocol):
    """``colour = scale * thermal + offset`` per axis (``track.cielniak2010.Affine``)."""

    @property
    def scale(self) -> tuple[float, float]: ...

    @property
    def offset(self) -> tuple[float, float]: ...


def order(
    a: F64,
    b: F64,
    thermal: NDArray[np.floating],
    colour: NDArray[np.uint8] | None = None,
    affine: AffineLike | None = None,
) -> int:
    """0 when person ``a`` is in front of ``b``, 1 when ``b`` is; ``a`` and ``b`` are boxes
    ``(u0, v0, u1, v1)`` in the thermal image. Stand-in: the lower box bottom is in front
    (``thermal``, ``colour`` and its ``affine`` map are what the classifier reads)."""
    return 0 if float(a[3]) >= float(b[3]) else 1


def sort_front_to_back(
    boxes: list[F64],
    thermal: NDArray[np.floating],
    colour: NDArray[np.uint8] | None = None,
    affine: AffineLike | None = None,
) -> list[int]:
    """Indices of ``boxes`` from front to back by pairwise :func:`order` (M log M comparisons,
    seed 004, section 5)."""

    def cmp(i: int, j: int) -> int:
        return -1 if order(boxes[i], boxes[j], thermal, colour, affine) == 0 else 1

    return sorted(range(len(boxes)), key=functools.cmp_to_key(cmp))


def overlap(a: F64, b: F64) -> float:
    """Intersection over the smaller box."""
    iw = max(0.0, min(a[2], b[2]) - max(a[0], b[0]))
    ih = max(0.0, min(a[3], b[3]) - max(a[1], b[1]))
    smaller = min((a[2] - a[0]) * (a[3] - a[1]), (b[2] - b[0]) * (b[3] - b[1]))
    return float(iw * ih / max(smaller, 1e-9))
