"""The elliptic head-and-body silhouette and its thermal-gradient score (seed 004, section 3).

A person in the thermal image is modelled by ellipses, head and body (torso, legs), scaled by the
silhouette height ``h`` (pixels) and placed by its centre ``(u, v)``; the box
``(u - w/2, v - h/2, u + w/2, v + h/2)`` with ``w = width_ratio * h`` is what the tracker
reports. The measurement is unthresholded (seed 004, section 3: "measurements are
incorporated directly ... without any preprocessing, such as thresholding"): the image
gradient is sampled at points along the contours and projected on the outward
normal, the edge score of Birchfield's elliptical head tracker (Birchfield, CVPR 1998),
signed for a warm person on a cooler background: the temperature falls outward, so the
score of a point is ``max(0, -n . grad T)`` (K/px), averaged over the contour.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

F64 = NDArray[np.float64]

#: K/px: a point's score saturates at the edge gradient of a person (8 K clothing-to-room
#: contrast through the default 0.7 px blur and the Sobel kernel gives about 2 K/px), so a
#: much hotter object (a 45 C radiator) cannot outscore a person with a few of its edges.
SATURATION = 2.0


@dataclass(frozen=True)
class Silhouette:
    """Contour points and outward unit normals in units of the silhouette height.

    Origin at the box centre, x right, y down; top of the head at y = -0.5, feet at 0.5.
    Proportions (in body heights) of an adult, by the classic rules of thumb: the head
    0.13 tall (about 1/7.5 of the height) and 0.10 wide, the torso from the chin to the
    crotch (0.13 .. 0.52 from the top) 0.26 wide at the shoulders, the legs below it 0.18
    wide together. One ellipse from head to feet does not fit: it narrows at the
    shoulders, where a person is widest, and the best-scoring size came out 20% small
    on rendered people; head, torso and legs ellipses fit within 6%.
    """

    points: F64  # (N, 2)
    normals: F64  # (N, 2)
    width_ratio: float  # box width / height

    @staticmethod
    def head_and_body(n_head: int = 12, n_torso: int = 16, n_legs: int = 16) -> Silhouette:
        """Head, torso and legs ellipses stacked from the top of the head to the feet."""
        if min(n_head, n_torso, n_legs) < 4:
            raise ValueError(f"contour points ({n_head}, {n_torso}, {n_legs}) must be at least 4")
        parts = [
            _ellipse((0.0, -0.435), (0.05, 0.065), n_head),
            _ellipse((0.0, -0.175), (0.13, 0.195), n_torso),
            _ellipse((0.0, 0.26), (0.09, 0.24), n_legs),
        ]
        pts = np.concatenate([p[0] for p in parts])
        nrm = np.concatenate([p[1] for p in parts])
        return Silhouette(pts, nrm, width_ratio=0.3)


def _ellipse(centre: tuple[float, float], axes: tuple[float, float], n: int) -> tuple[F64, F64]:
    a, b = axes
    t = 2.0 * math.pi * (np.arange(n) + 0.5) / n
    pts = np.stack([centre[0] + a * np.cos(t), centre[1] + b * np.sin(t)], axis=1)
    nrm = np.stack([np.cos(t) / a, np.sin(t) / b], axis=1)  # gradient of the implicit form
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    return pts, nrm


@dataclass(frozen=True, eq=False)
class GradientImage:
    """Sobel gradient of a temperature image (K/px), ready for sampling."""

    gx: NDArray[np.float32]
    gy: NDArray[np.float32]

    @staticmethod
    def of(temperature: NDArray[np.floating]) -> GradientImage:
        t = np.asarray(temperature, dtype=np.float32)
        # the Sobel kernel sums 4 differences of 2 px each: /8 gives K/px
        gx = ndimage.sobel(t, axis=1, mode="nearest") / np.float32(8.0)
        gy = ndimage.sobel(t, axis=0, mode="nearest") / np.float32(8.0)
        return GradientImage(gx.astype(np.float32), gy.astype(np.float32))

    @property
    def shape(self) -> tuple[int, int]:
        h, w = self.gx.shape
        return h, w


def silhouette_scores(grad: GradientImage, silhouette: Silhouette, states: F64) -> F64:
    """Mean outward-falling gradient (K/px) along the contour of each state ``(u, v, h, ...)``.

    A sixth column, when present, is the width factor ``a`` (the silhouette's widths are
    scaled by it: about 1 for a person seen from the front, 0.6-0.7 in profile). Contour
    points outside the image score 0 (nothing is measured there).
    """
    if states.ndim != 2 or states.shape[1] < 3:
        raise ValueError(f"states shape {states.shape} must be (N, >=3)")
    H, W = grad.shape
    u = states[:, 0:1]
    v = states[:, 1:2]
    h = states[:, 2:3]
    a = states[:, 5:6] if states.shape[1] >= 6 else np.ones_like(h)
    px = np.rint(u + h * a * silhouette.points[:, 0]).astype(np.intp)  # (N, P)
    py = np.rint(v + h * silhouette.points[:, 1]).astype(np.intp)
    inside = (px >= 0) & (px < W) & (py >= 0) & (py < H)
    pxc = np.clip(px, 0, W - 1)
    pyc = np.clip(py, 0, H - 1)
    g_n = (
        grad.gx[pyc, pxc] * silhouette.normals[:, 0] + grad.gy[pyc, pxc] * silhouette.normals[:, 1]
    )
    point_score = np.where(inside, np.clip(-g_n, 0.0, SATURATION), 0.0)
    out: F64 = point_score.mean(axis=1).astype(np.float64)
    return out


def state_boxes(states: F64, width_ratio: float) -> F64:
    """Boxes ``(u0, v0, u1, v1)`` of states ``(u, v, h, ..., a)`` (``a``: width factor)."""
    a = states[:, 5] if states.shape[1] >= 6 else 1.0
    w = width_ratio * states[:, 2] * a
    h = states[:, 2]
    out: F64 = np.stack(
        [states[:, 0] - w / 2, states[:, 1] - h / 2, states[:, 0] + w / 2, states[:, 1] + h / 2],
        axis=1,
    )
    return out
