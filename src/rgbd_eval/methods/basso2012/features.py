"""Per-cluster features of seed 000, 5.3: height, centroids, distance, occlusion, blob, histogram.

Pure functions over arrays in the depth camera's optical frame, with the ground
plane normalised as in :mod:`rgbd_eval.detect.plane` (height = ``n . p + d``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import cv2
import numba
import numpy as np
from numpy.typing import NDArray

from rgbd_eval.detect.plane import cross3
from rgbd_eval.types import Box2D, CameraModel, Pose

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: Share of a person's height taken by the head: the anthropometric canon of an
#: adult about eight heads tall. The thesis' head centroid (5.4.2) averages the
#: points in this top slice of the cluster.
HEAD_FRACTION = 1.0 / 8.0


@dataclass(frozen=True)
class ClusterGeometry:
    """The geometric features of one cluster, in the depth optical frame (5.3)."""

    height: float
    lowest: float
    real_centroid: FloatArray
    ground_point: FloatArray
    theoretical_centroid: FloatArray
    top_point: FloatArray
    distance: float


#: For pixel-uniform samples of the visible side of a sphere or of an upright
#: cylinder of radius r, the mean sits in front of the axis by 4/3 of the samples'
#: standard deviation across the line of sight (sphere: 2r/3 vs r/2; cylinder:
#: pi r/4 vs r/sqrt(3), ratio 1.36).
SURFACE_TO_AXIS = 4.0 / 3.0


def cluster_geometry(
    voxel_points: FloatArray,
    full_points: FloatArray,
    plane: FloatArray,
    head_centroid: bool,
    surface_correction: bool,
) -> ClusterGeometry:
    """Height, real and theoretical centroid and distance of one cluster (5.3).

    ``voxel_points`` are the cluster's down-sampled points, ``full_points`` its
    full-resolution points. The height is that of the highest full-resolution
    point. The real centroid is the mean of the head slice (the top
    :data:`HEAD_FRACTION` of the height) when ``head_centroid`` (Table 5.1), else
    of the whole cluster. With ``surface_correction`` the head centroid is moved
    away from the sensor, horizontally, from the visible surface to the head's
    axis (:data:`SURFACE_TO_AXIS`; a head is round, a whole body with its arms is
    not); the thesis keeps the surface mean.
    """
    normal, d = plane[:3], float(plane[3])
    points = full_points if full_points.shape[0] else voxel_points
    heights = points @ normal + d
    voxel_heights = voxel_points @ normal + d
    height = float(heights.max())
    if head_centroid:
        head = np.compress(heights >= height * (1.0 - HEAD_FRACTION), points, axis=0)
        centroid = head.mean(axis=0)
        if surface_correction:
            centroid = centroid + _surface_to_axis(head, centroid, normal)
    else:
        centroid = points.mean(axis=0)
    ground = centroid - (float(centroid @ normal) + d) * normal
    theoretical = ground + normal * (0.5 * height)
    top = ground + normal * height
    return ClusterGeometry(
        height=height,
        lowest=float(voxel_heights.min()),
        real_centroid=centroid,
        ground_point=ground,
        theoretical_centroid=theoretical,
        top_point=top,
        distance=float(np.linalg.norm(centroid)),
    )


def _surface_to_axis(part: FloatArray, centroid: FloatArray, normal: FloatArray) -> FloatArray:
    """Horizontal shift from the visible surface's mean to the body's vertical axis."""
    view = centroid - float(centroid @ normal) * normal  # line of sight, on the ground
    norm = float(np.linalg.norm(view))
    if norm < 1e-9 or part.shape[0] < 2:
        return np.zeros(3)
    view /= norm
    across = cross3(normal, view)
    spread = float(np.std(part @ across))
    shift: FloatArray = view * (SURFACE_TO_AXIS * spread)
    return shift


class RgbProjection:
    """Depth-optical points -> RGB pixels for one frame, the rotation matrix computed once.

    Calling it gives the pixel coordinates ``(N, 2)`` and the RGB-frame depth ``(N,)``.
    """

    def __init__(self, depth_to_rgb: Pose, rgb_camera: CameraModel) -> None:
        # The arithmetic of ``Pose.transform_points``, with its matrix kept.
        self._rotation_t = depth_to_rgb.rotation_matrix().T
        self._translation = np.asarray(depth_to_rgb.translation)
        self.camera = rgb_camera

    def __call__(self, points: FloatArray) -> tuple[FloatArray, FloatArray]:
        in_rgb = np.asarray(points, dtype=np.float64) @ self._rotation_t + self._translation
        return self.camera.project(in_rgb), in_rgb[:, 2]


def project_to_rgb(
    points: FloatArray, depth_to_rgb: Pose, rgb_camera: CameraModel
) -> tuple[FloatArray, FloatArray]:
    """Depth-optical points -> RGB pixel coordinates ``(N, 2)`` and their RGB-frame depth ``(N,)``."""
    return RgbProjection(depth_to_rgb, rgb_camera)(points)


def full_body_box(
    geometry: ClusterGeometry, cluster_uv: FloatArray, project: RgbProjection
) -> Box2D | None:
    """The theoretical box on the RGB image: head to ground vertically (5.3).

    Horizontally it spans the cluster's projected points. None when the head or
    the ground point is behind the RGB camera.
    """
    ends, z = project(np.stack([geometry.top_point, geometry.ground_point]))
    if np.any(z <= 1e-3):
        return None
    top = float(ends[:, 1].min())
    bottom = float(ends[:, 1].max())
    us = np.concatenate([cluster_uv[:, 0], ends[:, 0]])
    left, right = float(us.min()), float(us.max())
    return Box2D(left, top, max(right - left, 1.0), max(bottom - top, 1.0))


def box_inside_image(box: Box2D, camera: CameraModel) -> bool:
    """True when the whole box lies on the image (pixel edges at -0.5 and size - 0.5)."""
    return (
        box.left >= -0.5
        and box.top >= -0.5
        and box.right <= camera.width - 0.5
        and box.bottom <= camera.height - 0.5
    )


def occluded_by_nearer_points(
    box: Box2D,
    own_range: float,
    other_uv: FloatArray,
    other_range: FloatArray,
    margin: float,
) -> bool:
    """True when a point of another cluster, nearer than ``own_range - margin``, falls in ``box``.

    This is the thesis' angular test (Figure 5.6: a nearer cluster covering the
    angles of a farther one) done with the nearer clusters' points rather than
    their bounding boxes, so an L-shaped or slanted neighbour does not flag a
    person it does not actually cover.
    """
    if other_uv.shape[0] == 0:
        return False
    inside = (
        (other_uv[:, 0] >= box.left)
        & (other_uv[:, 0] <= box.right)
        & (other_uv[:, 1] >= box.top)
        & (other_uv[:, 1] <= box.bottom)
        & (other_range < own_range - margin)
    )
    return bool(np.any(inside))


@dataclass(frozen=True, eq=False)
class Blob:
    """The RGB pixels of a cluster: ``mask`` over the box whose top-left pixel is ``(top, left)``."""

    top: int
    left: int
    mask: NDArray[np.bool_]


def blob(uv: FloatArray, footprint: int, rgb_camera: CameraModel) -> Blob:
    """The blob on the RGB image: each projected point covers ``footprint^2`` pixels.

    A depth pixel seen from the RGB camera covers about ``fx_rgb / fx_depth``
    RGB pixels per side, so a decimated depth image still yields a solid mask.
    Pixel ``j`` of the ``k`` a point covers per side is ``rint(u + j - (k - 1) / 2)``.
    """
    if uv.shape[0] == 0:
        return Blob(0, 0, np.zeros((0, 0), dtype=bool))
    k = max(1, int(footprint))
    offsets = np.arange(k, dtype=np.float64) - (k - 1) / 2.0
    top, left, mask = _blob_kernel(
        np.ascontiguousarray(uv, dtype=np.float64), offsets, rgb_camera.width, rgb_camera.height
    )
    return Blob(top, left, mask)


def _blob_mask(
    uv: FloatArray, offsets: FloatArray, image_width: int, image_height: int
) -> tuple[int, int, NDArray[np.bool_]]:
    """:func:`blob`'s top row, left column and mask, the pixels ``rint(u + offset)``."""
    n, k = uv.shape[0], offsets.shape[0]
    u = np.empty((n, k), dtype=np.int64)  # each point's k columns and k rows
    v = np.empty((n, k), dtype=np.int64)
    # The box spans the blob's pixels on the image (rows and columns off it included).
    left, right, top, bottom = 2**62, -(2**62), 2**62, -(2**62)  # n >= 1: all replaced
    for i in range(n):
        for j in range(k):
            u[i, j] = np.int64(np.rint(uv[i, 0] + offsets[j]))
            v[i, j] = np.int64(np.rint(uv[i, 1] + offsets[j]))
            left, right = min(left, u[i, j]), max(right, u[i, j])
            top, bottom = min(top, v[i, j]), max(bottom, v[i, j])
    left, right = max(left, 0), min(right, image_width - 1)
    top, bottom = max(top, 0), min(bottom, image_height - 1)
    if left > right or top > bottom:
        return 0, 0, np.zeros((0, 0), dtype=np.bool_)
    mask = np.zeros((bottom - top + 1, right - left + 1), dtype=np.bool_)
    for i in range(n):
        for a in range(k):
            row = v[i, a]
            if 0 <= row < image_height:
                for b in range(k):
                    col = u[i, b]
                    if 0 <= col < image_width:
                        mask[row - top, col - left] = True
    return top, left, mask


