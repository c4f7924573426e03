"""The five methods give the same outputs as before the package layout change (issue 29).

Short synthetic recordings (40 frames) are rendered with ``synth``, then ``run`` scores each
method on its kind of recording, ``score`` re-scores basso2012's tracks and ``sweep`` runs two
points of basso2012. The expected values in ``tests/data/layout_golden.json`` were written
before any module moved: recordings by sha256, counts exactly, every other number (metrics,
detection and track positions) to 1e-9. Timings, paths and the machine are left out.

Regenerate only when behaviour is meant to change (and say so in the commit)::

    PYTHONPATH=src python -m tests.test_layout_golden --write
"""

from __future__ import annotations

import csv
import hashlib
import json
import math
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from rgbd_eval.cli.main import app

ROOT = Path(__file__).resolve().parents[1]
EXPECTED = Path(__file__).resolve().parent / "data" / "layout_golden.json"
SCENARIOS = ROOT / "configs" / "scenarios"
FRAMES = 40
#: Recording name -> synth arguments (scenario, extra options).
RECORDINGS: dict[str, tuple[str, tuple[str, ...]]] = {
    "demo40": ("demo", ()),
    "stereo40": ("moving_complex", ("--rig", "stereo")),
    # thermal_crossings has nobody in view in its first 40 frames; the corridor has.
    "corridor40": (str(SCENARIOS / "cielniak2010" / "thermal_corridor.yaml"), ()),
    "scene1_40": (str(SCENARIOS / "dmtbs" / "scene1.yaml"), ()),
}
#: Method -> the recording it runs on.
RUNS = {
    "basso2012": "demo40",
    "pinto2022": "demo40",
    "satake2009": "stereo40",
    "cielniak2010": "corridor40",
    "dmtbs": "scene1_40",
}
TOLERANCE = 1e-9
#: What is kept of each sequence of a report (not timings, paths or the machine).
KEPT = ("name", "frames", "scored", "counts", "metrics", "detections")
#: What is kept of the overall row (issue 33's breakdowns, intervals and gaps are tested
#: on their own, tests/metrics/test_metrics_breakdowns.py and test_metrics_bootstrap.py).
OVERALL_KEPT = ("counts", "metrics")


def _invoke(args: list[str]) -> str:
    result = CliRunner().invoke(app, args)
    if result.exit_code != 0:
        raise AssertionError(
            f"rgbd-eval {' '.join(args)}: exit {result.exit_code}\n{result.output}"
        )
    return result.output


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _rows(path: Path, columns: Sequence[str]) -> list[list[float]]:
    with path.open(newline="") as f:
        return [[float(row[c]) for c in columns] for row in csv.DictReader(f)]


def _scores(report: Mapping[str, Any]) -> dict[str, Any]:
    """Counts and metrics of each sequence and overall, the config and the detection counts."""
    return {
        "config": report["config"],
        "sequences": [{k: s[k] for k in KEPT if k in s} for s in report["sequences"]],
        "overall": {k: report["overall"][k] for k in OVERALL_KEPT},
    }


def measure(work: Path) -> dict[str, Any]:
    """Render the recordings, run every method, score and sweep; the numbers to compare."""
    out: dict[str, Any] = {"recordings": {}, "runs": {}}
    for name, (scenario, extra) in RECORDINGS.items():
        rec = work / f"{name}.mcap"
        _invoke(["synth", scenario, "--frames", str(FRAMES), "-o", str(rec), *extra])
        gt = rec.with_name(f"{name}.gt.csv")
        out["recordings"][name] = {"mcap": _sha256(rec), "gt": _sha256(gt)}
    for method, name in RUNS.items():
        folder = work / method
        rec = work / f"{name}.mcap"
        _invoke(["run", str(rec), "--method", method, "--out", str(folder)])
        report = json.loads((folder / "report.json").read_text())
        out["runs"][method] = {
            **_scores(report),
            "detections": _rows(
                folder / f"{name}.detections.csv",
                ("frame", "x", "y", "z", "height", "confidence"),
            ),
            "tracks": _rows(
                folder / f"{name}.tracks.csv", ("frame", "id", "x", "y", "z", "height")
            ),
        }
    tracks = work / "basso2012" / "demo40.tracks.csv"
    gt = work / "demo40.gt.csv"
    _invoke(["score", str(tracks), "--gt", str(gt), "--out", str(work / "score")])
    out["score"] = _scores(json.loads((work / "score" / "report.json").read_text()))
    sweep = work / "sweep"
    _invoke(
        [
            "sweep",
            "tracker.min_confidence",
            "-1",
            "0",
            "--dataset",
            str(work / "demo40.mcap"),
            "--cluster",
            "local:1",
            "--cache",
            str(work / "cache"),
            "--out",
            str(sweep),
        ]
    )
    records = json.loads((sweep / "sweep.json").read_text())["records"]
    out["sweep"] = [{k: v for k, v in r.items() if k != "seconds"} for r in records]
    return out


def differences(expected: Any, actual: Any, where: str = "") -> list[str]:
    """Where ``actual`` differs from ``expected``: ints, strings exactly, floats to 1e-9."""
    if isinstance(expected, dict) and isinstance(actual, dict):
        if expected.keys() != actual.keys():
            return [f"{where}: keys {sorted(expected)} != {sorted(actual)}"]
        return [d for k in expected for d in differences(expected[k], actual[k], f"{where}.{k}")]
    if isinstance(expected, list) and isinstance(actual, list):
        if len(expected) != len(actual):
            return [f"{where}: {len(expected)} items expected, got {len(actual)}"]
        return [
            d
            for i, (e, a) in enumerate(zip(expected, actual, strict=True))
            for d in differences(e, a, f"{where}[{i}]")
        ]
    if (
        isinstance(expected, float)
        and isinstance(actual, float | int)
        and not isinstance(actual, bool)
    ):
        if math.isnan(expected) and math.isnan(actual):
            return []
        if abs(expected - actual) <= TOLERANCE:
            return []
    elif type(expected) is type(actual) and expected == actual:
        return []
    return [f"{where}: expected {expected!r}, got {actual!r}"]


@pytest.mark.slow
def test_outputs_match_the_golden_values(tmp_path: Path) -> None:
    expected = json.loads(EXPECTED.read_text())
    found = differences(expected, measure(tmp_path))
    assert not found, "\n".join(found[:40])


def test_differences_compares_floats_to_a_tolerance() -> None:
    assert differences({"a": [1, 0.5, "x"]}, {"a": [1, 0.5 + 1e-12, "x"]}) == []
    assert differences({"a": 1}, {"a": 2}) == [".a: expected 1, got 2"]
    assert differences([0.5], [0.5 + 1e-6]) == ["[0]: expected 0.5, got 0.500001"]
    assert differences({"n": 3}, {"n": 3.0}) == [".n: expected 3, got 3.0"]


if __name__ == "__main__" and sys.argv[1:] == ["--write"]:
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        values = measure(Path(tmp))
    EXPECTED.parent.mkdir(exist_ok=True)
    EXPECTED.write_text(json.dumps(values, indent=None, separators=(",", ":")) + "\n")
    print(f"wrote {EXPECTED}")
