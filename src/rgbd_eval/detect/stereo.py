"""Depth from a rectified stereo pair by semi-global matching (satake2009, seed 002, 2.4 step 1).

OpenCV's ``StereoSGBM`` (Hirschmueller 2008) matches the left image against the right
one at a processed size (the seed processes 512x384, section 4); depth is
``Z = fx * B / disparity`` with ``fx`` at that size and the baseline B taken from the
right camera's projection matrix (``P[0, 3] = Tx = -fx * B``, ROS CameraInfo). It is
real stereo, so it fails where stereo fails: textureless surfaces, occlusion borders and
repeated patterns give no depth (NaN) or wrong depth.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property

import cv2
import numba
import numpy as np
from numpy.typing import NDArray

from rgbd_eval.types import CameraModel


@dataclass(frozen=True)
class SgbmParams:
    """StereoSGBM settings. ``P1 = 8 c b^2``, ``P2 = 32 c b^2`` (c channels, b block size)
    are OpenCV's documented recommendation; ``num_disparities`` bounds the nearest depth
    (``fx B / num_disparities``)."""

    num_disparities: int = 64
    block_size: int = 5
    uniqueness_ratio: int = 10
    speckle_window: int = 100
    speckle_range: int = 2
    disp12_max_diff: int = 1
    #: ``MODE_SGBM_3WAY`` is OpenCV's fastest full-disparity mode; ``MODE_SGBM`` the 5-path one.
    three_way: bool = True

    def __post_init__(self) -> None:
        if self.num_disparities <= 0 or self.num_disparities % 16:
            raise ValueError(
                f"num_disparities={self.num_disparities} must be a positive multiple of 16"
            )
        if self.block_size < 1 or self.block_size % 2 == 0:
            raise ValueError(f"block_size={self.block_size} must be odd and >= 1")


def baseline_from_projection(P: NDArray[np.floating]) -> float:
    """Baseline B (m) from a right camera's ``3x4`` projection matrix: ``Tx = P[0,3] = -fx B``."""
    Pm = np.asarray(P, dtype=np.float64).reshape(3, 4)
    fx, tx = float(Pm[0, 0]), float(Pm[0, 3])
    if not fx > 0:
        raise ValueError(f"projection matrix has fx={fx}")
    baseline = -tx / fx
    if not baseline > 0:
        raise ValueError(
            f"projection matrix Tx={tx} gives baseline {baseline} m: not the right camera of a pair"
        )
    return baseline


def baseline_of(right: CameraModel) -> float:
    """Baseline B (m) of a rectified pair from its right camera (``tx = -fx B``)."""
    P = np.zeros((3, 4))
    P[0, 0], P[0, 3] = right.fx, right.tx
    return baseline_from_projection(P)


def make_matcher(params: SgbmParams) -> cv2.StereoSGBM:
    """A configured ``cv2.StereoSGBM`` for grey images."""
    b = params.block_size
    return cv2.StereoSGBM.create(
        minDisparity=0,
        numDisparities=params.num_disparities,
        blockSize=b,
        P1=8 * b * b,
        P2=32 * b * b,
        disp12MaxDiff=params.disp12_max_diff,
        uniquenessRatio=params.uniqueness_ratio,
        speckleWindowSize=params.speckle_window,
        speckleRange=params.speckle_range,
        mode=cv2.STEREO_SGBM_MODE_SGBM_3WAY if params.three_way else cv2.STEREO_SGBM_MODE_SGBM,
    )


def resized(image: NDArray[np.generic], size: tuple[int, int]) -> NDArray[np.uint8]:
    """An 8-bit image at ``size = (width, height)`` (``INTER_AREA``; as is when it already fits)."""
    img = np.asarray(image)
    if img.dtype != np.uint8:
        raise ValueError(f"stereo images must be 8-bit, got {img.dtype}")
    if (img.shape[1], img.shape[0]) == size:
        return img
    return np.asarray(cv2.resize(img, size, interpolation=cv2.INTER_AREA), np.uint8)


