"""Fixtures: the demo scenario's first 60 frames, run once with the default method."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from rgbd_eval.cli.main import app
from rgbd_eval.datasets import scenarios_dir
from rgbd_eval.sim import load_scenario, synthesize

#: Frames of the demo used: three people crossing, tracked, missed and occluded.
FRAMES = 60


@pytest.fixture(scope="session")
def demo(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The demo recording's first frames (with its own ground-truth sidecar)."""
    out = tmp_path_factory.mktemp("annotate_demo") / "demo.mcap"
    return synthesize(
        load_scenario(scenarios_dir() / "demo.yaml"), out, max_frames=FRAMES
    ).recording


@pytest.fixture(scope="session")
def demo_run(demo: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``rgbd-eval run`` on it: the tracks the tasks are pre-annotated with."""
    out = tmp_path_factory.mktemp("annotate_run") / "run"
    result = CliRunner().invoke(app, ["run", str(demo), "--out", str(out)])
    assert result.exit_code == 0, result.output
    return out
