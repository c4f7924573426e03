"""Fixtures: one real run (with --video) on a short synthetic recording, and every page on disk."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest
from typer.testing import CliRunner

from rgbd_eval.bench import BenchResult
from rgbd_eval.cli.bench_cmd import STAGE_LABELS
from rgbd_eval.cli.main import app
from rgbd_eval.compare import compare_reports
from rgbd_eval.config import Gating, load_config
from rgbd_eval.datasets import scenarios_dir
from rgbd_eval.files import file_digest
from rgbd_eval.methods.basso2012.experiments import Claim, Reproduction, to_json
from rgbd_eval.metrics import Counts
from rgbd_eval.pipeline import run_sequence
from rgbd_eval.plugins import ReproduceResult
from rgbd_eval.report.html.pages import (
    bench_page,
    compare_page,
    reproduce_page,
    write_run_html,
    write_sweep_html,
)
from rgbd_eval.report.run import report_dict
from rgbd_eval.sim import load_scenario, synthesize
from rgbd_eval.sweep import SweepRecord, SweepResult

#: Frames of the synthetic recording: enough for people to be detected, tracked and missed.
FRAMES = 24


@pytest.fixture(scope="session")
def recording(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The first frames of the demo scenario (three people), with its ground-truth sidecar."""
    out = tmp_path_factory.mktemp("html_rec") / "short.mcap"
    return synthesize(
        load_scenario(scenarios_dir() / "demo.yaml"), out, max_frames=FRAMES
    ).recording


