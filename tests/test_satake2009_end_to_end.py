"""satake2009 end to end: the crossing scenario's first second, stereo only, scored."""

from __future__ import annotations

from pathlib import Path

import pytest

from rgbd_eval.config import load_config
from rgbd_eval.datasets import scenarios_dir
from rgbd_eval.pipeline import run_sequence
from rgbd_eval.sim import load_scenario, synthesize


@pytest.mark.slow
def test_satake2009_tracks_person_a_from_the_stereo_pair(tmp_path: Path) -> None:
    # Frames 0-29 (1.5 s at 20 fps) of satake2009_crossing: person A stands 5 m ahead of
    # the approaching robot (B enters at 1.0 s, at the image border). A is found from
    # SGBM depth and templates alone, and kept under one id.
    scenario = load_scenario(scenarios_dir() / "satake2009_crossing.yaml")
    rec = synthesize(scenario, tmp_path / "crossing30.mcap", max_frames=30).recording
    config = load_config(method="satake2009")
    result = run_sequence(rec, config)
    assert result.scores is not None
    s = result.scores.summary()
    assert s["num_gt"] is not None and int(s["num_gt"]) >= 30
    assert s["mota"] is not None and float(s["mota"]) > 0.5
    assert s["id_switches"] == 0
    assert s["motp"] is not None and float(s["motp"]) < 0.3  # metres: metric gating
