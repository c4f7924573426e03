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
S = 1.8 / 1.75  # width scale of a 1.8 m figure


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


def test_person_at_a_known_position_projects_to_the_expected_box() -> None:
    f = Simulator(scene()).frame(0)
    (gt,) = f.ground_truth
    assert gt.world_xyz == pytest.approx((4.1, 0.0, 0.9))  # centroid at half the height
    box = gt.box2d
    assert box is not None
    # Top: the hair's crown at z = 1.8, 0.015 s behind the feet (facing away, towards the
    # camera): depth 4.0 - 0.015 * 1.0286 = 3.98457; v = 239.5 - 609.2755 * 0.7 / 3.98457
    # = 132.46, +0.5 for the pixel-edge convention -> 132.96
    assert box.top == pytest.approx(CY - FY * 0.7 / (4.0 - 0.015 * S) + 0.5, abs=0.05)
    # Bottom: the heels at z = 0, 0.075 s in front of the ankle: depth 4.0 - 0.07714 = 3.92286;
    # v = 239.5 + 609.2755 * 1.1 / 3.92286 = 410.35 -> 410.85
    assert box.bottom == pytest.approx(CY + FY * 1.1 / (4.0 - 0.075 * S) + 0.5, abs=0.05)
    # left-right symmetric figure on the optical axis: centred on u = 319.5 + 0.5
    assert box.left + box.width / 2 == pytest.approx(320.0, abs=0.05)
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
    f = Simulator(scene(people=[{"id": 2, "path": [{"x": 4.1, "y": -2.17}]}])).frame(0)
    (gt,) = f.ground_truth
    assert gt.box2d is not None
    assert gt.box2d.right == 640.0
    # centre at u = 319.5 + 2.17 * 589.37 / 4 + 0.5 = 639.7; half the figure's width (arms,
    # about 0.29 m * 1.0286) is 0.298 * 589.37 / 4 = 44 px -> left edge near 596
    assert gt.box2d.left == pytest.approx(596.0, abs=6.0)
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
