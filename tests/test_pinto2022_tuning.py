"""pinto2022's re-ID calibration runs on tuning scenes only (issue 31)."""

from __future__ import annotations

from pathlib import Path
from types import ModuleType

import pytest

from rgbd_eval.sim.scenario import load_scenario, scenarios_dir
from tests.tools import load_tool

TUNING = sorted((scenarios_dir() / "tuning").glob("pinto2022_*_tuning.yaml"))
SCORED = sorted((scenarios_dir() / "pinto2022").glob("*.yaml"))


def _tool() -> ModuleType:
    return load_tool("tools/pinto2022/calibrate_reid.py", "pinto2022_calibrate_reid")


def test_the_tuning_scenes_differ_from_the_scored_scenes() -> None:
    assert len(TUNING) >= 2 and SCORED
    for t in map(load_scenario, TUNING):
        ids = {p.id for p in t.people}
        for path in SCORED:
            scored = load_scenario(path)
            assert t.seed != scored.seed, path
            assert t.room != scored.room, path
            assert ids.isdisjoint(p.id for p in scored.people), path  # other people drawn
            assert {(o.kind, o.x, o.y) for o in t.obstacles}.isdisjoint(
                {(o.kind, o.x, o.y) for o in scored.obstacles}
            ), path
            assert (t.robot.x, t.robot.y, t.robot.yaw_deg) != (
                scored.robot.x,
                scored.robot.y,
                scored.robot.yaw_deg,
            ), path


def test_the_calibration_refuses_a_scored_scene(tmp_path: Path) -> None:
    with pytest.raises(SystemExit, match="not a tuning scene"):
        _tool().render([scenarios_dir() / "pinto2022" / "still.yaml"], tmp_path)
    assert not list(tmp_path.iterdir())  # nothing rendered
