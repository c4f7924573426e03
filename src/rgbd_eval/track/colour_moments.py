"""Adaptive colour model of a person: three colour moments per channel per body region.

Seed 004, section 4 uses the colour representation of its reference [34] (Stricker and
Orengo, "Similarity of color images", 1995): per channel the mean ``E``, the standard
deviation ``sigma = (mean (p - E)^2)^(1/2)`` and the skewness ``s = (mean (p - E)^3)^(1/3)``
(the signed cube root of the third central moment, so all three are in pixel units),
compared by the weighted sum of absolute differences. The moments of any rectangle come
from integral images of ``p``, ``p^2`` and ``p^3`` in constant time (four look-ups each),
which keeps the model cheap enough to evaluate for every particle. With a foreground mask
(the tracker's: the warm pixels of the thermal image mapped onto the colour image) the
integrals are of ``m p^k`` and ``m``, so a region's moments are those of the person's own
pixels, not of the wall and floor around a thin silhouette. The spatial layout
enters as body regions (head, torso, legs: the bands of
:class:`rgbd_eval.track.silhouette.Silhouette`), each with its own moments. The model
adapts: ``m <- (1 - alpha) m + alpha m_observed`` after each confident update.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
from numpy.typing import NDArray

from rgbd_eval import exact

F64 = NDArray[np.float64]

#: Body regions as (top, bottom) fractions of the box height and their width fraction of
#: the box: head 0..0.13, torso 0.13..0.52, legs 0.52..1 (the silhouette's proportions),
#: each narrowed to the part's width so that little background enters.
REGIONS: tuple[tuple[float, float, float], ...] = (
    (0.0, 0.13, 0.33),
    (0.13, 0.52, 0.87),
    (0.52, 1.0, 0.6),
)


#: The cubes of the 8-bit values, exact in float32 (255^3 < 2^24).
_VALUES = np.arange(256, dtype=np.float32)
_CUBES = _VALUES * _VALUES * _VALUES
_NONE: F64 = np.zeros((0, 0, 0))


@dataclass(frozen=True, eq=False)
class IntegralMoments:
    """Integral images of ``p``, ``p^2``, ``p^3`` of a multi-channel image ((H+1, W+1, C) each),
    and with a mask, of the mask ((H+1, W+1, 1)); the powers are then of masked pixels."""

    s1: F64
    s2: F64
    s3: F64
    count: F64 | None = None
    min_count: int = 1

    @staticmethod
    def of(
        image: NDArray[np.generic],
        mask: NDArray[np.bool_] | None = None,
        min_count: int = 1,
        reuse: IntegralMoments | None = None,
    ) -> IntegralMoments:
        """From an ``HxW`` or ``HxWxC`` image (any numeric dtype), over the pixels of ``mask``
        (``HxW``) when given: a box with fewer than ``min_count`` of them is not measured.

        ``reuse``: an earlier result whose arrays of the right shape are overwritten (it is
        not valid afterwards); a tracker passes last frame's to spare fresh memory pages.
        """
        raw = np.asarray(image)
        img = raw[..., None] if raw.ndim == 2 else raw
        if img.ndim != 3:
            raise ValueError(f"image shape {raw.shape} must be HxW or HxWxC")
        if mask is not None and mask.shape != img.shape[:2]:
            raise ValueError(f"mask shape {mask.shape} differs from image shape {img.shape[:2]}")
        if min_count < 1:
            raise ValueError(f"min_count={min_count} must be at least 1")

        def buffer(old: F64 | None, channels: int) -> F64 | None:
            shape = (img.shape[0] + 1, img.shape[1] + 1, channels)
            fits = old is not None and old.shape == shape and old.dtype == np.float64
            return old if fits and old is not None and old.flags.c_contiguous else None

        def integral(a: NDArray[np.generic], out: F64 | None = None) -> F64:
            # OpenCV's integral (4x faster than two cumsums); sums of 8-bit powers stay
            # below 2^53 for images up to 2^12 x 2^12, so both are exact and equal
            res = cv2.integral(np.ascontiguousarray(a), out, sdepth=cv2.CV_64F)
            return np.asarray(res, dtype=np.float64).reshape(a.shape[0] + 1, a.shape[1] + 1, -1)

        old = reuse if reuse is not None else IntegralMoments(_NONE, _NONE, _NONE)
        count = None
        if mask is not None:
            byte_mask = mask.astype(np.uint8)
            count = integral(byte_mask, buffer(old.count, 1))
            if img.dtype == np.uint8 and img.shape[2] <= 4:
                # the masked pixels copied onto zeros: ``img * mask``, 30 times faster
                masked = np.zeros(img.shape, dtype=np.uint8)
                res = cv2.copyTo(np.ascontiguousarray(img), byte_mask, masked)
                img = np.asarray(res, dtype=np.uint8).reshape(img.shape)
            else:
                img = img * mask[..., None].astype(img.dtype)
        if img.dtype == np.uint8:
            # 8-bit: p and p^2 in one pass from the bytes, p^3 <= 255^3 < 2^24 exact in
            # float32 (a table of the cubes); the same integers as the float64 path, a
            # third of its time
            c = img.shape[2]
            s1, s2 = cv2.integral2(
                np.ascontiguousarray(img),
                buffer(old.s1, c),
                buffer(old.s2, c),
                sdepth=cv2.CV_64F,
                sqdepth=cv2.CV_64F,
            )
            shape = (img.shape[0] + 1, img.shape[1] + 1, -1)
            cubes = np.asarray(cv2.LUT(np.ascontiguousarray(img), _CUBES)).reshape(img.shape)
            return IntegralMoments(
                np.asarray(s1, dtype=np.float64).reshape(shape),
                np.asarray(s2, dtype=np.float64).reshape(shape),
                integral(cubes, buffer(old.s3, c)),
                count,
                min_count if count is not None else 1,
            )
        img = img.astype(np.float64)
        sq = img * img
        return IntegralMoments(
            integral(img),
            integral(sq),
            integral(sq * img),
            count,
            min_count if count is not None else 1,
        )

    @property
    def shape(self) -> tuple[int, int]:
        return self.s1.shape[0] - 1, self.s1.shape[1] - 1

    def moments(self, box: tuple[int, int, int, int]) -> F64:
        """``(3, C)``: mean, standard deviation and skewness per channel of integer box
        ``(u0, v0, u1, v1)`` (half-open, clipped to the image); NaN when it is empty."""
        H, W = self.shape
        u0, v0, u1, v1 = box
        u0, u1 = min(max(u0, 0), W), min(max(u1, 0), W)
        v0, v1 = min(max(v0, 0), H), min(max(v1, 0), H)

        def total(s: F64) -> F64:
            out: F64 = s[v1, u1] - s[v0, u1] - s[v1, u0] + s[v0, u0]
            return out

        n = (u1 - u0) * (v1 - v0) if u1 > u0 and v1 > v0 else 0
        if self.count is not None and n > 0:
            n = round(float(total(self.count)[0]))
        if n < self.min_count or n <= 0:
            return np.full((3, self.s1.shape[2]), np.nan)

        m1 = total(self.s1) / n
        m2 = total(self.s2) / n
        m3 = total(self.s3) / n
        var = np.maximum(m2 - m1 * m1, 0.0)
        third = m3 - 3.0 * m1 * m2 + 2.0 * (m1 * m1 * m1)  # E[(p - E)^3] from the raw moments
        return np.stack([m1, np.sqrt(var), exact.cbrt(third)])

    def moments_many(self, boxes: NDArray[np.intp]) -> F64:
        """``(N, 3, C)``: :meth:`moments` of N integer boxes (N, 4) at once."""
        H, W = self.shape
        # integer clips by minimum/maximum (np.clip's Python wrapper costs more than them)
        u0 = np.minimum(np.maximum(boxes[:, 0], 0), W)
        u1 = np.minimum(np.maximum(boxes[:, 2], 0), W)
        v0 = np.minimum(np.maximum(boxes[:, 1], 0), H)
        v1 = np.minimum(np.maximum(boxes[:, 3], 0), H)
        # the four corners as flat indices, computed once for every integral image
        corners = [v * (W + 1) + u for v, u in ((v1, u1), (v0, u1), (v1, u0), (v0, u0))]

        def total(s: F64) -> F64:
            flat = s.reshape(-1, s.shape[2])
            a, b, c, d = (flat.take(i, axis=0) for i in corners)
            out: F64 = a - b - c + d
            return out

        area = np.maximum(u1 - u0, 0) * np.maximum(v1 - v0, 0)
        n = area if self.count is None else np.round(total(self.count)[:, 0]) * (area > 0)
        n = n.astype(np.float64)[:, None]
        empty = (n[:, 0] <= 0) | (n[:, 0] < self.min_count)

        with np.errstate(invalid="ignore", divide="ignore"):
            m1 = total(self.s1) / n
            m2 = total(self.s2) / n
            m3 = total(self.s3) / n
        var = np.maximum(m2 - m1 * m1, 0.0)
        third = m3 - 3.0 * m1 * m2 + 2.0 * (m1 * m1 * m1)
        out: F64 = np.stack([m1, np.sqrt(var), exact.cbrt(third)], axis=1)
        out[empty] = np.nan
        return out


def region_boxes_many(boxes: F64) -> NDArray[np.intp]:
    """``(N, R, 4)`` integer boxes of the body regions of N person boxes (see :func:`region_boxes`)."""
    w = boxes[:, 2] - boxes[:, 0]
    h = boxes[:, 3] - boxes[:, 1]
    uc = (boxes[:, 0] + boxes[:, 2]) / 2.0
    out = np.empty((len(boxes), len(REGIONS), 4), dtype=np.intp)
    for r, (top, bottom, width) in enumerate(REGIONS):
        half = width * w / 2.0
        out[:, r, 0] = np.round(uc - half)
        out[:, r, 1] = np.round(boxes[:, 1] + top * h)
        out[:, r, 2] = np.round(uc + half)
        out[:, r, 3] = np.round(boxes[:, 1] + bottom * h)
    return out


def person_moments_many(integral: IntegralMoments, boxes: F64) -> F64:
    """``(N, R, 3, C)`` moments of the body regions of N person boxes."""
    regions = region_boxes_many(boxes)
    n, r = regions.shape[:2]
    out: F64 = integral.moments_many(regions.reshape(n * r, 4)).reshape(n, r, 3, -1)
    return out


def moment_distances(model: F64, observed: F64, weights: MomentWeights | None = None) -> F64:
    """:func:`moment_distance` of one model ``(R, 3, C)`` to N observations ``(N, R, 3, C)``."""
    wt = weights or MomentWeights()
    w = np.array([wt.mean, wt.std, wt.skew])[None, None, :, None]
    per_region = (w * np.abs(observed - model[None])).sum(axis=(2, 3))  # (N, R)
    ok = np.isfinite(per_region)
    count = ok.sum(axis=1)
    total = np.where(ok, per_region, 0.0).sum(axis=1)
    out: F64 = np.where(count > 0, total / np.maximum(count, 1), np.inf)
    return out


def region_boxes(box: F64) -> list[tuple[int, int, int, int]]:
    """Integer boxes of the body regions of a person box ``(u0, v0, u1, v1)``."""
    u0, v0, u1, v1 = (float(x) for x in box)
    w, h, uc = u1 - u0, v1 - v0, (u0 + u1) / 2.0
    out = []
    for top, bottom, width in REGIONS:
        half = width * w / 2.0
        out.append(
            (round(uc - half), round(v0 + top * h), round(uc + half), round(v0 + bottom * h))
        )
    return out


def person_moments(integral: IntegralMoments, box: F64) -> F64:
    """``(R, 3, C)`` moments of the body regions of a person box."""
    return np.stack([integral.moments(r) for r in region_boxes(box)])


@dataclass(frozen=True)
class MomentWeights:
    """Weights of the mean, deviation and skewness differences (Stricker-Orengo's w_i1..w_i3)."""

    mean: float = 1.0
    std: float = 1.0
    skew: float = 1.0


def moment_distance(a: F64, b: F64, weights: MomentWeights = MomentWeights()) -> float:
    """Stricker-Orengo distance: weighted sum of |differences| over moments, channels and
    regions, averaged over the regions both sides measured (inf when none)."""
    if a.shape != b.shape:
        raise ValueError(f"moment shapes {a.shape} and {b.shape} differ")
    w = np.array([weights.mean, weights.std, weights.skew])[None, :, None]
    per_region = (w * np.abs(a - b)).sum(axis=(1, 2))
    ok = np.isfinite(per_region)
    return float(per_region[ok].mean()) if ok.any() else float("inf")


@dataclass(frozen=True)
class ColourModel:
    """A person's adaptive colour moments ``(R, 3, C)``."""

    moments: F64

    def updated(self, observed: F64, alpha: float) -> ColourModel:
        """``(1 - alpha) m + alpha m_observed`` per region; a region not observed (NaN) keeps
        its moments, a region not yet known takes the observation."""
        if not 0.0 <= alpha <= 1.0:
            raise ValueError(f"alpha={alpha} must be in [0, 1]")
        blend = (1.0 - alpha) * self.moments + alpha * observed
        out = np.where(np.isnan(observed), self.moments, blend)
        out = np.where(np.isnan(self.moments), observed, out)
        return ColourModel(out)

    def contrast(self, background: F64) -> float:
        """Mean absolute difference of the regions' channel means to the ``background``
        colour ``(C,)`` (the image's mean): how far this person stands out; 0.0 unmeasured."""
        d = np.abs(self.moments[:, 0, :] - background[None, :])
        ok = np.isfinite(d)
        return float(d[ok].mean()) if ok.any() else 0.0


#: Immerkær's mask: the difference of two Laplacians, blind to planes and linear ramps.
_NOISE_MASK = np.array([[1.0, -2.0, 1.0], [-2.0, 4.0, -2.0], [1.0, -2.0, 1.0]])


def noise_sigma(image: NDArray[np.generic]) -> float:
    """The standard deviation of the pixel noise of an ``HxW(xC)`` image, averaged over the
    channels: Immerkær, "Fast noise variance estimation" (CVIU 64(2), 1996),
    ``sigma = sqrt(pi / 2) / (6 (W - 2) (H - 2)) * sum |I * N|``. Edges add to it, so it is
    an upper bound on a textured image; 0.0 for an image smaller than 3x3."""
    raw = np.asarray(image)
    if raw.ndim == 2:
        raw = raw[..., None]
    H, W = raw.shape[:2]
    channels = raw.shape[2]
    if H < 3 or W < 3:
        return 0.0
    total_abs = 0.0
    if raw.dtype == np.uint8 and channels <= 4:
        # 8-bit: every |I * N| is an integer below 2^12, exact in int16, and OpenCV's L1
        # norm sums them exactly (in int32 blocks, then in float64 below 2^53): the same
        # number as the float path, all channels in one pass
        r16 = cv2.filter2D(raw, cv2.CV_16S, _NOISE_MASK, borderType=cv2.BORDER_CONSTANT)
        total_abs = float(cv2.norm(r16[1:-1, 1:-1], cv2.NORM_L1))
    else:
        img = raw.astype(np.float32, copy=False)
        for c in range(channels):
            r = cv2.filter2D(img[..., c], cv2.CV_32F, _NOISE_MASK, borderType=cv2.BORDER_CONSTANT)
            total_abs += float(np.abs(r[1:-1, 1:-1], dtype=np.float64).sum())
    return float(np.sqrt(np.pi / 2.0) * total_abs / (6.0 * (W - 2) * (H - 2) * channels))


def channel_means(image: NDArray[np.generic]) -> F64:
    """``(C,)`` mean of each channel of an ``HxWxC`` image: ``image.reshape(-1, C).mean(axis=0)``.

    8-bit with up to 4 channels by OpenCV, several times faster and the same numbers (the
    sums of 8-bit values are exact integers both ways)."""
    if image.ndim != 3:
        raise ValueError(f"image shape {image.shape} must be HxWxC")
    if image.dtype == np.uint8 and 1 <= image.shape[2] <= 4 and image.size < 2**40:
        sums = np.asarray(cv2.sumElems(np.ascontiguousarray(image))[: image.shape[2]])
        fast: F64 = sums / (image.shape[0] * image.shape[1])
        return fast
    out: F64 = image.reshape(-1, image.shape[2]).mean(axis=0)
    return out


def reliability(contrast: float, noise: float, factor: float) -> float:
    """How far colour can be trusted, in [0, 1]: ``c^2 / (c^2 + (factor * noise)^2)`` for a
    person's colour contrast ``c`` against the image's noise (1.0 when both are 0 is not
    possible: no contrast gives 0.0)."""
    if contrast <= 0.0:
        return 0.0
    c2, n2 = contrast * contrast, (factor * noise) * (factor * noise)
    return float(c2 / (c2 + n2))
