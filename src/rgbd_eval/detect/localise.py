"""The people localiser (seed 001, III-B): image box + depth image -> world position.

For each person box on the colour image: the ray through the box centre (in the colour
camera), scaled to the 25th percentile of the valid depth inside the box, then moved
colour camera -> depth camera -> world with the frame's pose (the seed's camera -> odom
-> map; here the recording's tf chain gives ``world_T_depth_optical`` directly).

Depth images hold the z coordinate of each point (not the range along the ray), so the
ray is taken with unit z (``image_geometry``'s C++ ``projectPixelTo3dRay``) and scaled by
the percentile of z: a unit-norm ray times z would place off-axis people too close.

Rays and projections follow each camera's lens distortion (:class:`CameraModel`).

Which depth pixels lie "inside the box": with the depth and colour cameras at the same
place (identity extrinsics, a registered depth image) and the same lens distortion, every
depth pixel maps to the colour image independently of its depth, so the box maps to a
depth-image rectangle exactly; otherwise every valid depth point is projected into the
colour image once per frame and the points falling in the box are taken, and their z in
the colour camera is used.
Boxes with no valid depth inside are dropped and counted.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rgbd_eval.types import Box2D, CameraModel, Pose

FloatArray = NDArray[np.float64]

#: The depth percentile taken as the person's distance (III-B).
DEPTH_PERCENTILE = 25.0


@dataclass(frozen=True)
class LocalisedBox:
    """A box's world position (x, y, z), its depth along the colour camera axis, and height."""

    box: Box2D
    position: tuple[float, float, float]
    depth: float
    height: float


@dataclass(frozen=True)
class Localisation:
    """Localised boxes (in input order, dropped ones left out) and which were dropped."""

    boxes: list[LocalisedBox]
    kept: list[int]
    dropped: int


@dataclass(frozen=True)
class DepthView:
    """What the localiser needs of a frame (independent of the frame's stream layout)."""

    depth: NDArray[np.float32]
    depth_camera: CameraModel
    rgb_camera: CameraModel
    depth_to_rgb: Pose  # rgb_optical_T_depth_optical
    camera_pose: Pose  # world_T_depth_optical


def _is_identity(pose: Pose, tol: float = 1e-9) -> bool:
    t = np.asarray(pose.translation)
    return bool(np.all(np.abs(t) < tol) and abs(abs(pose.rotation[3]) - 1.0) < tol)


def _box_depths_registered(view: DepthView, box: Box2D) -> FloatArray:
    """Valid depths in the depth-image rectangle the colour box maps to (identity extrinsics)."""
    rc, dc = view.rgb_camera, view.depth_camera
    # A depth pixel (u, v) sees the ray ((u - cx_d)/fx_d, (v - cy_d)/fy_d, 1), which hits the
    # colour image at u_rgb = fx_rgb * (u - cx_d) / fx_d + cx_rgb: affine in u, any depth.
    # (With the same lens distortion the distorted normalised coordinates match too.)
    u0 = (box.left - rc.cx) * dc.fx / rc.fx + dc.cx
    u1 = (box.right - rc.cx) * dc.fx / rc.fx + dc.cx
    v0 = (box.top - rc.cy) * dc.fy / rc.fy + dc.cy
    v1 = (box.bottom - rc.cy) * dc.fy / rc.fy + dc.cy
    # Pixel centres (integer coordinates) inside [u0, u1) x [v0, v1).
    c0, c1 = max(int(np.ceil(u0)), 0), min(int(np.ceil(u1)), dc.width)
    r0, r1 = max(int(np.ceil(v0)), 0), min(int(np.ceil(v1)), dc.height)
    if c1 <= c0 or r1 <= r0:
        return np.zeros(0)
    region = view.depth[r0:r1, c0:c1]
    values = region[np.isfinite(region) & (region > 0)]
    return values.astype(np.float64)


class _ProjectedDepth:
    """Valid depth points projected once into the colour image: (u, v, z_rgb)."""

    def __init__(self, view: DepthView) -> None:
        points = view.depth_camera.backproject(view.depth).reshape(-1, 3)
        points = points[np.isfinite(points[:, 2]) & (points[:, 2] > 0)]
        in_rgb = view.depth_to_rgb.transform_points(points)
        in_rgb = in_rgb[in_rgb[:, 2] > 0]
        uv = view.rgb_camera.project(in_rgb)
        self.u, self.v, self.z = uv[:, 0], uv[:, 1], in_rgb[:, 2]

    def depths(self, box: Box2D) -> FloatArray:
        # A depth pixel is in the box if its centre projects into [left, right) x [top, bottom),
        # as in the registered case.
        u, v = self.u, self.v
        inside = (u >= box.left) & (u < box.right) & (v >= box.top) & (v < box.bottom)
        return np.asarray(self.z[inside], dtype=np.float64)


def localise(view: DepthView, boxes: Sequence[Box2D]) -> Localisation:
    """World positions of person boxes (III-B); boxes without valid depth are dropped."""
    registered = _is_identity(view.depth_to_rgb) and view.rgb_camera.lens == view.depth_camera.lens
    projected = None if registered or not boxes else _ProjectedDepth(view)
    rgb_to_world = view.camera_pose.compose(view.depth_to_rgb.inverse())
    rc = view.rgb_camera
    out: list[LocalisedBox] = []
    kept: list[int] = []
    for i, box in enumerate(boxes):
        values = (
            projected.depths(box) if projected is not None else _box_depths_registered(view, box)
        )
        if values.size == 0:
            continue
        z = float(np.percentile(values, DEPTH_PERCENTILE))
        u = box.left + 0.5 * box.width
        v = box.top + 0.5 * box.height
        ray = rc.rays_at(u, v)
        world = rgb_to_world.transform_points((ray * z)[None, :])[0]
        if rc.lens is None:
            height = box.height * z / rc.fy
        else:  # between the rays through the top and bottom centre of the box
            ends = rc.rays_at([u, u], [box.top, box.bottom])
            height = float(ends[1, 1] - ends[0, 1]) * z
        out.append(
            LocalisedBox(box, (float(world[0]), float(world[1]), float(world[2])), z, height)
        )
        kept.append(i)
    return Localisation(out, kept, len(boxes) - len(out))
