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


PROVENANCE = {
    "generator": "rgbd-eval synth",
    "tool_version": "0.1.0",
    "renderer_version": 2,
    "scenario": "demo",
    "scenario_sha256": "11" * 32,
    "scenario_file_sha256": "22" * 32,
    "seed": 7,
    "frames": 150,
    "container": "mcap",
    "closed_loop": None,
}


def test_same_provenance_other_bytes_is_compared_with_a_note() -> None:
    base = report(0.9, 0.04, 2)
    base["sequences"][0]["provenance"] = dict(PROVENANCE)
    base["machine"] = {"cpu": "AMD EPYC", "flags": "avx2 fma"}
    base["libraries"] = {"mcap": "1.2.0"}
    cur = copy.deepcopy(base)
    cur["sequences"][0]["sha256"] = "cd" * 32
    cur["machine"] = {"cpu": "Intel Xeon", "flags": "avx2 fma avx512f"}
    c = compare_reports(base, cur)
    assert c.regressions == ()
    (note,) = c.notes
    assert "differ in bytes" in note and "one provenance" in note and "seed 7" in note
    assert "machine.cpu: 'AMD EPYC' -> 'Intel Xeon'" in note
    assert "mcap" not in note  # the same library versions are not listed


@pytest.mark.parametrize(
    ("change", "named"),
    [
        ({"seed": 8}, "seed: 7 -> 8"),
        ({"renderer_version": 3}, "renderer_version: 2 -> 3"),
        ({"scenario_sha256": "33" * 32}, "scenario_sha256"),
    ],
)
def test_other_provenance_is_refused_naming_what_differs(
    change: dict[str, Any], named: str
) -> None:
    base = report(0.9, 0.04, 2)
    base["sequences"][0]["provenance"] = dict(PROVENANCE)
    cur = copy.deepcopy(base)
    cur["sequences"][0]["sha256"] = "cd" * 32
    cur["sequences"][0]["provenance"].update(change)
    with pytest.raises(CompareInputError, match="different provenance") as err:
        compare_reports(base, cur)
    assert named in str(err.value)
    # the file digest alone (a comment edited in the scenario file) is not part of the identity
    same = copy.deepcopy(base)
    same["sequences"][0]["sha256"] = "cd" * 32
    same["sequences"][0]["provenance"]["scenario_file_sha256"] = "44" * 32
    assert len(compare_reports(base, same).notes) == 1


def test_cli_prints_the_note_and_gates_on_the_metrics(tmp_path: Path) -> None:
    base = report(0.9, 0.04, 2)
    base["sequences"][0]["provenance"] = dict(PROVENANCE)
    cur = copy.deepcopy(base)
    cur["sequences"][0]["sha256"] = "cd" * 32
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    a.write_text(json.dumps(base))
    b.write_text(json.dumps(cur))
    result = runner.invoke(app, ["compare", str(a), str(b), "--markdown", str(tmp_path / "c.md")])
    assert result.exit_code == 0, result.output
    assert "note: sequence 'demo': the recordings differ in bytes" in result.stderr
    assert "Notes:" in (tmp_path / "c.md").read_text()


# ----------------------------------------------------------------------------- significance

TUD = Path(pytest.importorskip("motmetrics").__file__).parent / "data" / "TUD-Campus"


def _scored(tmp_path: Path, name: str, keep: Any = None) -> Path:
    """`rgbd-eval score` of TUD-Campus' tracker output (rows kept by ``keep``) into a folder."""
    rows = (TUD / "test.txt").read_text().splitlines()
    tracks = tmp_path / name / "TUD-Campus.txt"  # the sequence is named after the file
    tracks.parent.mkdir()
    tracks.write_text("\n".join(r for r in rows if keep is None or keep(r)) + "\n")
    out = tmp_path / name / "out"
    result = runner.invoke(
        app, ["score", str(tracks), "--gt", str(TUD / "gt.txt"), "--out", str(out)]
    )
    assert result.exit_code == 0, result.output
    return out


def _track_id(row: str) -> int:
    return int(row.split(",")[1])


def test_significance_tells_a_real_change_from_noise(tmp_path: Path) -> None:
    base = _scored(tmp_path, "base")
    # Track 4's last row gone: one miss more, MOTA 0.28 pp lower, in one frame of 71.
    one = _scored(tmp_path, "one", lambda r: not r.startswith("37,4,"))
    # Tracks 3 and 6 gone: misses in many frames.
    many = _scored(tmp_path, "many", lambda r: _track_id(r) not in (3, 6))
    strict = ["--tolerance", "mota=0"]
    result = runner.invoke(app, ["compare", str(base), str(one), *strict])
    assert result.exit_code == 1 and "TUD-Campus/mota" in result.stderr  # beyond tolerance 0
    result = runner.invoke(app, ["compare", str(base), str(one), *strict, "--significance"])
    assert result.exit_code == 0, result.output  # within the noise of its frames
    assert "(noise)" in result.stdout
    result = runner.invoke(app, ["compare", str(base), str(many), "--significance"])
    assert result.exit_code == 1 and "regression(s) beyond noise" in result.stderr
    assert "(beyond noise)" in result.stdout


def test_reports_without_frame_tables_compare_on_the_tolerance(tmp_path: Path) -> None:
    base = _scored(tmp_path, "base")
    cur = _scored(tmp_path, "cur", lambda r: _track_id(r) not in (3, 6))
    (cur / "TUD-Campus.frames.npz").unlink()
    result = runner.invoke(app, ["compare", str(base), str(cur), "--significance"])
    # MOTA falls by more than its 1 pp tolerance: a regression, gated as without intervals.
    assert result.exit_code == 1 and "TUD-Campus/mota" in result.stderr
    assert "no intervals (current report without its TUD-Campus.frames.npz)" in result.stdout
    # A report from before the tables (no frames_file key) compares the same way.
    report_json = cur / "report.json"
    data = json.loads(report_json.read_text())
    del data["sequences"][0]["frames_file"]
    old = tmp_path / "old.json"
    old.write_text(json.dumps(data))
    result = runner.invoke(app, ["compare", str(base), str(old), "--significance"])
    assert result.exit_code == 1 and "no intervals" in result.stdout
    # One line on stderr: the error (the note on the gate is with the table).
    assert result.stderr.count("\n") == 1


def test_a_frame_table_that_changed_is_refused(tmp_path: Path) -> None:
    base = _scored(tmp_path, "base")
    cur = _scored(tmp_path, "cur")
    table = cur / "TUD-Campus.frames.npz"
    table.write_bytes(table.read_bytes() + b"\0")
    result = runner.invoke(app, ["compare", str(base), str(cur)])
    assert result.exit_code == 2 and "changed since the report was written" in result.stderr
