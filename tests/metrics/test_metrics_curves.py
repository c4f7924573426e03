"""Threshold curves: one pass equals separate `score` runs of the filtered tracker output."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from rgbd_eval.cli.main import app
from rgbd_eval.config import EvaluationConfig
from rgbd_eval.metrics import curves
from rgbd_eval.report.scoring import score_sequence

TUD = Path(pytest.importorskip("motmetrics").__file__).parent / "data"


def _with_confidences(folder: Path) -> tuple[Path, Path]:
    """TUD-Campus' tracker output with a confidence per row (seeded), and its ground truth."""
    rows = np.loadtxt(TUD / "TUD-Campus" / "test.txt", delimiter=",")
    rows[:, 6] = np.round(np.random.default_rng(5).uniform(0.0, 1.0, len(rows)), 3)
    tracks = folder / "tracks.txt"
    np.savetxt(tracks, rows, delimiter=",", fmt="%g")
    return tracks, TUD / "TUD-Campus" / "gt.txt"


def test_thresholds_are_the_values_present_capped_by_quantiles() -> None:
    assert curves.thresholds([0.5, 0.1, 0.1, 0.9], 5) == [0.1, 0.5, 0.9]
    values = sorted(float(v) for v in range(100))
    picked = curves.thresholds(values, 5)
    # Quantiles 0, 1/4, 1/2, 3/4, 1 of 100 values (each one of them): the lowest keeps all.
    assert picked == [0.0, 24.0, 49.0, 74.0, 99.0]
    with pytest.raises(ValueError, match="at least 2"):
        curves.thresholds(values, 1)


def test_the_curve_equals_separate_score_runs(tmp_path: Path) -> None:
    tracks, gt = _with_confidences(tmp_path)
    out = tmp_path / "out"
    args = ["score", str(tracks), "--gt", str(gt), "--out", str(out), "--curve"]
    result = CliRunner().invoke(app, [*args, "--curve-points", "6", "--json"])
    assert result.exit_code == 0, result.output
    curve = json.loads(result.output)["analysis"]["curve"]
    assert curve["available"] and curve["max_points"] == 6
    points = curve["points"]
    assert len(points) == 6
    rows = np.loadtxt(tracks, delimiter=",")
    for point in points:
        # The same tracker output with only the rows of confidence >= the threshold, scored
        # as `rgbd-eval score` scores a file.
        kept = tmp_path / f"kept_{point['threshold']}.txt"
        np.savetxt(kept, rows[rows[:, 6] >= point["threshold"]], delimiter=",", fmt="%g")
        alone = score_sequence("TUD-Campus", kept, gt, EvaluationConfig(), 0)
        assert point["counts"] == alone.scores.counts.to_dict(), point["threshold"]
    # The lowest threshold keeps every row: the report's own counts.
    report = json.loads((out / "report.json").read_text())
    assert points[0]["counts"] == report["sequences"][0]["counts"]
    # The best threshold of MOTA is one of those scored, and the best of them.
    motas = {p["threshold"]: p["metrics"]["mota"] for p in points}
    assert motas[curve["best"]["mota"]] == max(motas.values())


def test_no_confidences_no_curve() -> None:
    gt = TUD / "TUD-Campus" / "gt.txt"
    scored = score_sequence(
        "TUD-Campus", TUD / "TUD-Campus" / "test.txt", gt, EvaluationConfig(), 0
    )
    # TUD's tracker output has -1 in every row: one value, no curve.
    curve = curves.sweep([(scored.aligned.gt, scored.aligned.tracks)], EvaluationConfig())
    assert not curve.points and "same confidence" in curve.reason
