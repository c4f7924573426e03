"""dmtbs's smallest blob is chosen on a tuning scene by a rule fixed in advance (issue 31)."""

from __future__ import annotations

from pathlib import Path
from types import ModuleType

import pytest
import yaml

from rgbd_eval.methods.dmtbs.detector import DmtbsDetectorConfig
from rgbd_eval.sim.scenario import load_scenario, scenarios_dir
from tests.tools import load_tool

ROOT = Path(__file__).resolve().parents[1]
TUNING = scenarios_dir() / "tuning" / "dmtbs_hall_tuning.yaml"
SCORED = scenarios_dir() / "dmtbs"


def _tool() -> ModuleType:
    return load_tool("tools/dmtbs/min_blob_area.py", "dmtbs_min_blob_area")


TOOL = _tool()


def test_fewest_errors_then_the_middle_of_the_widest_best_interval() -> None:
    # People's largest near blobs 0.08, 0.2, 0.3 (and one person with none: an error at
    # every threshold); false blobs 0.01, 0.03. Kept when surface >= t: t in (0.03, 0.08]
    # loses no person and keeps no false blob: 1 error; its middle is 0.055.
    people = [0.08, 0.2, 0.3, 0.0]
    false = [0.01, 0.03]
    assert TOOL.errors_at(people, false, 0.0) == 3
    assert TOOL.errors_at(people, false, 0.05) == 1
    assert TOOL.errors_at(people, false, 0.1) == 2
    assert TOOL.choose(people, false) == pytest.approx((0.055, 0.03, 0.08, 1))
    # No false blob at all: every t up to the smallest person's blob is best, from 0.
    assert TOOL.choose([0.0817, 0.5], []) == pytest.approx((0.04085, 0.0, 0.0817, 0))
    # Two best intervals with 1 error each, (0.02, 0.03] and (0.05, 0.4]: the widest wins.
    assert TOOL.choose([0.03, 0.4], [0.02, 0.05]) == pytest.approx((0.225, 0.05, 0.4, 1))


def test_the_tuning_scene_differs_from_the_scored_scenes() -> None:
    tuning = load_scenario(TUNING)
    for path in sorted(SCORED.glob("*.yaml")):
        if path.name.startswith("run-"):
            continue
        scored = load_scenario(path)
        assert tuning.seed != scored.seed, path
        assert tuning.room != scored.room, path
        assert {(o.kind, o.x, o.y) for o in tuning.obstacles}.isdisjoint(
            {(o.kind, o.x, o.y) for o in scored.obstacles}
        ), path
        assert [p.path for p in tuning.people] != [p.path for p in scored.people], path
        # the people are drawn from the seed: none is given a height
        assert all("height" not in p.model_fields_set for p in tuning.people)


def test_method_file_takes_the_tuned_value() -> None:
    data = yaml.safe_load((ROOT / "src/rgbd_eval/methods/dmtbs/method.yaml").read_text())
    assert data["detector"]["min_blob_area_m2"] == 0.041 == DmtbsDetectorConfig().min_blob_area_m2
