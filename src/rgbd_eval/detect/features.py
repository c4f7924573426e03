"""Per-cluster features of seed 000, 5.3: height, centroids, distance, occlusion, blob, histogram.

Pure functions over arrays in the depth camera's optical frame, with the ground
plane normalised as in :mod:`rgbd_eval.detect.plane` (height = ``n . p + d``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

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
        head = points[heights >= height * (1.0 - HEAD_FRACTION)]
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
    across = np.cross(normal, view)
    spread = float(np.std(part @ across))
    shift: FloatArray = view * (SURFACE_TO_AXIS * spread)
    return shift


def project_to_rgb(
    points: FloatArray, depth_to_rgb: Pose, rgb_camera: CameraModel
) -> tuple[FloatArray, FloatArray]:
    """Depth-optical points -> RGB pixel coordinates ``(N, 2)`` and their RGB-frame depth ``(N,)``."""
    in_rgb = depth_to_rgb.transform_points(points)
    uv = rgb_camera.project(in_rgb)
    return uv, in_rgb[:, 2]


def full_body_box(
    geometry: ClusterGeometry,
    cluster_uv: FloatArray,
    depth_to_rgb: Pose,
    rgb_camera: CameraModel,
) -> Box2D | None:
    """The theoretical box on the RGB image: head to ground vertically (5.3).

    Horizontally it spans the cluster's projected points. None when the head or
    the ground point is behind the RGB camera.
    """
    ends, z = project_to_rgb(
        np.stack([geometry.top_point, geometry.ground_point]), depth_to_rgb, rgb_camera
    )
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


def blob_pixels(uv: FloatArray, footprint: int, rgb_camera: CameraModel) -> IntArray:
    """Flat RGB-image indices of the blob: each projected point covers ``footprint^2`` pixels.

    A depth pixel seen from the RGB camera covers about ``fx_rgb / fx_depth``
    RGB pixels per side, so a decimated depth image still yields a solid mask.
    """
    if uv.shape[0] == 0:
        return np.zeros(0, dtype=np.int64)
    k = max(1, int(footprint))
    offsets = np.arange(k, dtype=np.float64) - (k - 1) / 2.0
    du, dv = np.meshgrid(offsets, offsets)
    u = np.rint(uv[:, 0:1] + du.reshape(1, -1)).astype(np.int64).reshape(-1)
    v = np.rint(uv[:, 1:2] + dv.reshape(1, -1)).astype(np.int64).reshape(-1)
    ok = (u >= 0) & (u < rgb_camera.width) & (v >= 0) & (v < rgb_camera.height)
    mask = np.zeros(rgb_camera.width * rgb_camera.height, dtype=bool)
    mask[v[ok] * rgb_camera.width + u[ok]] = True
    pixels: IntArray = np.flatnonzero(mask).astype(np.int64)
    return pixels


def colour_histogram(rgb: NDArray[np.uint8], pixels: IntArray, bins: int) -> NDArray[np.float32]:
    """Flattened 3D RGB histogram (``bins**3`` values, R slowest) normalised to sum 1 (6.2.2).

    An empty blob gives the uniform histogram.
    """
    if bins < 1:
        raise ValueError(f"bins must be >= 1, got {bins}")
    size = bins**3
    if pixels.shape[0] == 0:
        return np.full(size, 1.0 / size, dtype=np.float32)
    flat = rgb.reshape(-1, rgb.shape[-1])
    lut = np.arange(256, dtype=np.intp) * bins // 256  # channel value -> bin
    index = (lut[flat[pixels, 0]] * bins + lut[flat[pixels, 1]]) * bins + lut[flat[pixels, 2]]
    hist = np.bincount(index, minlength=size).astype(np.float64)
    out: NDArray[np.float32] = (hist / hist.sum()).astype(np.float32)
    return out
