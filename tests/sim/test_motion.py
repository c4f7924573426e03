"""Timelines of people and robot, hand-computed, plus a continuity property."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rgbd_eval.sim.motion import (
    SIT_TRANSITION_S,
    clothes_at,
    gait_amplitude,
    person_state,
    person_timeline,
    robot_pose,
    robot_timeline,
)
from rgbd_eval.sim.scenario import Person, Robot


def person(**kw: object) -> Person:
    data: dict[str, object] = {"id": 1, "path": [{"x": 0.0, "y": 0.0}]}
    data.update(kw)
    return Person.model_validate(data)


def test_straight_walk_then_stay() -> None:
    p = person(path=[{"x": 0.0, "y": 0.0}, {"x": 3.0, "y": 4.0, "speed": 1.25}])
    segs = person_timeline(p)
    # 5 m at 1.25 m/s = 4 s
    assert [(g.kind, g.t0, g.t1) for g in segs] == [("walk", 0.0, 4.0)]
    s = person_state(p, segs, 2.0)  # half way: (1.5, 2.0), walked 2.5 m
    assert (s.x, s.y, s.speed, s.distance) == pytest.approx((1.5, 2.0, 1.25, 2.5))
    assert s.heading == pytest.approx(math.atan2(4.0, 3.0))
    end = person_state(p, segs, 10.0)
    assert end.present and (end.x, end.y, end.speed, end.distance) == pytest.approx((3, 4, 0, 5))


def test_start_time_and_vanish() -> None:
    p = person(
        start_s=1.0, leave="vanish", path=[{"x": 0.0, "y": 0.0}, {"x": 2.0, "y": 0.0, "speed": 1.0}]
    )
    segs = person_timeline(p)
    assert not person_state(p, segs, 0.5).present  # before start
    assert person_state(p, segs, 2.0).x == pytest.approx(1.0)  # 1 s after start
    assert not person_state(p, segs, 3.5).present  # arrived at t = 3, then gone


def test_wait_and_sit_segments() -> None:
    p = person(
        path=[
            {"x": 0.0, "y": 0.0},
            {"x": 1.0, "y": 0.0, "speed": 0.5, "wait_s": 1.0, "sit_s": 4.0, "face_deg": 90},
        ]
    )
    segs = person_timeline(p)
    # walk 2 s, wait 1 s, sit 4 s
    assert [(g.kind, g.t0, g.t1) for g in segs] == [
        ("walk", 0.0, 2.0),
        ("wait", 2.0, 3.0),
        ("sit", 3.0, 7.0),
    ]
    assert person_state(p, segs, 2.5).heading == pytest.approx(math.pi / 2)
    assert person_state(p, segs, 3.0 + SIT_TRANSITION_S / 2).sit == pytest.approx(0.5)
    assert person_state(p, segs, 5.0).sit == 1.0
    assert person_state(p, segs, 7.0 - SIT_TRANSITION_S / 4).sit == pytest.approx(0.25)
    assert person_state(p, segs, 8.0).sit == 0.0


def test_gait_amplitude_follows_speed() -> None:
    p = person(path=[{"x": 0.0, "y": 0.0}, {"x": 6.0, "y": 0.0, "speed": 0.6, "wait_s": 5}])
    segs = person_timeline(p)
    assert gait_amplitude(p, segs, 3.0) == pytest.approx(0.5)  # 0.6 / 1.2
    assert gait_amplitude(p, segs, 12.0) == 0.0  # standing


def test_clothes_change() -> None:
    p = person(clothes=[{"at_s": 5.0, "shirt": [1, 2, 3], "trousers": [4, 5, 6]}])
    assert clothes_at(p, 4.9) == (p.shirt, p.trousers)
    assert clothes_at(p, 5.0) == ((1, 2, 3), (4, 5, 6))


def test_robot_turns_in_place_then_drives() -> None:
    r = Robot.model_validate(
        {"turn_rate_deg_s": 45.0, "start_s": 1.0, "path": [{"x": 0.0, "y": 2.0, "speed": 0.5}]}
    )
    segs = robot_timeline(r)
    # turn 90 deg at 45 deg/s: 2 s (t = 1..3); drive 2 m at 0.5 m/s: 4 s (t = 3..7)
    assert [(g.kind, g.t0, g.t1) for g in segs] == [("turn", 1.0, 3.0), ("drive", 3.0, 7.0)]
    assert robot_pose(r, segs, 0.0) == (0.0, 0.0, 0.0)
    assert robot_pose(r, segs, 2.0) == pytest.approx((0.0, 0.0, math.pi / 4))
    assert robot_pose(r, segs, 5.0) == pytest.approx((0.0, 1.0, math.pi / 2))
    assert robot_pose(r, segs, 9.0) == pytest.approx((0.0, 2.0, math.pi / 2))


def test_static_robot_has_no_timeline() -> None:
    r = Robot(x=1.0, y=2.0, yaw_deg=90.0)
    assert robot_timeline(r) == []
    assert robot_pose(r, [], 5.0) == pytest.approx((1.0, 2.0, math.pi / 2))


coord = st.floats(-5.0, 5.0)


@settings(max_examples=40, deadline=None)
@given(
    st.lists(
        st.tuples(coord, coord, st.floats(0.2, 2.0), st.floats(0.0, 1.0)), min_size=1, max_size=5
    ),
    st.floats(0.0, 20.0),
)
def test_positions_are_continuous(
    points: list[tuple[float, float, float, float]], t: float
) -> None:
    """Nobody moves faster than the fastest segment speed allows."""
    p = person(path=[{"x": x, "y": y, "speed": v, "wait_s": w} for x, y, v, w in points])
    segs = person_timeline(p)
    dt = 0.01
    a, b = person_state(p, segs, t), person_state(p, segs, t + dt)
    vmax = max(v for _, _, v, _ in points)
    assert math.hypot(b.x - a.x, b.y - a.y) <= vmax * dt + 1e-9
    assert b.distance >= a.distance


def test_follower_keeps_its_offset_in_the_leaders_frame() -> None:
    from rgbd_eval.sim.motion import PersonState, follower_state
    from rgbd_eval.sim.scenario import Follow

    lead = PersonState(True, 2.0, 1.0, math.pi / 2, 1.0, 3.0, 0.0)  # facing +y
    f = follower_state(lead, Follow(id=1, right_m=0.7, behind_m=0.5))
    # facing +y, the right is +x and behind is -y: (2.7, 0.5)
    assert (f.x, f.y) == pytest.approx((2.7, 0.5))
    assert (f.heading, f.speed, f.distance, f.present) == (lead.heading, 1.0, 3.0, True)


def test_follow_validation() -> None:
    from rgbd_eval.errors import ConfigError
    from rgbd_eval.sim.scenario import parse_scenario

    lead = {"id": 1, "path": [{"x": 1.0, "y": 0.0}]}
    ok = parse_scenario(
        {"name": "g", "duration_s": 1, "people": [lead, {"id": 2, "follow": {"id": 1}}]}
    )
    assert ok.people[1].follow is not None and ok.people[1].follow.right_m == 0.7
    with pytest.raises(ConfigError, match=r"follow\.id=3"):
        parse_scenario(
            {"name": "g", "duration_s": 1, "people": [lead, {"id": 2, "follow": {"id": 3}}]}
        )
    chain = [lead, {"id": 2, "follow": {"id": 1}}, {"id": 3, "follow": {"id": 2}}]
    with pytest.raises(ConfigError, match=r"follow\.id=2"):
        parse_scenario({"name": "g", "duration_s": 1, "people": chain})
    both = {"id": 2, "path": [{"x": 0.0, "y": 0.0}], "follow": {"id": 1}}
    with pytest.raises(ConfigError, match="either a non-empty path or follow"):
        parse_scenario({"name": "g", "duration_s": 1, "people": [lead, both]})
