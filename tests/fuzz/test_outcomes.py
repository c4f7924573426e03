"""Runs that must succeed with the right result, and interruptions that must leave nothing."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from rgbd_eval.io.groundtruth import write_csv
from tests.fuzz.cli import leftovers, run_cli
from tests.fuzz.corpus import (
    FRAMES,
    flip_byte,
    good_recording,
    ground_truth_objects,
    odd_recording,
    without_statistics,
)
from tests.io.conftest import depth_image


def test_bom_ground_truth_scores_as_without(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rec = good_recording(tmp_path)
    plain = tmp_path / "plain.csv"
    write_csv(plain, ground_truth_objects())
    bom = tmp_path / "bom.csv"
    bom.write_bytes(b"\xef\xbb\xbf" + plain.read_bytes())  # as a spreadsheet program saves it
    reports = []
    for gt in (plain, bom):
        out = tmp_path / f"out_{gt.stem}"
        result = run_cli(["run", str(rec), "--gt", str(gt), "--out", str(out)], capsys)
        assert result.code == 0, result.stderr
        reports.append(json.loads((out / "report.json").read_text()))
    assert reports[0]["sequences"][0]["counts"] == reports[1]["sequences"][0]["counts"]
    assert reports[1]["sequences"][0]["counts"]["num_gt"] == FRAMES


def test_some_empty_depth_frames_are_reported(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    def depth(i: int) -> np.ndarray:
        d = depth_image(i)
        return np.full_like(d, np.nan) if i in (1, 2) else d

    rec = odd_recording(tmp_path / "gaps.bag", depth=depth)
    out = tmp_path / "out"
    result = run_cli(["run", str(rec), "--out", str(out)], capsys)
    assert result.code == 0, result.stderr
    warning = "2 of 4 depth frames hold no valid pixel"
    assert warning in result.stdout
    assert any(
        warning in w
        for w in json.loads((out / "report.json").read_text())["sequences"][0]["warnings"]
    )


def test_rerun_keeps_the_users_files(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rec = good_recording(tmp_path)
    out = tmp_path / "runs" / "ci"
    assert run_cli(["run", str(rec), "--out", str(out)], capsys).code == 0
    (out / "compare.md").write_text("written by compare --markdown")
    assert run_cli(["run", str(rec), "--out", str(out)], capsys).code == 0
    assert (out / "compare.md").read_text() == "written by compare --markdown"
    assert (out / "report.json").is_file() and leftovers(tmp_path) == []


def test_output_is_checked_before_the_recording_is_read(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rec = good_recording(tmp_path)
    flip_byte(rec, 200)  # a corrupt recording would fail with 3 once read
    (tmp_path / "file.txt").write_text("x")
    result = run_cli(["run", str(rec), "--out", str(tmp_path / "file.txt")], capsys)
    assert result.code == 7, result.stderr  # the output problem comes first


def test_interrupted_sweep_leaves_no_output(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    import rgbd_eval.sweep

    def interrupted(*args: object, **kwargs: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(rgbd_eval.sweep, "run_sweep", interrupted)
    rec = good_recording(tmp_path)
    out = tmp_path / "sweep"
    args = ["sweep", "tracker.min_confidence", "-1", "0", "--dataset", str(rec), "--out", str(out)]
    result = run_cli([*args, "--jobs", "1"], capsys)
    assert result.code == 130 and result.error_lines == ["error: interrupted"]
    assert not out.exists() and leftovers(tmp_path) == []


def test_sweep_writes_all_outputs_or_none(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rec = good_recording(tmp_path)
    out = tmp_path / "sweep"
    args = ["sweep", "tracker.min_confidence", "-1", "0", "--dataset", str(rec), "--out", str(out)]
    result = run_cli([*args, "--jobs", "1"], capsys)
    assert result.code == 0, result.stderr
    assert {p.name for p in out.iterdir()} >= {"sweep.csv", "sweep.json", "sweep.png"}
    assert leftovers(tmp_path) == []


def test_sigterm_during_run_cleans_up(tmp_path: Path) -> None:
    rec = good_recording(tmp_path)
    out = tmp_path / "out"
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[2] / "src"))
    proc = subprocess.Popen(
        [sys.executable, "-m", "rgbd_eval", "run", str(rec), "--out", str(out)],
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    # The staging folder appears before any recording is read; terminate then.
    for _ in range(600):
        if leftovers(tmp_path) or proc.poll() is not None:
            break
        time.sleep(0.05)
    proc.send_signal(signal.SIGTERM)
    _, stderr = proc.communicate(timeout=120)
    if proc.returncode == 0:
        pytest.skip("the run finished before SIGTERM arrived")
    assert proc.returncode == 128 + signal.SIGTERM, stderr
    assert stderr.strip().splitlines()[-1] == f"error: interrupted by signal {int(signal.SIGTERM)}"
    assert leftovers(tmp_path) == [] and not out.exists()


def test_mcap_without_statistics_is_read_not_called_empty(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rec = without_statistics(good_recording(tmp_path), tmp_path / "nostats.mcap")
    out = tmp_path / "out"
    result = run_cli(["run", str(rec), "--out", str(out)], capsys)
    assert result.code == 0, result.stderr  # was exit 3, "recording is empty (no messages)"
    report = json.loads((out / "report.json").read_text())
    assert report["sequences"][0]["frames"] == FRAMES and report["sequences"][0]["scored"]
