"""``run --method cielniak2010`` end to end on a short synthetic thermal recording."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from rgbd_eval.sim import parse_scenario, synthesize
from tests.sim.test_thermal_camera import SCENARIO


@pytest.mark.slow
def test_run_reads_the_thermal_stream_and_scores_image_boxes(tmp_path: Path) -> None:
    rec = tmp_path / "thermal.mcap"
    synthesize(parse_scenario({**SCENARIO, "duration_s": 0.5}), rec)  # 15 frames
    env = {**os.environ, "RGBD_EVAL_CACHE": str(tmp_path / "cache")}
    res = subprocess.run(
        [sys.executable, "-m", "rgbd_eval", "run", str(rec), "--method", "cielniak2010",
         "--out", str(tmp_path / "out"), "--json"],
        cwd=tmp_path, env=env, capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert res.returncode == 0, res.stderr
    report = json.loads(res.stdout)
    text = json.dumps(report)
    assert "cielniak2010" in text and '"iou"' in text