@pytest.fixture(scope="session")
def run_dir(recording: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``rgbd-eval run --video`` on the short recording."""
    out = tmp_path_factory.mktemp("html_run") / "run"
    result = CliRunner().invoke(app, ["run", str(recording), "--out", str(out), "--video"])
    assert result.exit_code == 0, result.output
    return out


@pytest.fixture(scope="session")
def unscored_dir(recording: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The outputs of a run without ground truth: the short recording's, its ground truth dropped."""
    config = load_config(method="basso2012")
    result = replace(run_sequence(recording, config), ground_truth=None, scores=None)
    out = tmp_path_factory.mktemp("html_unscored")
    write_run_html(out, [result], config, report_dict([result], config, [file_digest(recording)]))
    return out


@pytest.fixture(scope="session")
def score_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``rgbd-eval score`` of MOTChallenge files: person 1 tracked, then lost, then an id switch."""
    folder = tmp_path_factory.mktemp("html_score")
    # frame,id,x,y,w,h,consider,class,visibility: person 1 in frames 1-4.
    (folder / "gt.txt").write_text("".join(f"{f},1,0,0,10,10,1,1,1.0\n" for f in range(1, 5)))
    # frame,id,x,y,w,h,...: track 7 on it in frames 1-2, nothing in 3 (a miss), track 8 in 4
    # (an id switch); track 9 far away in frame 1 (a false positive).
    rows = ["1,7,0,0,10,10", "1,9,50,50,10,10", "2,7,0,0,10,10", "4,8,0,0,10,10"]
    (folder / "tracks.txt").write_text("".join(r + ",-1,-1,-1,-1\n" for r in rows))
    out = folder / "out"
    args = ["score", str(folder / "tracks.txt"), "--gt", str(folder / "gt.txt"), "--out", str(out)]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    return out


def counts(fp: int, fn: int, id_switches: int, matches: int = 90) -> Counts:
    """Consistent counts of a 100-instance, 50-frame sequence: matches + fn = 100 ground truth."""
    return Counts(
        gating=Gating.IOU,
        threshold=0.5,
        num_frames=50,
        num_gt=matches + fn,
        num_tracks=matches + fp,
        num_matches=matches,
        fp=fp,
        fn=fn,
        id_switches=id_switches,
        similarity_sum=0.8 * matches,
        num_gt_tracks=2,
        mostly_tracked=2,
        main_tr_matches=matches - id_switches,
        idtp=matches - id_switches,
        idfp=fp + id_switches,
        idfn=fn + id_switches,
    )


def sweep_result() -> SweepResult:
    """A 3 x 2 grid over one sequence (min_confidence x classifier), counts made up but consistent."""
    grid = [
        {"tracker.min_confidence": c, "tracker.classifier": k}
        for c in (-1.0, -0.5, 0.0)
        for k in (True, False)
    ]
    made = {(-1.0, True): (12, 8, 2), (-1.0, False): (15, 8, 4), (-0.5, True): (5, 10, 1)}
    made |= {(-0.5, False): (6, 10, 3), (0.0, True): (3, 14, 1), (0.0, False): (3, 15, 2)}
    records = tuple(
        SweepRecord(
            p,
            "short",
            counts(*made[p["tracker.min_confidence"], p["tracker.classifier"]]),
            0.1,
        )
        for p in grid
    )
    return SweepResult(tuple(grid[0]), tuple(grid), records, 1.0, 1.0, 0, 1)


def reproduction() -> ReproduceResult:
    """basso2012's result with Tables 7.2 and 7.6 (three thresholds), Figures 7.7 and 7.9, two claims."""
    res = Reproduction(seconds=12.0)
    summary = {"motp": 0.8, "mota": 0.85, "fp_rate": 0.05, "fn_rate": 0.1, "id_switches": 2}
    summary |= {"main_tr": 0.7, "all_tr": 0.9}
    res.tables["7.2"] = {"static_simple": summary, "static_complex": {**summary, "mota": 0.8}}
    res.tables["7.6"] = {
        "0.5": {**summary, "fn_rate": 0.2, "mota": 0.75},
        "-0.5": summary,
        "-1.0": {**summary, "fp_rate": 0.08},
    }
    res.track_lengths = {"static_simple": {0.0: [40, 20, 10, 5], 3.0: [60, 30], 30.0: [80, 40]}}
    res.voxel_timing = {
        v: {"read": 2.0, "voxel": 3.0, "clustering": 10.0 * v / 0.06, "total_detect": 20.0}
        for v in (0.04, 0.06, 0.1)
    }
    res.claims = [
        Claim("7.3, Table 7.6", "FN rise for thresholds above -0.5", True, "FN 10% -> 20%"),
        Claim("7.1, Figure 7.7", "fewer tracks with memory", False, "4 vs 2"),
    ]
    claims = tuple((c.text, c.held) for c in res.claims)
    return ReproduceResult(markdown="", data=to_json(res), claims=claims)


def bench_result() -> BenchResult:
    stage_ms = {"index": 1.0, "decode": 6.0, "voxel": 2.5, "hog": 6.0, "track": 3.0}
    stage_ms |= {"score": 2.0, "other": 0.5}
    return BenchResult(
        schema_version=2,
        path="short.mcap",
        method="basso2012",
        frames=24,
        repeats=1,
        rgb_size=(640, 480),
        depth_size=(160, 120),
        detections_per_frame=3.0,
        tracks_per_frame=3.0,
        scored=True,
        stage_ms=stage_ms,
        total_ms_repeats=(21.0,),
        floor_ms_repeats=(7.0,),
        raw_ms=1.0,
        raw_reader="mcap",
        track_alone_ms=3.0,
        peak_rss_mib=300.0,
        openblas_threads="1",
        cpus=(0,),
    )


@pytest.fixture(scope="session")
def pages(
    run_dir: Path,
    unscored_dir: Path,
    score_dir: Path,
    tmp_path_factory: pytest.TempPathFactory,
) -> dict[str, Path]:
    """Every page: the report.html of a run, of a run without ground truth and of ``score``,
    and the sweep, compare, reproduce and bench pages."""
    out = tmp_path_factory.mktemp("html_pages")
    write_sweep_html(out, sweep_result(), "basso2012", ["short.mcap"], [], Gating.IOU)
    baseline = json.loads((run_dir / "report.json").read_text())
    current = json.loads(json.dumps(baseline))
    metrics = current["sequences"][0]["metrics"]
    metrics["id_switches"] += 1  # regressed (tolerance 0)
    metrics["fn_rate"] = max(0.0, metrics["fn_rate"] - 0.05)  # better by 5 points
    comparison = compare_reports(baseline, current)
    (out / "compare.html").write_text(compare_page(comparison, "base.json", "current.json"))
    (out / "reproduce.html").write_text(reproduce_page(reproduction(), "basso2012"))
    (out / "bench.html").write_text(bench_page(bench_result(), STAGE_LABELS))
    return {
        "run": run_dir / "report.html",
        "unscored": unscored_dir / "report.html",
        "score": score_dir / "report.html",
        "sweep": out / "sweep.html",
        "compare": out / "compare.html",
        "reproduce": out / "reproduce.html",
        "bench": out / "bench.html",
    }
