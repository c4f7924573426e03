"""Our ray caster on hand-made triangles: depth, barycentrics, ties, clipping, arbitrary rays."""

from __future__ import annotations

import numpy as np
import pytest

from rgbd_eval.sim.meshes import MeshBuilder
from rgbd_eval.sim.raster import RayBundle, binned_rays, pixel_rays
from rgbd_eval.sim.render import Scene, make_scene, occluded_towards, render_hits
from rgbd_eval.types import CameraModel, Pose

# An 8x6 camera, f = 4 px, principal point at pixel (3.5, 2.5): pixel (i, j)'s ray is
# ((i - 3.5) / 4, (j - 2.5) / 4, 1).
CAM = CameraModel(8, 6, 4.0, 4.0, 3.5, 2.5)


def _bundle(cam: CameraModel = CAM) -> RayBundle:
    d, cells = pixel_rays(cam.width, cam.height, cam.fx, cam.fy, cam.cx, cam.cy)
    return RayBundle(d, cells, (cam.fx, cam.fy, cam.cx, cam.cy), (cam.width, cam.height))


def _plane(z: float) -> tuple[np.ndarray, np.ndarray]:
    """Two triangles covering x, y in [-10, 10] at depth z (camera frame)."""
    v = np.array([[-10, -10, z], [10, -10, z], [10, 10, z], [-10, 10, z]], dtype=float)
    return v, np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int32)


def test_a_plane_is_hit_at_its_depth_by_every_pixel() -> None:
    b = _bundle()
    b.cast(*_plane(2.0))
    assert np.all(b.t == 2.0)  # unit-z rays: t is the depth z
    assert set(b.triangle.tolist()) == {0, 1}


def test_barycentrics_of_a_hand_made_hit() -> None:
    # triangle (0,0,1), (1,0,1), (0,1,1); pixel (5, 3) looks along (0.375, 0.125, 1) and hits
    # (0.375, 0.125, 1) = (1 - u - v) a + u b + v c with u = 0.375, v = 0.125
    b = _bundle()
    b.cast(np.array([[0, 0, 1], [1, 0, 1], [0, 1, 1]], dtype=float), np.array([[0, 1, 2]]))
    k = 3 * CAM.width + 5
    assert b.triangle[k] == 0
    assert (b.t[k], b.u[k], b.v[k]) == (1.0, 0.375, 0.125)
    # pixel (2, 1) looks along (-0.375, -0.375, 1): outside the triangle
    assert b.triangle[1 * CAM.width + 2] == -1


def test_the_nearer_hit_wins_and_equal_depths_keep_the_first_triangle() -> None:
    far_v, far_t = _plane(3.0)
    near_v, near_t = _plane(1.5)
    b = _bundle()
    b.cast(far_v, far_t)
    b.cast(near_v, near_t, triangle_offset=2)
    assert np.all(b.t == 1.5) and np.all(b.triangle >= 2)
    tie = _bundle()
    tie.cast(*_plane(2.0))
    tie.cast(*_plane(2.0), triangle_offset=2)  # the same depth again: not taken
    assert np.all(tie.triangle < 2)


def test_a_triangle_through_the_camera_plane_is_clipped_not_lost() -> None:
    # a floor-like triangle from behind the camera (z = -5) to far ahead (z = 20), 1 m below
    v = np.array([[-10, 1, -5], [10, 1, -5], [0, 1, 20]], dtype=float)
    b = _bundle()
    b.cast(v, np.array([[0, 1, 2]]))
    # the lower rows (y > 0) see it at z = 1 / y_ray: row 5 (y = 2.5 / 4) at 1.6 m
    row5 = b.t[5 * CAM.width : 6 * CAM.width]
    assert np.all(row5[np.isfinite(row5)] == pytest.approx(1.6))
    assert np.isfinite(row5).sum() >= 4
    assert np.all(np.isinf(b.t[: 3 * CAM.width]))  # rows above the horizon see nothing


def test_t_max_limits_arbitrary_rays() -> None:
    d = np.array([[0.0, 0.0, 1.0], [0.1, 0.0, 1.0], [0.0, 0.0, 0.5]])
    cells, grid, size = binned_rays(d)
    b = RayBundle(d, cells, grid, size, t_max=np.array([np.inf, 1.0, 4.1]))
    b.cast(*_plane(2.0))
    # ray 0 hits at t = 2; ray 1 would hit at t = 2 > t_max = 1; ray 2 (z = 0.5) at t = 4
    assert b.triangle.tolist()[0] >= 0 and b.triangle[1] == -1 and b.t[2] == 4.0


def test_binned_rays_need_forward_rays() -> None:
    with pytest.raises(ValueError, match="forward"):
        binned_rays(np.array([[0.0, 0.0, -1.0]]))


def test_render_and_shadows_through_the_scene_api() -> None:
    b = MeshBuilder()
    b.box((0.0, 0.0, 3.0), (8.0, 8.0, 0.01), np.eye(3), (200.0, 200.0, 200.0), 1)  # a wall
    b.box((0.0, 0.0, 2.0), (1.0, 1.0, 1.0), np.eye(3), (50.0, 50.0, 50.0), 2)  # a block
    scene = make_scene(b.build())
    assert isinstance(scene, Scene) and scene.n_triangles == 24
    hits = render_hits(scene, CAM, Pose.identity())
    centre = hits.depth[2:4, 3:5]
    assert np.all(centre == 1.5)  # the block's front face
    assert np.isclose(hits.depth[0, 0], 2.995, atol=1e-6)  # the wall's front face
    # wall points behind the block are shadowed from a light at the camera, the corner is not
    pts = np.array([[0.0, 0.0, 2.995], [1.5, 1.5, 2.995]])
    blocked = occluded_towards([scene], pts, np.zeros(3), np.eye(3))
    assert blocked.tolist() == [True, False]
