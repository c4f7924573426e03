"""The benchmark on a tiny synthesized recording: structure and sanity, never timing thresholds."""

from __future__ import annotations

import dataclasses
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest
import typer
from typer.testing import CliRunner

from rgbd_eval.bench import LATE_STAGES, READ_STAGES, SCHEMA_VERSION, BenchResult, benchmark
from rgbd_eval.cli.bench_cmd import bench
from rgbd_eval.config import load_config
from rgbd_eval.datasets import scenarios_dir
from rgbd_eval.errors import ConfigError, InputError
from rgbd_eval.methods.basso2012.detector import STAGES
from rgbd_eval.sim import load_scenario, synthesize

FRAMES = 10
runner = CliRunner()


def _app() -> typer.Typer:
    """The command alone, as ``rgbd-eval`` registers it."""
    app = typer.Typer(pretty_exceptions_enable=False)
    app.command("bench")(bench)

    @app.callback()
    def _root() -> None:
        """Keep ``bench`` a subcommand."""

    return app


@pytest.fixture(scope="module")
def recording(tmp_path_factory: pytest.TempPathFactory) -> Path:
    scenario = load_scenario(scenarios_dir() / "demo.yaml")
    out = tmp_path_factory.mktemp("bench") / "tiny.mcap"
    return synthesize(scenario, out, max_frames=FRAMES).recording


@pytest.fixture(scope="module")
def result(recording: Path) -> BenchResult:
    return benchmark(recording, load_config(method="basso2012"), repeats=2)


def test_every_stage_is_present_and_non_negative(result: BenchResult) -> None:
    expected = [*READ_STAGES, *STAGES, "detections", "track", *LATE_STAGES]
    assert list(result.stage_ms) == expected
    assert all(ms >= 0.0 and math.isfinite(ms) for ms in result.stage_ms.values())
    assert result.frames == FRAMES and result.repeats == 2
    assert len(result.total_ms_repeats) == len(result.floor_ms_repeats) == 2
    assert result.rgb_size == (640, 480) and result.depth_size == (160, 120)
    assert result.scored  # the synthesizer writes a ground-truth sidecar


def test_fps_and_ratio_follow_from_the_totals(result: BenchResult) -> None:
    assert result.total_ms > 0.0 and result.floor_ms > 0.0
    assert result.fps == pytest.approx(1e3 / result.total_ms)
    assert result.floor_fps == pytest.approx(1e3 / result.floor_ms)
    assert result.ratio == pytest.approx(result.total_ms / result.floor_ms)
    assert result.stage_fps("track") == pytest.approx(1e3 / result.stage_ms["track"])
    # each repeat's stages sum to its wall time; the median of two is their mean, so the
    # stage medians add up to the median total
    assert sum(result.stage_ms.values()) == pytest.approx(result.total_ms, rel=1e-6)
    assert result.peak_rss_mib > 0.0


def test_cpu_time_is_measured_per_repeat(result: BenchResult) -> None:
    assert len(result.cpu_ms_repeats) == 2 and all(ms > 0.0 for ms in result.cpu_ms_repeats)
    assert result.cpu_fps == pytest.approx(1e3 / result.cpu_ms)
    assert result.to_json()["cpu_ms"] == pytest.approx(result.cpu_ms)


def test_cpu_figures_are_the_median_repeat(result: BenchResult) -> None:
    timed = dataclasses.replace(result, cpu_ms_repeats=(20.0, 30.0, 25.0))
    # median of 20, 30, 25 ms is 25 ms -> 1000 / 25 = 40 fps
    assert timed.cpu_ms == 25.0 and timed.cpu_fps == pytest.approx(40.0)
    # not measured (a result built without it): 0 ms, and JSON says so with null
    untimed = dataclasses.replace(result, cpu_ms_repeats=())
    assert untimed.cpu_ms == 0.0 and untimed.to_json()["cpu_fps"] is None


def test_one_repeat_stages_sum_to_the_wall_time(recording: Path) -> None:
    one = benchmark(recording, load_config(method="basso2012"), repeats=1)
    assert sum(one.stage_ms.values()) == pytest.approx(one.total_ms, rel=1e-9)
    assert one.total_ms_repeats == (one.total_ms,)


def test_json_is_versioned_and_complete(result: BenchResult) -> None:
    data = json.loads(json.dumps(result.to_json()))
    assert data["schema_version"] == SCHEMA_VERSION
    assert data["fps"] == pytest.approx(result.fps)
    assert data["stage_ms"] == result.stage_ms
    for key in ("floor_fps", "ratio", "raw_ms", "peak_rss_mib", "frames", "method"):
        assert key in data


def test_bad_arguments_raise_package_errors(recording: Path, tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="repeat=0"):
        benchmark(recording, load_config(method="basso2012"), repeats=0)
    with pytest.raises(InputError):
        benchmark(tmp_path / "missing.mcap", load_config(method="basso2012"), repeats=1)


def test_cli_json_and_table(recording: Path) -> None:
    out = runner.invoke(_app(), ["bench", str(recording), "--repeat", "1", "--json", "--all-cores"])
    assert out.exit_code == 0, out.output
    data = json.loads(out.output)
    assert data["schema_version"] == SCHEMA_VERSION and data["frames"] == FRAMES
    assert data["repeats"] == 1
    table = runner.invoke(
        _app(),
        [
            "bench",
            str(recording),
            "--repeat",
            "1",
            "--all-cores",
            "--set",
            "tracker.classifier=false",
        ],
    )
    assert table.exit_code == 0, table.output
    for label in (
        "sub-clustering",
        "HOG",
        "tracking",
        "pipeline",
        "decode alone",
        "pipeline/floor",
        "tracking alone",
        "pipeline, CPU time",
        "CPU time / wall time",
    ):
        assert label in table.output


def test_tracking_alone_is_timed(result: BenchResult) -> None:
    assert result.track_alone_ms > 0.0
    assert result.track_alone_fps == pytest.approx(1e3 / result.track_alone_ms)
    assert result.to_json()["track_alone_fps"] == pytest.approx(result.track_alone_fps)


def test_cli_pins_itself_to_one_cpu(recording: Path) -> None:
    # In a child process: pinning the test process would slow the rest of the suite.
    if not hasattr(os, "sched_setaffinity"):
        pytest.skip("CPU affinity is not available on this platform")
    out = subprocess.run(
        [sys.executable, "-m", "rgbd_eval", "bench", str(recording), "--repeat", "1", "--json"],
        capture_output=True,
        text=True,
        check=True,
    )
    assert len(json.loads(out.stdout)["cpus"]) == 1


def test_cli_errors_are_one_line_with_exit_codes(recording: Path, tmp_path: Path) -> None:
    missing = runner.invoke(_app(), ["bench", str(tmp_path / "nope.mcap")])
    assert missing.exit_code == 3
    assert missing.output.startswith("error:") and "Traceback" not in missing.output
    bad_key = runner.invoke(_app(), ["bench", str(recording), "--set", "tracker.nope=1"])
    assert bad_key.exit_code == 4 and bad_key.output.startswith("error:")
    bad_repeat = runner.invoke(_app(), ["bench", str(recording), "--repeat", "0"])
    assert bad_repeat.exit_code == 4 and "repeat=0" in bad_repeat.output
