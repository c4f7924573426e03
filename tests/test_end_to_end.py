"""End to end on a freshly synthesized sequence: scored, plausible, and bit-for-bit repeatable."""

from __future__ import annotations

from pathlib import Path

import pytest

from rgbd_eval.config import load_config
from rgbd_eval.datasets import scenarios_dir
from rgbd_eval.io.recording import open_recording
from rgbd_eval.pipeline import detect_and_track, detect_sequence, run_sequence, track_sequence
from rgbd_eval.sim import load_scenario, synthesize


@pytest.mark.slow
def test_demo_scenario_end_to_end(tmp_path: Path) -> None:
    scenario = load_scenario(scenarios_dir() / "demo.yaml")
    rec = synthesize(scenario, tmp_path / "demo60.mcap", max_frames=60).recording
    config = load_config(method="basso2012")
    first = run_sequence(rec, config)
    second = run_sequence(rec, config)
    assert first.scores is not None and second.scores is not None
    assert first.scores.counts == second.scores.counts  # same input, config, seed: same numbers
    summary = first.scores.summary()
    # Three people walk in view at 2-6 m: most instances are tracked with well-placed boxes.
    assert summary["num_gt"] is not None and int(summary["num_gt"]) > 100
    assert summary["mota"] is not None and float(summary["mota"]) > 0.5
    assert summary["motp"] is not None and float(summary["motp"]) > 0.7


@pytest.mark.slow
def test_interleaved_run_equals_detect_then_track(tmp_path: Path) -> None:
    scenario = load_scenario(scenarios_dir() / "demo.yaml")
    rec = synthesize(scenario, tmp_path / "demo30.mcap", max_frames=30).recording
    config = load_config(method="basso2012")
    detections = detect_sequence(open_recording(rec), config)
    tracks = track_sequence(detections, config)
    kept, interleaved = detect_and_track(open_recording(rec), config)
    assert interleaved == tracks and sum(map(len, tracks)) > 0
    assert kept.stamps_ns == detections.stamps_ns
    for mine, theirs in zip(kept.detections, detections.detections, strict=True):
        assert [d.appearance for d in mine] == [None] * len(theirs)
        assert [d.position for d in mine] == [d.position for d in theirs]
        assert [d.box2d for d in mine] == [d.box2d for d in theirs]