def _grey(image: NDArray[np.generic], size: tuple[int, int]) -> NDArray[np.uint8]:
    img = np.asarray(image)
    if img.ndim == 3:
        img = cv2.cvtColor(img, cv2.COLOR_RGB2GRAY)
    if img.dtype != np.uint8:
        raise ValueError(f"stereo images must be 8-bit, got {img.dtype}")
    if (img.shape[1], img.shape[0]) != size:
        img = cv2.resize(img, size, interpolation=cv2.INTER_AREA)
    return np.ascontiguousarray(img)


def _raw_disparity(
    left: NDArray[np.generic],
    right: NDArray[np.generic],
    size: tuple[int, int],
    matcher: cv2.StereoSGBM,
) -> NDArray[np.int16]:
    """SGBM's own output: left-image disparity in 1/16 px, ``<= 0`` where it has none."""
    if np.shape(left)[:2] != np.shape(right)[:2]:
        raise ValueError(f"stereo pair sizes differ: {np.shape(left)} vs {np.shape(right)}")
    return np.asarray(matcher.compute(_grey(left, size), _grey(right, size)), np.int16)


def disparity(
    left: NDArray[np.generic],
    right: NDArray[np.generic],
    size: tuple[int, int],
    matcher: cv2.StereoSGBM,
) -> NDArray[np.float32]:
    """Left-image disparity (px) at ``size = (width, height)``; NaN where SGBM has none."""
    raw = _raw_disparity(left, right, size, matcher)
    disp = raw.astype(np.float32) / 16.0
    disp[raw <= 0] = np.nan  # OpenCV marks no match as (minDisparity - 1) * 16
    return disp


def depth_from_disparity(
    disp: NDArray[np.float32], fx: float, baseline: float
) -> NDArray[np.float32]:
    """``Z = fx B / d`` (m), NaN where the disparity is NaN or not positive."""
    with np.errstate(divide="ignore", invalid="ignore"):
        z = np.float32(fx * baseline) / disp
    z[~(disp > 0)] = np.nan
    return z.astype(np.float32)


def _depth_of_raw(raw: NDArray[np.int16], fx_baseline: np.float32) -> NDArray[np.float32]:
    """:func:`depth_from_disparity` of :func:`disparity`'s output, from SGBM's raw output, in one pass.

    The same float32 operations per pixel: ``d = raw / 16``, ``Z = fx B / d``; NaN where
    ``raw <= 0`` (no match). Branch-free, so that the loop vectorises.
    """
    flat = np.ascontiguousarray(raw).reshape(-1)
    out = np.empty(flat.size, np.float32)
    sixteen = np.float32(16.0)
    nan = np.float32(np.nan)
    for i in range(flat.size):
        r = flat[i]
        z = fx_baseline / (np.float32(max(r, 1)) / sixteen)  # max: never a division by 0
        out[i] = z if r > 0 else nan
    return out.reshape(raw.shape)


_depth_kernel: Callable[[NDArray[np.int16], np.float32], NDArray[np.float32]] = numba.njit(
    cache=True
)(_depth_of_raw)


@dataclass(frozen=True)
class StereoDepth:
    """Depth at the processed size and the left camera scaled to it."""

    depth: NDArray[np.float32]
    camera: CameraModel

    @cached_property
    def far(self) -> NDArray[np.float32]:
        """:attr:`depth` with no depth (NaN) as +inf, computed once (the template search's input)."""
        return np.where(np.isnan(self.depth), np.float32(np.inf), self.depth).astype(
            np.float32, copy=False
        )


def stereo_depth(
    left: NDArray[np.generic],
    right: NDArray[np.generic],
    left_camera: CameraModel,
    baseline: float,
    size: tuple[int, int],
    matcher: cv2.StereoSGBM,
) -> StereoDepth:
    """Depth (m, NaN invalid) of the left view of a rectified pair, at ``size``."""
    if not baseline > 0:
        raise ValueError(f"baseline={baseline} must be > 0")
    camera = left_camera.scaled(*size)
    raw = _raw_disparity(left, right, size, matcher)
    return StereoDepth(_depth_kernel(raw, np.float32(camera.fx * baseline)), camera)
