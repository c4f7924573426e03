"""`compare` on hand-made reports: better/worse/regressed, tolerances, unusable input."""

from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from rgbd_eval.cli.main import app
from rgbd_eval.compare import Status, compare_reports, parse_tolerances
from rgbd_eval.errors import CompareInputError

runner = CliRunner()


def report(mota: float, fp_rate: float, id_switches: int, gating: str = "iou") -> dict[str, Any]:
    metrics = {
        "mota": mota,
        "motp": 0.8,
        "idf1": 0.7,
        "main_tr": 0.75,
        "all_tr": 0.95,
        "fp_rate": fp_rate,
        "fn_rate": 0.05,
        "id_switches": id_switches,
        "recall_errors": 0,
        "fragmentations": 2,
    }
    return {
        "schema_version": 1,
        "evaluation": {"gating": gating, "threshold": 0.5},
        "config": {"tracker": {"min_confidence": -0.5}},
        "sequences": [{"name": "demo", "sha256": "ab" * 32, "metrics": metrics}],
        "overall": {"metrics": metrics},
    }


def test_statuses_and_default_tolerances() -> None:
    base = report(mota=0.900, fp_rate=0.040, id_switches=2)
    # MOTA -0.5 pp (within the 1 pp default): worse; FP -1 pp: better; one more ID switch: regressed
    # (tolerance 0 switches).
    cur = report(mota=0.895, fp_rate=0.030, id_switches=3)
    cur["config"]["tracker"]["min_confidence"] = -1.0
    c = compare_reports(base, cur)
    status = {d.metric: d.status for d in c.deltas if d.sequence == "demo"}
    assert status["mota"] is Status.WORSE
    assert status["fp_rate"] is Status.BETTER
    assert status["id_switches"] is Status.REGRESSED
    assert status["idf1"] is Status.SAME
    assert [d.metric for d in c.regressions] == ["id_switches"]
    assert c.config_changes == ("tracker.min_confidence: -0.5 -> -1.0",)
    # A looser tolerance turns the regression into "worse"; a tighter one makes MOTA regress.
    c2 = compare_reports(base, cur, parse_tolerances(["id_switches=1", "mota=0.001"]))
    assert {d.metric for d in c2.regressions} == {"mota"}


def test_motp_direction_follows_gating() -> None:
    base, cur = report(0.9, 0.04, 2, "metric"), report(0.9, 0.04, 2, "metric")
    cur["sequences"][0]["metrics"]["motp"] = 0.85  # metres: larger error is worse
    d = next(d for d in compare_reports(base, cur).deltas if d.metric == "motp")
    assert d.status is Status.REGRESSED  # 0.05 m worse > 0.01 tolerance


@pytest.mark.parametrize(
    ("mutate", "match"),
    [
        (lambda r: r["sequences"][0].update(name="other"), "different datasets"),
        (lambda r: r["sequences"][0].update(sha256="cd" * 32), "different content"),
        (lambda r: r["evaluation"].update(gating="metric"), "different scoring"),
    ],
)
def test_unusable_pairs(mutate: Any, match: str) -> None:
    base = report(0.9, 0.04, 2)
    cur = copy.deepcopy(base)
    mutate(cur)
    with pytest.raises(CompareInputError, match=match):
        compare_reports(base, cur)


def test_cli_exit_codes(tmp_path: Path) -> None:
    base, cur = tmp_path / "base.json", tmp_path / "cur.json"
    base.write_text(json.dumps(report(0.90, 0.04, 2)))
    cur.write_text(json.dumps(report(0.91, 0.04, 2)))
    md = tmp_path / "cmp.md"
    result = runner.invoke(app, ["compare", str(base), str(cur), "--markdown", str(md)])
    assert result.exit_code == 0, result.output
    assert "No regression" in md.read_text()
    cur.write_text(json.dumps(report(0.80, 0.04, 2)))
    result = runner.invoke(app, ["compare", str(base), str(cur)])
    assert result.exit_code == 1 and "demo/mota" in result.output
    cur.write_text(json.dumps({"schema_version": 99}))
    result = runner.invoke(app, ["compare", str(base), str(cur)])
    assert result.exit_code == 2 and "schema version 99" in result.output
    result = runner.invoke(app, ["compare", str(base), str(cur), "--tolerance", "speed=1"])
    assert result.exit_code == 2 and "METRIC=VALUE" in result.output
