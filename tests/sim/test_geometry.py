"""Ground-truth geometry: boxes of a person at a known place, visible fractions, depth of a wall."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from rgbd_eval.sim.annotate import clip_box
from rgbd_eval.sim.scenario import Scenario, parse_scenario
from rgbd_eval.sim.simulate import Simulator

FY = 609.2755  # 240 / tan(21.5 deg)
CY = 239.5


def scene(obstacles: list[dict[str, Any]] | None = None, **kw: Any) -> Scenario:
    """A static camera 1.1 m above the floor at x = 0.1 m, one 1.8 m person standing at (4.1, 0)."""
    data: dict[str, Any] = {
        "name": "geom",
        "duration_s": 0.1,
        "room": {
            "walls": False,
            "ceiling": False,
            "x_min": -5,
            "x_max": 20,
            "y_min": -10,
            "y_max": 10,
        },
        "obstacles": obstacles or [],
        "people": [{"id": 1, "height": 1.8, "path": [{"x": 4.1, "y": 0.0}]}],
        "sensor": {"rgb_noise_std": 0.0},
    }
    data.update(kw)
    return parse_scenario(data)


def _person_mesh(sim: Simulator, index: int = 0) -> np.ndarray:
    (_, mesh, _, _), *_ = sim.people_meshes(sim.time(index))
    return mesh.vertices


def test_person_at_a_known_position_projects_to_the_expected_box() -> None:
    sim = Simulator(scene())
    f = sim.frame(0)
    (gt,) = f.ground_truth
    v = _person_mesh(sim)
    top = float(v[:, 2].max())
    # the person stands at (4.1, 0); the centroid at half their current height (1.8 m tall,
    # plus hair and standing straighter than the rest pose: within 2 cm)
    assert gt.world_xyz == pytest.approx((4.1, 0.0, top / 2))
    assert top == pytest.approx(1.8, abs=0.02)
    box = gt.box2d
    assert box is not None
    # The box spans the projected mesh. The camera sits at x = 0.1, 1.1 m high, level: a
    # vertex at (x, y, z) projects to v = cy - fy (z - 1.1) / (x - 0.1); pixel-edge convention
    # adds 0.5. Top: the highest projected vertex; bottom: the lowest.
    depth = v[:, 0] - 0.1
    rows = CY - FY * (v[:, 2] - 1.1) / depth + 0.5
    assert box.top == pytest.approx(float(rows.min()), abs=1e-4)
    assert box.bottom == pytest.approx(float(rows.max()), abs=1e-4)
    # about 1.8 m tall at 4 m: (1.8 / 4) * 609.3 = 274 px, more for the nearer heels
    assert 270.0 < box.height < 290.0
    # the body is nearly left-right symmetric (it faces away, towards the camera's axis)
    assert box.left + box.width / 2 == pytest.approx(320.0, abs=4.0)
    # the id buffer holds the person's pixels inside its box only
    vs, us = np.nonzero(f.ids == 1)
    assert us.min() >= box.left - 1 and us.max() <= box.right
    assert vs.min() >= box.top - 1 and vs.max() <= box.bottom
    assert gt.visibility >= 0.97 and not gt.ignore


def test_visible_fraction_of_a_half_occluded_person() -> None:
    # a 2.5 m high panel at x = 3.0 covering world y in [0, 1]: its edge y = 0 is on the
    # optical axis, so it hides the figure's left half (image left = world +y)
    panel = {"kind": "box", "x": 3.0, "y": 0.5, "size": [0.1, 1.0, 2.5]}
    f = Simulator(scene([panel])).frame(0)
    (gt,) = f.ground_truth
    assert gt.visibility == pytest.approx(0.5, abs=0.05)
    assert not gt.ignore
    # the annotator's box still spans the whole person
    assert gt.box2d is not None and gt.box2d.height > 270


def test_fully_occluded_and_out_of_view_people_are_ignored() -> None:
    wall = {"kind": "box", "x": 3.0, "y": 0.0, "size": [0.1, 2.0, 2.5]}
    (hidden,) = Simulator(scene([wall])).frame(0).ground_truth
    assert hidden.visibility == 0.0 and hidden.ignore and hidden.box2d is not None
    behind = scene(people=[{"id": 5, "path": [{"x": -3.0, "y": 0.0}]}])
    (gone,) = Simulator(behind).frame(0).ground_truth
    assert gone.box2d is None and gone.ignore and gone.visibility == 0.0
    assert gone.world_xyz is not None and gone.world_xyz[0] == -3.0


def test_partly_out_of_the_image_box_is_clipped() -> None:
    # at 4 m the image spans y = +-4 * tan(28.5 deg) = +-2.17 m; a person at y = -2.17 is cut in half
    sim = Simulator(scene(people=[{"id": 2, "path": [{"x": 4.1, "y": -2.17}]}]))
    f = sim.frame(0)
    (gt,) = f.ground_truth
    assert gt.box2d is not None
    assert gt.box2d.right == 640.0
    # the left edge is the leftmost projected vertex: u = cx - fx y / (x - 0.1) + 0.5
    v = _person_mesh(sim)
    fx = sim.rgb_camera.fx
    cols = sim.rgb_camera.cx - fx * v[:, 1] / (v[:, 0] - 0.1) + 0.5
    assert gt.box2d.left == pytest.approx(float(cols.min()), abs=1e-4)
    assert 580.0 < gt.box2d.left < 620.0
    assert gt.visibility == pytest.approx(0.5, abs=0.1)


def test_depth_of_a_wall_at_a_known_distance() -> None:
    exact = {
        "depth_noise_k": 0.0,
        "quantise": False,
        "edge_dropout": 0.0,
        "dark_dropout": 0.0,
        "shiny_dropout": 0.0,
        "rgb_noise_std": 0.0,
    }
    room = {"x_min": -1.0, "x_max": 5.1, "y_min": -10, "y_max": 10, "wall_height": 5.0}
    f = Simulator(scene(people=[], room=room, sensor=exact)).frame(0)
    # the depth camera is 5.0 m from the wall; depth is z, not ray length: constant on the wall
    centre = f.depth[200:280, 280:360]
    assert np.allclose(centre, 5.0, atol=1e-4)
    # bottom rows see the floor: z = 1.1 * fy / (v - cy) is nearer than the wall
    assert np.nanmax(f.depth[-1]) < 5.0


def test_clip_box() -> None:
    assert clip_box((-10.0, 5.0, 20.0, 30.0), 640, 480).as_tuple() == (0.0, 5.0, 20.0, 25.0)  # type: ignore[union-attr]
    assert clip_box((700.0, 5.0, 720.0, 30.0), 640, 480) is None


def test_depth_noise_of_the_whole_pipeline_matches_the_model() -> None:
    """A wall 4 m ahead, quantisation off: std k z^2 = 0.001425 * 16 = 0.0228 m (Figure 6.1)."""
    room = {"x_min": -1.0, "x_max": 4.1, "y_min": -10, "y_max": 10, "wall_height": 5.0}
    sensor = {"quantise": False, "edge_dropout": 0.0, "dark_dropout": 0.0}
    f = Simulator(scene(people=[], room=room, sensor=sensor)).frame(0)
    wall = f.depth[140:340, 220:420].astype(np.float64)
    assert np.isfinite(wall).all()
    assert wall.std() == pytest.approx(0.0228, rel=0.05)
    assert wall.mean() == pytest.approx(4.0, abs=0.002)


def test_depth_beyond_eight_metres_is_invalid() -> None:
    room = {"x_min": -1.0, "x_max": 9.1, "y_min": -10, "y_max": 10, "wall_height": 8.0}
    f = Simulator(scene(people=[], room=room)).frame(0)
    # the wall at 9 m is beyond the Kinect's 8 m (seed 000, 2.1); the near floor is not
    assert np.isnan(f.depth[200:280, 280:360]).all()
    assert np.isfinite(f.depth[-5:]).mean() > 0.5


def test_a_follower_walks_beside_its_leader() -> None:
    pair = [
        {"id": 1, "path": [{"x": 5.0, "y": 2.0}, {"x": 5.0, "y": -2.0, "speed": 1.0}]},
        {"id": 2, "follow": {"id": 1, "right_m": 0.8}},
    ]
    sim = Simulator(scene(people=pair, duration_s=1.0))
    (a, b) = sim.frame(15).ground_truth  # t = 0.5 s: leader at (5, 1.5) walking towards -y
    assert a.world_xyz is not None and b.world_xyz is not None
    assert a.world_xyz[:2] == pytest.approx((5.0, 1.5))
    # facing -y, the leader's right is -x
    assert b.world_xyz[:2] == pytest.approx((4.2, 1.5))


def test_projector_shadow_left_of_a_foreground_pole() -> None:
    """Structured light: the wall strip the projector cannot see behind a pole has no depth.

    The projector is b = 7.5 cm right of the IR camera; a pole at z_f = 2 m in front of a
    wall at z_b = 4 m shadows a strip b (z_b / z_f - 1) = 0.075 m wide on the wall, seen left
    of the pole: 0.075 * 589.37 / 4 = 11.05 px at 640x480.
    """
    exact = {
        "depth_noise_k": 0.0,
        "quantise": False,
        "edge_dropout": 0.0,
        "dark_dropout": 0.0,
        "shiny_dropout": 0.0,
    }
    room = {"x_min": -1.0, "x_max": 4.1, "y_min": -10, "y_max": 10, "wall_height": 5.0}
    pole = {"kind": "box", "x": 2.125, "y": 0.0, "size": [0.05, 0.2, 3.0]}  # front at 2.1
    f = Simulator(scene([pole], people=[], room=room, sensor=exact)).frame(0)
    row = f.depth[240]
    pole_cols = np.flatnonzero(np.abs(row - 2.0) < 1e-3)
    assert len(pole_cols) > 0
    left = row[: pole_cols[0]]
    run = len(left) - np.flatnonzero(np.isfinite(left))[-1] - 1  # NaNs just left of the pole
    assert run == pytest.approx(11, abs=1)
    assert np.isfinite(row[pole_cols[-1] + 1 : pole_cols[-1] + 4]).all()  # nothing on the right
    no_shadow = Simulator(
        scene([pole], people=[], room=room, sensor={**exact, "projector_shadows": False})
    ).frame(0)
    assert np.isfinite(no_shadow.depth[240]).all()
