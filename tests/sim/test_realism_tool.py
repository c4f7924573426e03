"""tools/realism/measure.py's per-person report: who each rendered person is, and their row."""

from __future__ import annotations

from rgbd_eval.sim.scenario import parse_scenario
from rgbd_eval.sim.simulate import Simulator
from tests.tools import load_tool

TOOL = load_tool("tools/realism/measure.py", "realism_measure")


def test_describe_names_the_drawn_person() -> None:
    # person 3 of the grid: height 1.55 + 0.08 * 3 = 1.79 m, as the scene gives it
    sim = Simulator(parse_scenario(TOOL.scene(4.0, 90, 3, False), "realism"))
    text = TOOL.describe(sim, sim.time(sim.n_frames - 1))
    sex, height, weight, *_clothes, hair = text.split(", ")
    assert sex in ("female", "male")
    assert height == "1.79 m"
    assert weight.startswith("weight 0.")
    assert hair.endswith(" hair")
    # the same person at the same seed looks the same in every cell
    other = Simulator(parse_scenario(TOOL.scene(6.0, 180, 3, False), "realism"))
    assert TOOL.describe(other, other.time(other.n_frames - 1)) == text


def test_people_table_rows() -> None:
    # person 2: found in 3 of 4 shots; best scores 0.1, 0.6, 0.7, 0.9 -> median (0.6 + 0.7) / 2
    persons = {
        2: {"look": "male, 1.71 m", "shown": 4, "found": 3, "ssd_best": [0.1, 0.6, 0.7, 0.9]},
        1: {"look": "female, 1.63 m", "shown": 2, "found": 0, "ssd_best": [0.2, 0.0]},
    }
    lines = TOOL._people_table(persons).splitlines()
    assert lines[2] == "| 1 | female, 1.63 m | 0/2 | 0.10 |"
    assert lines[3] == "| 2 | male, 1.71 m | 3/4 | 0.65 |"
