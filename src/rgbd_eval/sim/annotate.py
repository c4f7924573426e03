"""Exact ground truth for one rendered frame: boxes, world positions, visible fractions.

The 2D box is what an annotator would draw: the figure's full extent from head
to feet (all mesh vertices projected into the RGB image), clipped to the image.
Box edges use the pixel-edge convention (pixel i spans [i, i+1)), so a point
projected at the continuous pixel-centre coordinate u lies at u + 0.5.
The visible fraction is the person's pixels in the id buffer divided by the
pixels the person would cover alone, inside or outside the image; a person
with no visible pixel is flagged ``ignore``.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from rgbd_eval.sim.meshes import Mesh
from rgbd_eval.sim.render import count_hits
from rgbd_eval.types import Box2D, CameraModel, GroundTruthObject, Pose

#: Vertices closer to the image plane than this (m) are not projected.
NEAR_M = 0.05


def projected_extent(
    vertices: NDArray[np.float64], camera: CameraModel, pose: Pose
) -> tuple[float, float, float, float] | None:
    """(u_min, v_min, u_max, v_max) of vertices in front of the camera, pixel-edge convention."""
    p = pose.inverse().transform_points(vertices)
    front = p[:, 2] > NEAR_M
    if not np.any(front):
        return None
    uv = camera.project(p[front])
    return (
        float(uv[:, 0].min()) + 0.5,
        float(uv[:, 1].min()) + 0.5,
        float(uv[:, 0].max()) + 0.5,
        float(uv[:, 1].max()) + 0.5,
    )


def clip_box(extent: tuple[float, float, float, float], width: int, height: int) -> Box2D | None:
    """Clip an extent to the image; None when nothing of it is inside."""
    u0, v0, u1, v1 = extent
    left, top = min(max(u0, 0.0), float(width)), min(max(v0, 0.0), float(height))
    right, bottom = min(max(u1, 0.0), float(width)), min(max(v1, 0.0), float(height))
    if right - left <= 0.0 or bottom - top <= 0.0:
        return None
    return Box2D(left, top, right - left, bottom - top)


def person_ground_truth(
    frame: int,
    stamp_ns: int,
    person_id: int,
    mesh: Mesh,
    top: float,
    xy: tuple[float, float],
    ids: NDArray[np.int32],
    camera: CameraModel,
    pose: Pose,
) -> GroundTruthObject:
    """Ground truth of one present person.

    ``mesh`` is the person's own mesh (world frame), ``top`` its current height,
    ``ids`` the RGB id buffer, ``pose`` world_T_rgb_optical (true, not odometry).
    The world position is the theoretical centroid: ground position at half the
    current height (seed 000, 5.3).
    """
    world = (float(xy[0]), float(xy[1]), top / 2.0)
    extent = projected_extent(mesh.vertices, camera, pose)
    box = clip_box(extent, camera.width, camera.height) if extent is not None else None
    visible_px = int(np.count_nonzero(ids == person_id))
    fraction = 0.0
    if extent is not None and visible_px > 0:
        u0, v0, u1, v1 = extent
        window = (math.floor(u0) - 1, math.floor(v0) - 1, math.ceil(u1) + 1, math.ceil(v1) + 1)
        alone = count_hits(mesh, camera, pose, window)
        fraction = min(1.0, visible_px / alone) if alone > 0 else 1.0
    return GroundTruthObject(
        frame=frame,
        stamp_ns=stamp_ns,
        object_id=person_id,
        box2d=box,
        world_xyz=world,
        visibility=round(fraction, 4),
        ignore=visible_px == 0,
    )
