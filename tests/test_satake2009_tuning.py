"""satake2009's measured settings are chosen on tuning scenes by a rule fixed in advance (issue 31)."""

from __future__ import annotations

from pathlib import Path
from types import ModuleType

import pytest
import yaml

from rgbd_eval.config import load_config
from rgbd_eval.sim.scenario import load_scenario, scenarios_dir
from tests.tools import load_tool

ROOT = Path(__file__).resolve().parents[1]
TUNING = scenarios_dir() / "tuning" / "satake2009_crossing_tuning.yaml"
SCORED = [scenarios_dir() / f"satake2009_{n}.yaml" for n in ("crossing", "following", "clutter")]


def _tool() -> ModuleType:
    return load_tool("tools/satake2009/tune.py", "satake2009_tune")


TOOL = _tool()


def _outcome(fp: int, fn: int, ids: int = 0, num_gt: int = 100) -> object:
    return TOOL.Outcome(fp + fn + ids, num_gt, fp, fn, ids, 0.1, 40.0)


def test_fewest_errors_then_the_first_cheapest_candidate() -> None:
    # errors 12, 9, 9, 10: the second and third tie at 9; the list is cheapest first, so
    # the second (index 1) is chosen. MOTA 91 %.
    outcomes = [_outcome(2, 10), _outcome(4, 5), _outcome(0, 8, 1), _outcome(0, 10)]
    assert TOOL.choose(outcomes) == 1
    assert outcomes[1].mota == pytest.approx(0.91)
    # one error fewer wins whatever the cost (MOTP and CPU are not used)
    assert TOOL.choose([_outcome(1, 10), _outcome(1, 9)]) == 1
    with pytest.raises(ValueError):
        TOOL.choose([])


def test_every_candidate_list_is_valid_and_holds_the_method_value() -> None:
    for keys, candidates in TOOL.SWEEPS:
        assert len(set(candidates)) == len(candidates) >= 2, keys
        for values in candidates:
            load_config(
                method="satake2009",
                overrides=[f"{k}={v}" for k, v in zip(keys, values, strict=True)],
            )
        config = load_config(method="satake2009").model_dump(mode="json")
        current = tuple(str(config[k.split(".")[0]][k.split(".")[1]]) for k in keys)
        assert current in candidates, (keys, current)


def test_the_tuning_scene_is_marked_and_differs_from_the_scored_scenes() -> None:
    assert TUNING.read_text().startswith("# TUNING scene")
    tuning = load_scenario(TUNING)
    assert tuning.name == "satake2009_crossing_tuning"
    assert any(r.kind == "stereo_pair" for r in tuning.rig)
    # short: one run of the sweep stays well under 30 s of CPU
    assert tuning.duration_s * tuning.sensor.rate_hz <= 120
    for path in SCORED:
        scored = load_scenario(path)
        assert tuning.seed != scored.seed, path
        assert tuning.room != scored.room, path
        assert {p.id for p in tuning.people}.isdisjoint({p.id for p in scored.people}), path
        assert [p.path for p in tuning.people] != [p.path for p in scored.people], path
        assert {(o.kind, o.x, o.y) for o in tuning.obstacles}.isdisjoint(
            {(o.kind, o.x, o.y) for o in scored.obstacles}
        ), path
    # the people's bodies and clothes are drawn from the seed: none is given a height or shirt
    assert all(not {"height", "shirt"} & p.model_fields_set for p in tuning.people)


def test_method_file_takes_the_tuned_values() -> None:
    data = yaml.safe_load((ROOT / "src/rgbd_eval/methods/satake2009/method.yaml").read_text())
    det, trk = data["detector"], data["tracker"]
    assert (det["uniqueness_ratio"], det["speckle_window"]) == (0, 0)
    assert det["num_disparities"] == 32
    assert det["template_rows"] == 16
    assert det["distance_ratio"] == 1.2
    assert det["min_score"] == 0.8
    assert trk["search_rows"] == 40
    assert trk["search_steps"] == 0
