"""Colour rejection of satake2009's false detections (seed 002, 2.2; the test is ours).

The seed rejects "objects with similar silhouette to person" (its Fig. 5) "using color and
texture information" and gives no detail. Our test: a person's head (skin, hair) and
torso (clothes) differ in colour, where a person-shaped object (mannequin, cabinet,
pillar, coat stand with one coat, plant) is one material from top to bottom, or has no
head where the template has one. Over the body pixels of a match (depth within
``band_m`` of its distance), the head rows (top quarter of the head-to-hip box) and the
torso rows (its lower 55 %) must each hold :data:`MIN_PIXELS` body pixels, and the CIELAB
chromaticities ``(a*, b*)`` of their mean colours must differ by at least ``min_chroma``. Lightness is
left out: shading alone makes the top of a uniform object darker or lighter than its
middle.

Known failures, by construction: a person whose hair and top are the same colour, seen
from behind, is rejected; an object with a differently coloured top (a coat stand with
a hat) is kept. A grey (mono) image carries no chromaticity: the test then keeps all.
The stereo texture of the synthetic world is on every surface, so texture tells nothing
there: this test uses colour only.
"""

from __future__ import annotations

import cv2
import numpy as np
from numpy.typing import NDArray

from rgbd_eval.methods.satake2009.templates import Match

#: Rows of the head-to-hip box: the head is its top quarter, the torso its lower 55 %.
HEAD_ROWS = (0.0, 0.25)
TORSO_ROWS = (0.45, 1.0)
#: Fewest body pixels per region (fewer in the head rows: no head, not a person).
MIN_PIXELS = 12


def _region(
    rgb: NDArray[np.uint8], body: NDArray[np.bool_], rows: tuple[float, float]
) -> NDArray[np.float64] | None:
    """Mean colour (0..1) of the body pixels in a band of rows (None: too few of them)."""
    h = body.shape[0]
    r0, r1 = round(rows[0] * h), max(round(rows[0] * h) + 1, round(rows[1] * h))
    sel = np.ascontiguousarray(body[r0:r1]).view(np.uint8)
    if cv2.countNonZero(sel) < MIN_PIXELS:
        return None
    mean = cv2.mean(np.ascontiguousarray(rgb[r0:r1]), mask=sel)
    return np.array(mean[:3], np.float64) / 255.0


def head_torso_chroma(
    rgb: NDArray[np.uint8], depth: NDArray[np.float32], m: Match, distance: float, band_m: float
) -> float | None:
    """Distance between the CIELAB ``(a*, b*)`` of the head's and the torso's mean colour.

    None when a region holds fewer than :data:`MIN_PIXELS` body pixels: no head where the
    template has one. ``rgb`` and ``depth`` are at the same (processed) size as the match;
    body pixels are those within ``band_m`` of ``distance`` (the match's refined distance).
    """
    H, W = depth.shape
    top = max(0, round(m.v))
    bottom = min(H, m.box[1] + m.box[3])
    left, right = max(0, m.box[0]), min(W, m.box[0] + m.box[2])
    if bottom - top < 4 or right - left < 2:
        return None
    d = depth[top:bottom, left:right]
    with np.errstate(invalid="ignore"):
        body = np.abs(d - distance) < band_m
    patch = rgb[top:bottom, left:right]
    head, torso = _region(patch, body, HEAD_ROWS), _region(patch, body, TORSO_ROWS)
    if head is None or torso is None:
        return None
    pair = np.array([[head, torso]], np.float32)
    lab = np.asarray(cv2.cvtColor(pair, cv2.COLOR_RGB2Lab), np.float32)[0]
    return float(np.hypot(lab[0, 1] - lab[1, 1], lab[0, 2] - lab[1, 2]))


def passes(
    rgb: NDArray[np.uint8],
    depth: NDArray[np.float32],
    m: Match,
    distance: float,
    band_m: float,
    min_chroma: float,
) -> bool:
    """Whether a match is kept: a head and a torso that differ by ``min_chroma`` (grey: kept)."""
    if rgb.ndim != 3:
        return True
    c = head_torso_chroma(rgb, depth, m, distance, band_m)
    return c is not None and c >= min_chroma
