"""The scenario model: shipped files load, bad files fail with a ConfigError naming the key."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
import yaml

from rgbd_eval.errors import ConfigError
from rgbd_eval.sim.scenario import load_scenario, parse_scenario, scenario_paths, scenarios_dir

THESIS = {
    "static_simple",
    "static_complex",
    "static_obstacles",
    "moving_simple",
    "moving_complex",
    "moving_obstacles",
}


def test_shipped_scenarios_load_and_match_the_thesis_test_set() -> None:
    scenarios = {p.stem: load_scenario(p) for p in scenario_paths()}
    assert THESIS | {"demo"} <= set(scenarios)
    for name in THESIS:
        sc = scenarios[name]
        # seed 000, chapter 7: about 750 frames, three people; Kinect at 30 Hz
        assert sc.n_frames == 750
        assert len(sc.people) == 3
        assert sc.sensor.rate_hz == 30.0
        assert sc.name == name
        assert bool(sc.robot.path) == name.startswith("moving")
        # "no obstacle is present" in scenarios 1 and 2: furniture only along the walls
        r = sc.room
        inside = [
            o
            for o in sc.obstacles
            if r.x_min + 1 < o.x < r.x_max - 1 and r.y_min + 1 < o.y < r.y_max - 1
        ]
        assert bool(inside) == name.endswith("obstacles")
    demo = scenarios["demo"]
    assert demo.n_frames == 150
    assert len(demo.people) == 3
    assert not demo.robot.path


def test_thesis_scenes_are_a_lab_with_walking_people_only() -> None:
    # Issue 31: the thesis' sequences were recorded in a lab (7.1) with people walking; the
    # seated people and the person-sized clutter (coat stands, plants, cabinets, mannequins)
    # are ours, in the *_clutter scenes only.
    clutter_kinds = {"coat_stand", "plant", "cabinet", "mannequin"}
    lab = {"table", "chair", "shelf", "door"}
    for name in THESIS:
        sc = load_scenario(scenarios_dir() / f"{name}.yaml")
        kinds = {o.kind.value for o in sc.obstacles}
        assert lab <= kinds, name
        assert not kinds & (clutter_kinds | {"sofa"}), name
        assert all(w.sit_s == 0.0 for p in sc.people for w in p.path), name
    for name in ("static_clutter", "moving_clutter"):
        sc = load_scenario(scenarios_dir() / f"{name}.yaml")
        assert clutter_kinds <= {o.kind.value for o in sc.obstacles}, name
        assert any(w.sit_s > 0.0 for p in sc.people for w in p.path), name


def test_kinect_defaults() -> None:
    sc = parse_scenario({"name": "x", "duration_s": 1.0})
    # seed 000, 2.1: 640x480, 57 x 43 degrees
    assert (sc.sensor.width, sc.sensor.height) == (640, 480)
    # fx = 320 / tan(28.5 deg) = 320 / 0.54296 = 589.37; fy = 240 / tan(21.5 deg) = 609.28
    assert sc.sensor.fx == pytest.approx(589.37, abs=0.01)
    assert sc.sensor.fy == pytest.approx(609.28, abs=0.01)
    assert sc.sensor.max_range_m == 8.0
    # 1 s at 30 Hz = 30 frames; frame 3 is 3/30 s = 100 ms after the first stamp
    assert sc.n_frames == 30
    assert sc.stamp_ns(3) - sc.stamp_ns(0) == 100_000_000


def test_unknown_key_is_rejected_with_its_location() -> None:
    with pytest.raises(ConfigError, match=r"people\.0\.hieght: unknown key"):
        parse_scenario(
            {
                "name": "x",
                "duration_s": 1,
                "people": [{"id": 1, "hieght": 1.7, "path": [{"x": 1, "y": 0}]}],
            }
        )


@pytest.mark.parametrize(
    ("patch", "where"),
    [
        ({"people": [{"id": 1, "height": 2.1, "path": [{"x": 1, "y": 0}]}]}, r"people\.0\.height"),
        ({"people": [{"id": 1, "height": 1.4, "path": [{"x": 1, "y": 0}]}]}, r"people\.0\.height"),
        ({"people": [{"id": 1, "path": []}]}, r"people\.0: .*non-empty path"),
        ({"people": [{"id": 1, "shirt": [300, 0, 0], "path": [{"x": 1, "y": 0}]}]}, "shirt"),
        ({"sensor": {"depth_decimation": 3}}, r"sensor\.depth_decimation"),
        ({"sensor": {"min_range_m": 5.0, "max_range_m": 4.0}}, "min_range_m"),
        ({"room": {"x_min": 0.0, "x_max": 0.5}}, "room"),
        ({"duration_s": 0.0}, "duration_s"),
        ({"name": "has space"}, "name"),
    ],
)
def test_out_of_range_values_are_rejected(patch: dict[str, object], where: str) -> None:
    data: dict[str, object] = {"name": "x", "duration_s": 1.0}
    data.update(patch)
    with pytest.raises(ConfigError, match=where):
        parse_scenario(data, "test")


def test_duplicate_person_ids_are_rejected() -> None:
    person = {"id": 4, "path": [{"x": 1.0, "y": 0.0}]}
    with pytest.raises(ConfigError, match="unique"):
        parse_scenario({"name": "x", "duration_s": 1.0, "people": [person, person]})


def test_clothes_changes_must_be_ordered() -> None:
    person = {
        "id": 1,
        "path": [{"x": 1.0, "y": 0.0}],
        "clothes": [
            {"at_s": 5.0, "shirt": [1, 2, 3], "trousers": [1, 2, 3]},
            {"at_s": 2.0, "shirt": [1, 2, 3], "trousers": [1, 2, 3]},
        ],
    }
    with pytest.raises(ConfigError, match="time order"):
        parse_scenario({"name": "x", "duration_s": 1.0, "people": [person]})


def test_load_errors_name_the_file(tmp_path: Path) -> None:
    missing = tmp_path / "nope.yaml"
    with pytest.raises(ConfigError, match=r"nope\.yaml"):
        load_scenario(missing)
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: x\nduration_s: 1\nrobot: {wheels: 4}\n")
    with pytest.raises(ConfigError, match=r"bad\.yaml.*robot\.wheels: unknown key"):
        load_scenario(bad)


def test_obstacle_defaults_per_kind() -> None:
    sc = parse_scenario(
        {"name": "x", "duration_s": 1.0, "obstacles": [{"kind": "coat_stand", "x": 1, "y": 2}]}
    )
    ob = sc.obstacles[0]
    assert ob.extent[2] == 1.8  # person-sized
    assert math.isclose(ob.x, 1.0)


def test_readme_example_is_a_valid_scenario() -> None:
    text = (scenarios_dir() / "README.md").read_text()
    block = text.split("```yaml\n", 1)[1].split("```", 1)[0]
    sc = parse_scenario(yaml.safe_load(block), "README")
    assert sc.people[1].follow is not None and sc.n_frames == 750


def test_overrides_apply_to_nested_keys_and_are_validated() -> None:
    demo = scenarios_dir() / "demo.yaml"
    sc = load_scenario(demo, [("recording.rgb_format", "raw"), ("sensor.depth_decimation", 2)])
    assert sc.recording.rgb_format == "raw" and sc.sensor.depth_decimation == 2
    assert load_scenario(demo).recording.rgb_format == "jpeg"  # the file is untouched
    with pytest.raises(ConfigError, match=r"unknown key 'nope' in recording"):
        load_scenario(demo, [("recording.nope", 1)])
    with pytest.raises(ConfigError, match="rgb_format"):
        load_scenario(demo, [("recording.rgb_format", "png")])
    with pytest.raises(ConfigError, match="duration_s is not a section"):
        load_scenario(demo, [("duration_s.x", 1)])
