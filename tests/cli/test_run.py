"""`rgbd-eval run` on small recordings: outputs, scoring paths, errors and exit codes."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from rgbd_eval.cli.main import app
from rgbd_eval.io.groundtruth import write_csv
from rgbd_eval.types import Box2D, GroundTruthObject
from tests.fuzz.cli import run_cli
from tests.io.conftest import PERIOD, T0, Spec, write_recording

runner = CliRunner()


def test_unscored_run_writes_outputs(tmp_path: Path) -> None:
    rec = write_recording(tmp_path / "nogt.mcap", "mcap", Spec(n=4, ground_truth=False))
    out = tmp_path / "out"
    result = runner.invoke(app, ["run", str(rec), "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert "no ground truth found, nothing scored" in result.output
    report = json.loads((out / "report.json").read_text())
    assert report["schema_version"] == 1 and report["overall"] is None
    seq = report["sequences"][0]
    assert seq["scored"] is False and seq["frames"] == 4 and len(seq["sha256"]) == 64
    assert report["config"]["tracker"]["min_confidence"] == -0.5
    for name in ("nogt.tracks.csv", "nogt.detections.csv", "nogt.birdseye.png", "report.md"):
        assert (out / name).stat().st_size > 0
    assert (
        (out / "nogt.tracks.csv")
        .read_text()
        .startswith("frame,id,bb_left,bb_top,bb_width,bb_height,conf,x,y,z")
    )


def test_scored_run_counts_every_ground_truth_instance(tmp_path: Path) -> None:
    rec = write_recording(tmp_path / "withgt.mcap", "mcap", Spec(n=5))
    out = tmp_path / "out"
    result = runner.invoke(app, ["run", str(rec), "--out", str(out), "--json"])
    assert result.exit_code == 0, result.output
    report = json.loads(result.output)
    counts = report["sequences"][0]["counts"]
    # One annotated person in each of the 5 frames: every instance is a match or a miss.
    assert counts["num_gt"] == 5
    assert counts["num_matches"] + counts["fn"] == 5
    assert report["overall"]["counts"] == counts
    # report.md: FP and FN with their counts, PT beside MT and ML.
    md = (out / "report.md").read_text()
    metrics = report["sequences"][0]["metrics"]
    fp_fn = f"| {100 * metrics['fp_rate']:.1f}% ({counts['fp']}) | {100 * metrics['fn_rate']:.1f}% ({counts['fn']}) |"
    assert fp_fn in md
    assert "| MT | PT | ML |" in md


def test_gating_needs_matching_ground_truth(tmp_path: Path) -> None:
    rec = write_recording(tmp_path / "boxes.mcap", "mcap", Spec(n=3, ground_truth=False))
    gt = tmp_path / "boxes_only.csv"
    write_csv(
        gt, [GroundTruthObject(i, T0 + i * PERIOD, 1, Box2D(1, 1, 5, 20), None) for i in range(3)]
    )
    out = tmp_path / "out"
    result = runner.invoke(
        app, ["run", str(rec), "--gt", str(gt), "--gating", "metric", "--out", str(out)]
    )
    assert result.exit_code == 6, result.output
    assert "'metric' gating needs world positions" in result.output
    assert not out.exists()  # a failed run leaves no report behind


def test_bad_ground_truth_and_bad_config(tmp_path: Path) -> None:
    rec = write_recording(tmp_path / "r.mcap", "mcap", Spec(n=2, ground_truth=False))
    bad = tmp_path / "bad.csv"
    bad.write_text("frame,id\n")
    result = runner.invoke(app, ["run", str(rec), "--gt", str(bad), "--out", str(tmp_path / "o")])
    assert result.exit_code == 5 and "missing columns" in result.output
    result = runner.invoke(
        app, ["run", str(rec), "--set", "tracker.nope=1", "--out", str(tmp_path / "o")]
    )
    assert result.exit_code == 4 and "unknown key 'nope'" in result.output
    result = runner.invoke(app, ["run", str(rec), "--gating", "both", "--out", str(tmp_path / "o")])
    assert result.exit_code == 4 and "evaluation.gating" in result.output
    assert not (tmp_path / "o").exists()


def test_folder_of_recordings_gives_overall_row(tmp_path: Path) -> None:
    data = tmp_path / "data"
    write_recording(data / "a.mcap", "mcap", Spec(n=2))
    write_recording(data / "b.bag", "ros1", Spec(n=3))
    out = tmp_path / "out"
    result = runner.invoke(app, ["run", str(data), "--out", str(out), "--cluster", "local:1"])
    assert result.exit_code == 0, result.output
    report = json.loads((out / "report.json").read_text())
    assert [s["name"] for s in report["sequences"]] == ["a", "b"]
    # Overall counts are sums, never averages of ratios.
    assert report["overall"]["counts"]["num_gt"] == 5
    assert "overall" in (out / "report.md").read_text()


def test_topic_option_chooses_streams_on_run_bench_and_sweep(tmp_path: Path) -> None:
    rec = write_recording(tmp_path / "topics.mcap", "mcap", Spec(n=3))
    wrong = "colour=/camera/depth/image_raw"  # a depth topic is no colour image
    for args in (
        ["run", str(rec), "--out", str(tmp_path / "o")],
        ["bench", str(rec), "--repeat", "1", "--all-cores"],
        ["sweep", "tracker.min_confidence", "0", "--dataset", str(rec), "--cluster", "local:1"],
    ):
        result = runner.invoke(app, [*args, "--topic", wrong])
        assert result.exit_code == 3, (args[0], result.output)
        assert "--topic colour=/camera/depth/image_raw: not a colour image topic" in result.output
    ok = runner.invoke(
        app,
        [
            "run",
            str(rec),
            "--out",
            str(tmp_path / "ok"),
            "--topic",
            "colour=/camera/rgb/image_color",
        ],
    )
    assert ok.exit_code == 0, ok.output
    assert not (tmp_path / "o").exists()


def test_gating_option_takes_its_own_threshold(tmp_path: Path) -> None:
    """Issue 28: pinto2022's metric 1.0 m was kept as an IoU threshold (nothing matched)."""
    rec = write_recording(tmp_path / "r.mcap", "mcap", Spec(n=3))
    runs = {
        "iou": ["--gating", "iou"],
        "iou_0.3": ["--gating", "iou", "--threshold", "0.3"],
        "metric": ["--gating", "metric"],
    }
    thresholds = {}
    for name, options in runs.items():
        out = tmp_path / name
        args = ["run", str(rec), "--method", "pinto2022", *options, "--out", str(out)]
        result = runner.invoke(app, args)
        assert result.exit_code == 0, result.output
        report = json.loads((out / "report.json").read_text())
        thresholds[name] = report["evaluation"]["threshold"]
    assert thresholds == {"iou": 0.5, "iou_0.3": 0.3, "metric": 1.0}


