"""Primitive meshes and the ray caster on hand-computable shapes."""

from __future__ import annotations

import numpy as np
import pytest

from rgbd_eval.sim.meshes import MeshBuilder, concatenate, unit_box, unit_cylinder, unit_sphere
from rgbd_eval.sim.render import count_hits, light_direction, make_scene, render_hits, shade
from rgbd_eval.sim.scenario import DEFAULT_SIZES, Obstacle, ObstacleKind
from rgbd_eval.sim.world import obstacle_mesh
from rgbd_eval.types import OPTICAL_TO_BODY, CameraModel, Pose

CAM = CameraModel(200, 100, 100.0, 100.0, 99.5, 49.5)
#: Camera at the world origin looking along world +x (optical z = world x).
POSE = OPTICAL_TO_BODY


def test_unit_primitives() -> None:
    v, t = unit_sphere()
    assert np.allclose(np.linalg.norm(v, axis=1), 1.0)
    assert t.max() == len(v) - 1
    cv, cn, ct = unit_cylinder()
    assert cv[:, 2].min() == 0.0 and cv[:, 2].max() == 1.0 and ct.max() == len(cv) - 1
    assert np.allclose(np.linalg.norm(cn, axis=1), 1.0)
    bv, bn, bt = unit_box()
    assert len(bt) == 12 and np.allclose(np.abs(bv), 0.5)
    # every face normal points away from the centre
    centres = bv[bt].mean(axis=1)
    normals = bn[bt[:, 0]]
    assert np.all(np.sum(centres * normals, axis=1) > 0)


def test_ellipsoid_normals_follow_the_inverse_transpose() -> None:
    b = MeshBuilder()
    b.sphere((0.0, 0.0, 0.0), (2.0, 1.0, 0.5), np.eye(3), (1.0, 1.0, 1.0), 3)
    m = b.build()
    # the gradient of x^2/4 + y^2 + z^2/0.25 is (x/4, y, 4 z): the true normal direction
    g = m.vertices / np.array([4.0, 1.0, 0.25])
    g /= np.linalg.norm(g, axis=1, keepdims=True)
    assert np.allclose(m.normals, g, atol=1e-9)
    assert set(m.object_ids.tolist()) == {3}


def test_square_at_two_metres_covers_the_expected_pixels() -> None:
    b = MeshBuilder()
    # a 1 m x 1 m x 1 cm slab facing the camera, its front at x = 2.0
    b.box((2.005, 0.0, 0.0), (0.01, 1.0, 1.0), np.eye(3), (200.0, 100.0, 50.0), 9)
    mesh = b.build()
    hits = render_hits(make_scene(mesh), CAM, POSE)
    inside = hits.triangle >= 0
    # half-width 0.5 m at 2 m: 100 * 0.5 / 2 = 25 px each side of the centre: 50 x 50 px
    assert inside.sum() == pytest.approx(2500, abs=110)
    assert np.allclose(hits.depth[inside], 2.0, atol=1e-5)
    assert np.isnan(hits.depth[~inside]).all()
    assert count_hits(mesh, CAM, POSE, (0, 0, 200, 100)) == inside.sum()
    # the slab faces the camera; the light comes from behind the camera (azimuth 180):
    # intensity = ambient 0.38 + 0.12 * n_z (0) + 0.62 * cos(0) = 1.0 -> the albedo itself
    img = shade(mesh, hits, light_direction(180.0, 0.0), 1.0)
    assert np.allclose(img[inside], (200.0, 100.0, 50.0), atol=1e-3)


def test_count_hits_beyond_the_image_and_subsampled() -> None:
    b = MeshBuilder()
    b.box((2.005, 0.0, 0.0), (0.01, 1.0, 1.0), np.eye(3), (1.0, 1.0, 1.0), 9)
    mesh = concatenate([b.build()])
    # camera 2 m to the right (world -y): the slab is 1.5..2.5 m to its left, at
    # u = 99.5 - 100 * (1.5..2.5) / 2 = -25.5..24.5, half outside the image
    shifted = Pose((0.0, -2.0, 0.0), (0.0, 0.0, 0.0, 1.0)).compose(POSE)
    inside_only = count_hits(mesh, CAM, shifted, (0, 0, 200, 100))
    whole = count_hits(mesh, CAM, shifted, (-60, 0, 200, 100))
    assert inside_only == pytest.approx(1250, abs=80)
    assert whole == pytest.approx(2500, abs=110)
    big = count_hits(
        mesh, CameraModel(2000, 1000, 1000.0, 1000.0, 999.5, 499.5), POSE, (0, 0, 2000, 1000)
    )
    # 500 x 500 = 250000 px, estimated on a coarser grid
    assert big == pytest.approx(250000, rel=0.03)
    assert count_hits(mesh, CAM, POSE, (5, 5, 5, 50)) == 0.0


