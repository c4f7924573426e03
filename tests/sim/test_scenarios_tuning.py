"""Tuning scenes (issue 31): they parse, and nothing that `reproduce` scores reads them."""

from __future__ import annotations

from pathlib import Path

import pytest

from rgbd_eval.sim.scenario import load_scenario, scenarios_dir

TUNING = sorted((scenarios_dir() / "tuning").glob("*.yaml"))
METHODS = Path(__file__).resolve().parents[2] / "src" / "rgbd_eval" / "methods"


def test_there_are_tuning_scenes() -> None:
    assert TUNING


@pytest.mark.parametrize("path", TUNING, ids=lambda p: p.stem)
def test_a_tuning_scene_parses_and_says_it_is_for_tuning(path: Path) -> None:
    scenario = load_scenario(path)
    assert scenario.name.endswith("_tuning")
    assert path.read_text().startswith("# TUNING scene")


def test_no_experiment_reads_a_tuning_scene() -> None:
    # the experiments of `reproduce` name their scenes by file: none is under tuning/ and
    # none is a tuning scene's name
    names = [load_scenario(p).name for p in TUNING]
    for experiments in sorted(METHODS.glob("*/experiments.py")):
        text = experiments.read_text()
        assert "tuning/" not in text, experiments
        for name in names:
            assert name not in text, (experiments, name)
