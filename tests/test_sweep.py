"""Sweeps: grid expansion and validation, the detection cache, equality with separate runs."""

from __future__ import annotations

from pathlib import Path

import pytest

from rgbd_eval.cache import DetectionCache, detection_key
from rgbd_eval.config import build_config, load_config
from rgbd_eval.errors import ConfigError
from rgbd_eval.files import file_digest
from rgbd_eval.pipeline import run_sequence
from rgbd_eval.sweep import SweepParam, expand_grid, parse_param, point_configs, run_sweep
from tests.io.conftest import Spec, write_recording


def test_grid_expansion_order_and_parsing() -> None:
    p = parse_param("tracker.min_confidence=-1,-0.5")
    assert p == SweepParam("tracker.min_confidence", (-1, -0.5))
    grid = expand_grid([p, SweepParam("tracker.classifier", (True, False))])
    # First parameter slowest: 2 x 2 points.
    assert grid == [
        {"tracker.min_confidence": -1, "tracker.classifier": True},
        {"tracker.min_confidence": -1, "tracker.classifier": False},
        {"tracker.min_confidence": -0.5, "tracker.classifier": True},
        {"tracker.min_confidence": -0.5, "tracker.classifier": False},
    ]
    with pytest.raises(ConfigError, match="swept twice"):
        expand_grid([p, p])
    with pytest.raises(ConfigError, match="expected NAME=V1,V2"):
        parse_param("tracker.min_confidence")


def test_every_point_is_validated_before_running() -> None:
    base = load_config(method="basso2012").model_dump(mode="json")
    grid = expand_grid([SweepParam("tracker.selectors", (10, 400))])
    with pytest.raises(
        ConfigError, match=r"sweep point tracker.selectors=400.*selectors=400 must not exceed"
    ):
        point_configs(base, [], grid)
    with pytest.raises(ConfigError, match="unknown key 'nope'"):
        point_configs(base, [], expand_grid([SweepParam("tracker.nope", (1,))]))


def test_cache_hit_and_invalidation(tmp_path: Path) -> None:
    rec = write_recording(tmp_path / "a.mcap", "mcap", Spec(n=4))
    cache = tmp_path / "cache"
    base = load_config(method="basso2012").model_dump(mode="json")
    grid = expand_grid([SweepParam("tracker.min_confidence", (-1.0, 0.0))])
    configs = point_configs(base, [], grid)
    first = run_sweep([rec], grid, configs, cache_root=cache)
    # Two tracker values share one detector config: one detection pass, a miss.
    assert (first.cache_hits, first.cache_misses) == (0, 1)
    second = run_sweep([rec], grid, configs, cache_root=cache)
    assert (second.cache_hits, second.cache_misses) == (1, 0)
    assert [r.counts for r in second.records] == [r.counts for r in first.records]
    # A detector change or a different recording is a different key.
    digest = file_digest(rec)
    other_detector = build_config(base, [("detector.voxel_size", 0.08)])
    assert detection_key(digest, other_detector) != detection_key(digest, configs[0])
    rec2 = write_recording(tmp_path / "b.mcap", "mcap", Spec(n=5))
    assert detection_key(file_digest(rec2), configs[0]) != detection_key(digest, configs[0])
    assert DetectionCache(cache).load(detection_key(file_digest(rec2), configs[0])) is None


def test_sweep_points_equal_separate_runs(tmp_path: Path) -> None:
    rec = write_recording(tmp_path / "a.mcap", "mcap", Spec(n=6))
    base = load_config(method="basso2012").model_dump(mode="json")
    grid = expand_grid([SweepParam("tracker.min_confidence", (-1.0, 0.5))])
    configs = point_configs(base, [], grid)
    result = run_sweep([rec], grid, configs, cache_root=tmp_path / "cache")
    for record, config in zip(result.records, configs, strict=True):
        single = run_sequence(rec, config)
        assert single.scores is not None
        assert record.counts == single.scores.counts


def test_cli_takes_negative_values_as_values(tmp_path: Path) -> None:
    # The README's `sweep tracker.min_confidence -3 -2.5 ...` once failed: "No such option: -3".
    import json

    from typer.testing import CliRunner

    from rgbd_eval.cli.main import app

    rec = write_recording(tmp_path / "a.mcap", "mcap", Spec(n=4))
    args = ["sweep", "tracker.min_confidence", "-3", "-2.5", "0.5", "--dataset", str(rec)]
    args += ["--cache", str(tmp_path / "cache"), "--out", str(tmp_path / "out")]
    args += ["--cluster", "local:1"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    records = json.loads((tmp_path / "out" / "sweep.json").read_text())["records"]
    assert [r["tracker.min_confidence"] for r in records] == [-3.0, -2.5, 0.5]


def test_cli_sweeps_a_null_value(tmp_path: Path) -> None:
    # `sweep tracker.static_devalidation_s null 2.0` (off, then on) once crashed drawing
    # sweep.png: float(None). Non-numeric values are plotted at evenly spaced positions.
    import json

    from typer.testing import CliRunner

    from rgbd_eval.cli.main import app

    rec = write_recording(tmp_path / "a.mcap", "mcap", Spec(n=4))
    args = ["sweep", "tracker.static_devalidation_s", "null", "2.0", "--dataset", str(rec)]
    args += ["--cache", str(tmp_path / "cache"), "--out", str(tmp_path / "out")]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    records = json.loads((tmp_path / "out" / "sweep.json").read_text())["records"]
    assert [r["tracker.static_devalidation_s"] for r in records] == [None, 2.0]
    assert (tmp_path / "out" / "sweep.png").stat().st_size > 0


def test_cli_refuses_a_cache_folder_that_is_a_file_and_a_bad_cluster(tmp_path: Path) -> None:
    from typer.testing import CliRunner

    from rgbd_eval.cli.main import app

    rec = write_recording(tmp_path / "a.mcap", "mcap", Spec(n=2))
    (tmp_path / "cache").write_text("a file")
    args = [
        "sweep",
        "tracker.min_confidence",
        "0",
        "--dataset",
        str(rec),
        "--out",
        str(tmp_path / "o"),
    ]
    result = CliRunner().invoke(app, [*args, "--cache", str(tmp_path / "cache")])
    assert result.exit_code == 7
    assert result.output.strip().splitlines() == [
        f"error: {tmp_path / 'cache'}: is a file, not a detection cache folder"
    ]
    result = CliRunner().invoke(app, [*args, "--cluster", "local:0"])
    assert (result.exit_code, result.output.strip()) == (
        4,
        "error: --cluster 'local:0': N in local:N must be at least 1",
    )
    # The hidden --jobs N of old scripts is --cluster local:N; not both.
    result = CliRunner().invoke(app, [*args, "--jobs", "2", "--cluster", "tcp://h:1"])
    assert result.exit_code == 4 and "--jobs and --cluster: give one" in result.output
    result = CliRunner().invoke(app, [*args, "--cache-mode", "nfs"])
    assert result.exit_code == 4 and "expected shared or client" in result.output
    assert not (tmp_path / "o").exists()


def test_a_grid_is_bounded_before_it_is_built() -> None:
    params = [SweepParam("tracker.min_confidence", tuple(range(1000))) for _ in range(2)]
    params[1] = SweepParam("tracker.acceleration_variance", tuple(range(1, 1001)))
    with pytest.raises(ConfigError, match=r"the grid has 1000000 points \(1000 tracker"):
        expand_grid(params)
