"""The elliptic head-and-body silhouette and its thermal contrast score (seed 004, section 3).

A person in the thermal image is modelled by ellipses, head and body (torso, legs), scaled by the
silhouette height ``h`` (pixels) and placed by its centre ``(u, v)``; the box
``(u - w/2, v - h/2, u + w/2, v + h/2)`` with ``w = width_ratio * h`` is what the tracker
reports. The measurement is unthresholded (seed 004, section 3: "measurements are
incorporated directly ... without any preprocessing, such as thresholding"): at points along
the contours the temperature gradient across the contour is measured, signed for a warm
person on a cooler background (the temperature falls outward), as in Birchfield's elliptical
head tracker (CVPR 1998). The gradient is taken at the silhouette's own scale: the
temperature a distance ``delta = offset * h`` inside the contour minus the temperature
``delta`` outside it, ``max(0, T(p - delta n) - T(p + delta n))`` clipped at
``saturation``, averaged over the contour (K). A one-pixel (Sobel) gradient was tried first
and measured on rendered walkers (seed 0 of ``thermal_stationary``, frames 30-250): its
best state was a silhouette half the person's size on the legs or the upper body in 7 of 10
cases, because any small ellipse finds edges somewhere on a person; with ``delta`` = 5% of
``h`` the outside samples of such a part land on the person's own warm body, and the best
state was within 10% of the true size in 8 of 10 cases. Even so, a filter placed on a
thin warm part (an arm, the legs) scores like a small, far person, and two filters on one
person split it into parts; a person's surroundings, though, are at room temperature, a
part's are the person's own body. With ``surround_weight`` > 0 the score loses that weight
times the mean warmth above the room (the image median, K, clipped at ``saturation``) at
``surround * h`` outside the contour (our addition to seed 004).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]


@dataclass(frozen=True)
class Silhouette:
    """Contour points and outward unit normals in units of the silhouette height.

    Origin at the box centre, x right, y down; top of the head at y = -0.5, feet at 0.5.
    Proportions (in body heights) of an adult, by the classic rules of thumb: the head
    0.13 tall (about 1/7.5 of the height) and 0.10 wide, the torso from the chin to the
    crotch (0.13 .. 0.52 from the top) 0.26 wide at the shoulders, the legs below it 0.18
    wide together. One ellipse from head to feet narrows at the shoulders, where a person
    is widest: on the articulated mannequins of renderer version 2 its best-scoring size
    came out 20% small, head, torso and legs ellipses within 6%. On the MakeHuman people
    of version 3 (six people, ``tests/track/test_thermal_pf.py``) both fit: sizes
    1.00-1.12 of the true height for these ellipses, 0.78-1.02 for one ellipse; the
    proportions above were not changed (they are not fitted to either).
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


@dataclass(frozen=True)
class ContrastParams:
    """The contrast measurement: sample offset (share of ``h``, at least ``min_offset_px``)
    and the saturation (K) of one point's contrast."""

    offset: float = 0.05
    min_offset_px: float = 1.5
    saturation: float = 8.0
    surround: float = 0.0
    surround_weight: float = 0.0

    def __post_init__(self) -> None:
        if self.offset <= 0.0 or self.min_offset_px <= 0.0:
            raise ValueError(
                f"offset={self.offset}, min_offset_px={self.min_offset_px} must be > 0"
            )
        if self.saturation <= 0.0:
            raise ValueError(f"saturation={self.saturation} must be positive")


def silhouette_scores(
    temperature: NDArray[np.float32],
    silhouette: Silhouette,
    states: F64,
    params: ContrastParams = ContrastParams(),
    room: float | None = None,
) -> F64:
    """Mean inward-minus-outward temperature (K) along the contour of each state ``(u, v, h, ...)``.

    A sixth column, when present, is the width factor ``a`` (the silhouette's widths are
    scaled by it: about 1 for a person seen from the front, 0.6-0.7 in profile). A contour
    point whose inner or outer sample falls outside the image scores 0 (nothing is measured).
    ``room``: :func:`room_temperature` of ``temperature`` when the caller has it already.
    """
    if states.ndim != 2 or states.shape[1] < 3:
        raise ValueError(f"states shape {states.shape} must be (N, >=3)")
    u = states[:, 0:1]
    v = states[:, 1:2]
    h = states[:, 2:3]
    a = states[:, 5:6] if states.shape[1] >= 6 else np.ones_like(h)
    x = u + h * a * silhouette.points[:, 0]  # (N, P)
    y = v + h * silhouette.points[:, 1]
    d = np.maximum(params.offset * h, params.min_offset_px)
    nx, ny = silhouette.normals[:, 0] * d, silhouette.normals[:, 1] * d
    t_in, ok_in = _sample(temperature, x - nx, y - ny)
    t_out, ok_out = _sample(temperature, x + nx, y + ny)
    point = np.where(ok_in & ok_out, np.clip(t_in - t_out, 0.0, params.saturation), 0.0)
    out: F64 = point.mean(axis=1).astype(np.float64)
    if params.surround_weight > 0.0:
        if room is None:
            room = room_temperature(temperature)
        ds = params.surround * h
        t_far, ok_far = _sample(
            temperature, x + silhouette.normals[:, 0] * ds, y + silhouette.normals[:, 1] * ds
        )
        warm = np.where(ok_far, np.clip(t_far - room, 0.0, params.saturation), 0.0)
        out = out - params.surround_weight * warm.mean(axis=1)
    return out


def room_temperature(temperature: NDArray[np.float32]) -> float:
    """The room's temperature for the surround term: the median of every 4th pixel."""
    return float(np.median(temperature[::4, ::4]))


def _sample(image: NDArray[np.float32], x: F64, y: F64) -> tuple[F64, NDArray[np.bool_]]:
    """Nearest-pixel values at ``(x, y)`` and whether each lies inside the image."""
    H, W = image.shape
    xi = np.rint(x).astype(np.intp)
    yi = np.rint(y).astype(np.intp)
    ok = (xi >= 0) & (xi < W) & (yi >= 0) & (yi < H)
    # one flat index (the clipped pixel of a point outside is read and not used)
    flat = np.minimum(np.maximum(yi, 0), H - 1) * W + np.minimum(np.maximum(xi, 0), W - 1)
    vals: F64 = np.ravel(image).take(flat).astype(np.float64)
    return vals, ok


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