def test_threshold_outside_its_gating_range_is_a_usage_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rec = write_recording(tmp_path / "r.mcap", "mcap", Spec(n=2, ground_truth=False))
    for options, problem in (
        (["--threshold", "1.5"], "IoU threshold=1.5 must be in (0, 1]"),
        (["--gating", "metric", "--threshold", "inf"], "metric threshold=inf must be a finite"),
        (["--method", "pinto2022", "--threshold", "-1"], "metric threshold=-1.0 must be"),
        (["--gating", "iou", "--threshold", "nan"], "IoU threshold=nan must be in"),
    ):
        out = tmp_path / "o"
        outcome = run_cli(["run", str(rec), *options, "--out", str(out)], capsys)
        assert outcome.code == 2, outcome
        (line,) = outcome.error_lines
        assert line.startswith("error: Invalid value for '--threshold': "), line
        assert problem in line and line.endswith("run --help)"), line
        assert not out.exists()


def test_dmtbs_on_a_recording_shorter_than_its_background_initialisation_says_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Issue 28: 5 frames, all spent on the 30-frame background initialisation, found nothing."""
    rec = write_recording(tmp_path / "short.mcap", "mcap", Spec(n=5))
    out = tmp_path / "out"
    outcome = run_cli(["run", str(rec), "--method", "dmtbs", "--out", str(out), "--json"], capsys)
    assert outcome.code == 0, outcome
    expected = "spends all 5 frames of the recording on its background initialisation"
    assert any(
        line.startswith("warning: short: ") and expected in line for line in outcome.error_lines
    ), outcome.stderr
    (seq,) = json.loads((out / "report.json").read_text())["sequences"]
    assert any(expected in w for w in seq["warnings"]), seq["warnings"]
    # Shorter initialisation, no warning.
    out2 = tmp_path / "out2"
    args = ["run", str(rec), "--method", "dmtbs", "--set", "detector.init_frames=2"]
    outcome = run_cli([*args, "--out", str(out2)], capsys)
    assert outcome.code == 0 and "initialisation" not in outcome.stderr + outcome.stdout
    (seq,) = json.loads((out2 / "report.json").read_text())["sequences"]
    assert not any("initialisation" in w for w in seq["warnings"])