@pytest.mark.parametrize("index", [0, 3, 5])
def test_cached_static_render_equals_one_full_cast(index: int) -> None:
    """Static scene cached + people cast in their window == casting everything at once."""
    from rgbd_eval.sim.simulate import Simulator

    from .conftest import tiny_scenario

    sc = tiny_scenario(
        people=[
            {"id": 1, "path": [{"x": 3.0, "y": -1.0}, {"x": 3.0, "y": 1.0}]},
            {"id": 2, "path": [{"x": 0.15, "y": 0.3}]},  # beside the camera, partly behind it
        ]
    )
    sim = Simulator(sc, 0)
    f = sim.frame(index)
    t = sim.time(index)
    people = [m for _, m, _, _ in sim.people_meshes(t)]
    mesh = concatenate([sim.static, *people])
    full = render_hits(make_scene(mesh), sim.rgb_camera, f.rgb_pose)
    ids = np.where(full.triangle >= 0, mesh.object_ids[np.maximum(full.triangle, 0)], -1)
    assert np.array_equal(ids, f.ids)
    assert np.any(f.ids == 1)
    # person 2 straddles the camera's plane: the near-plane clipping is exercised
    near = sim.people_meshes(t)[1][1].vertices
    depth = f.rgb_pose.inverse().transform_points(near)[:, 2]
    assert depth.min() < 0.0 < depth.max()


@pytest.mark.parametrize("kind", [k for k in ObstacleKind if k is not ObstacleKind.PICTURE])
def test_obstacles_stand_on_the_floor_within_their_extent(kind: ObstacleKind) -> None:
    ob = Obstacle(kind=kind, x=2.0, y=-1.0, yaw_deg=0.0)
    b = MeshBuilder()
    obstacle_mesh(ob, 77, b)
    v = b.build().vertices
    sx, sy, sz = ob.extent
    assert v[:, 2].min() == pytest.approx(0.0, abs=1e-9)  # on the floor
    assert v[:, 2].max() == pytest.approx(sz, rel=0.05)  # as tall as declared
    # footprint inside the declared box (a few cm of slack for feet and hooks)
    assert np.abs(v[:, 0] - 2.0).max() <= sx / 2 + 0.05
    assert np.abs(v[:, 1] + 1.0).max() <= sy / 2 + 0.05


def test_person_sized_objects_are_person_sized() -> None:
    for kind in (ObstacleKind.COAT_STAND, ObstacleKind.PLANT, ObstacleKind.CABINET):
        # the detector keeps clusters 1.4 .. 2.3 m high (seed 000, Table 5.1)
        assert 1.4 <= DEFAULT_SIZES[kind][2] <= 2.3


def test_static_cache_tells_cameras_with_one_frame_id_apart() -> None:
    """Two cameras with the same frame id, one pose, but another size or focal length each
    get their own static hits (the cache once keyed them by frame id alone)."""
    from dataclasses import replace

    from rgbd_eval.sim.simulate import Simulator

    from .conftest import tiny_scenario

    sim = Simulator(tiny_scenario(robot={}), 0)  # static robot: the cache is used
    view = sim.scene_view(0, 0)
    big = sim.rgb_camera  # 160x120
    small = big.scaled(80, 60)  # same frame id, half the size
    wide = replace(big, fx=big.fx / 2.0, fy=big.fy / 2.0)  # same size, twice the field of view
    assert big.frame_id == small.frame_id == wide.frame_id
    for camera in (big, small, wide, big, small):
        got = view.render(camera, view.rgb_pose)
        want = render_hits(sim._static_scene, camera, view.rgb_pose)  # static scene only
        assert got.triangle.shape == (camera.height, camera.width)
        static = got.triangle < sim.static.n_triangles  # people overlaid where they are nearer
        assert np.array_equal(got.triangle[static], want.triangle[static])
        assert static.mean() > 0.5