#: Compiled on first use, cached on disk.
_blob_kernel: Callable[[FloatArray, FloatArray, int, int], tuple[int, int, NDArray[np.bool_]]] = (
    numba.njit(cache=True)(_blob_mask)
)


def colour_histogram(rgb: NDArray[np.uint8], region: Blob, bins: int) -> NDArray[np.float32]:
    """Flattened 3D RGB histogram (``bins**3`` values, R slowest) normalised to sum 1 (6.2.2).

    Channel value ``x`` falls in bin ``x * bins // 256``. An empty blob gives the
    uniform histogram.
    """
    if bins < 1:
        raise ValueError(f"bins must be >= 1, got {bins}")
    size = bins**3
    if not region.mask.any():
        return np.full(size, 1.0 / size, dtype=np.float32)
    height, width = region.mask.shape
    crop = rgb[region.top : region.top + height, region.left : region.left + width]
    # OpenCV counts exactly (integers, returned as float32) with these bins.
    counts = cv2.calcHist([crop], [0, 1, 2], region.mask.view(np.uint8), [bins] * 3, [0, 256] * 3)
    hist = np.asarray(counts, dtype=np.float64).reshape(-1)
    out: NDArray[np.float32] = (hist / hist.sum()).astype(np.float32)
    return out


def _pixel_extent(pixels: IntArray, width: int) -> tuple[int, int, int, int]:
    """Smallest and largest row and column of flat (row-major) pixel indices."""
    r_lo, r_hi, c_lo, c_hi = 2**62, -(2**62), 2**62, -(2**62)
    for p in pixels:
        r, c = p // width, p % width
        r_lo, r_hi = min(r_lo, r), max(r_hi, r)
        c_lo, c_hi = min(c_lo, c), max(c_hi, c)
    return r_lo, r_hi, c_lo, c_hi


_extent_kernel: Callable[[IntArray, int], tuple[int, int, int, int]] = numba.njit(cache=True)(
    _pixel_extent
)


def touches_border(pixels: IntArray, camera: CameraModel) -> tuple[bool, bool, bool]:
    """Whether a cluster's depth pixels reach the image's top, bottom, or left/right edge."""
    if pixels.shape[0] == 0:
        return (False, False, False)
    r_lo, r_hi, c_lo, c_hi = _extent_kernel(
        np.ascontiguousarray(pixels, dtype=np.int64), camera.width
    )
    return (r_lo == 0, r_hi == camera.height - 1, c_lo == 0 or c_hi == camera.width - 1)
