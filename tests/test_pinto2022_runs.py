"""pinto2022 through `rgbd-eval run` on a Re-ID scenario, and its detector feeding basso2012's
tracker on a recording (the issue's "Show" items), plus the frame-rate measurement of
`reproduce pinto2022`."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from rgbd_eval.cli.main import app
from rgbd_eval.config import load_config
from rgbd_eval.datasets import scenarios_dir
from rgbd_eval.methods.pinto2022.detector_config import Pinto2022DetectorConfig
from rgbd_eval.methods.pinto2022.experiments import frame_rate
from rgbd_eval.pipeline import run_sequence
from rgbd_eval.sim import load_scenario, synthesize

runner = CliRunner()
FRAMES = 40  # 4 s of the 10 Hz scenario: tracks confirm after 3 frames (III-E)


@pytest.fixture(scope="module")
def still(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The first 4 s of the 'still' Re-ID scenario (Table I), with its ground truth."""
    scenario = load_scenario(scenarios_dir() / "pinto2022" / "still.yaml")
    out = tmp_path_factory.mktemp("pinto") / "still.mcap"
    return synthesize(scenario, out, max_frames=FRAMES).recording


@pytest.mark.slow
def test_run_cli_on_a_reid_scenario_scores_in_metres(still: Path, tmp_path: Path) -> None:
    out = tmp_path / "run"
    result = runner.invoke(
        app, ["run", str(still), "--method", "pinto2022", "--out", str(out), "--json"]
    )
    assert result.exit_code == 0, result.output
    report = json.loads(result.output)
    seq = report["sequences"][0]
    assert seq["frames"] == FRAMES and seq["scored"] is True
    assert report["config"]["evaluation"]["gating"] == "metric"
    counts = seq["counts"]
    assert counts["num_matches"] > 0
    # metric gating at 1 m (V-B): MOTP is a mean distance in metres, so at most the gate
    assert 0.0 <= seq["metrics"]["motp"] <= 1.0
    assert (out / "still.tracks.csv").stat().st_size > 0


@pytest.mark.slow
def test_pinto_detector_feeds_basso_tracker_on_a_recording(still: Path) -> None:
    # The mixed pairing: pinto2022's CNN boxes, localiser and embedding; basso2012's UKF and
    # track management (its colour classifier off: the detections carry no histogram).
    config = load_config(
        method="basso2012",
        overrides=[
            "detector.name=pinto2022",
            "tracker.classifier=false",
            "evaluation.gating=metric",
        ],
    )
    assert isinstance(config.detector, Pinto2022DetectorConfig)
    result = run_sequence(still, config)
    assert result.scores is not None
    assert sum(len(d) for d in result.detections.detections) > 0
    assert int(result.scores.summary()["num_matches"] or 0) > 0


@pytest.mark.slow
def test_frame_rate_counts_cpu_and_wall_time(still: Path) -> None:
    rate = frame_rate(still, frames=5)
    assert rate.frames == 5
    assert rate.cpu_fps > 0.0 and rate.wall_fps > 0.0
