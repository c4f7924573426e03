"""``rgbd-eval score``: score a tracker's recorded output against ground truth."""

from __future__ import annotations

import gc
import json
import time
from pathlib import Path
from typing import Annotated

import typer

from rgbd_eval.cli.common import (
    CLUSTER_HELP,
    DEFAULT_CURVE_POINTS,
    ConfigOption,
    CurveOption,
    CurvePointsOption,
    SetOption,
    console,
    err_console,
    handle_errors,
    metrics_table,
    with_threshold,
)
from rgbd_eval.config import load_config
from rgbd_eval.errors import ConfigError
from rgbd_eval.outdir import OutputFolder


@handle_errors
def score(
    tracks: Annotated[
        Path,
        typer.Argument(
            help="tracker output (MOTChallenge .txt, tracks.csv, KTP, a bag with tracks) or a folder"
        ),
    ],
    gt: Annotated[
        Path, typer.Option(help="ground truth (MOTChallenge gt.txt, CSV sidecar, KTP) or a folder")
    ],
    gating: Annotated[
        str | None, typer.Option(help="'iou' (image boxes) or 'metric' (ground plane)")
    ] = None,
    threshold: Annotated[
        float | None, typer.Option(help="IoU >= x, or distance <= x metres")
    ] = None,
    convention: Annotated[
        str | None,
        typer.Option(help="'motchallenge' (devkit/TrackEval, default) or 'motmetrics' (1.4)"),
    ] = None,
    benchmark: Annotated[
        str,
        typer.Option(help="MOTChallenge ground-truth rules: auto, mot15, mot16, mot17, mot20"),
    ] = "auto",
    tracks_topic: Annotated[
        str | None, typer.Option(help="topic of the tracks in a bag (when there are several)")
    ] = None,
    config_file: ConfigOption = None,
    overrides: SetOption = None,
    out: Annotated[
        Path | None, typer.Option(help="output folder (default: runs/<time>-score)")
    ] = None,
    json_out: Annotated[
        bool, typer.Option("--json", help="print report.json on stdout instead of a table")
    ] = False,
    cluster: Annotated[
        str | None, typer.Option(help=f"{CLUSTER_HELP} (default: in this process)")
    ] = None,
    force: Annotated[
        bool,
        typer.Option(help="write into a non-empty --out folder we did not write (keeps its files)"),
    ] = False,
    curve: CurveOption = False,
    curve_points: CurvePointsOption = DEFAULT_CURVE_POINTS,
) -> None:
    """Score recorded tracker output against ground truth; write the same report as `run`."""
    from rgbd_eval.io.tracks import Benchmark, sequence_pairs
    from rgbd_eval.report.analysis import analyse, inputs_of_score
    from rgbd_eval.report.html.pages import write_score_html
    from rgbd_eval.report.scoring import score_sequence, table_rows, write_report

    sets = list(overrides or [])
    for key, value in (("gating", gating), ("convention", convention)):
        if value is not None:
            sets.append(f"evaluation.{key}={value}")
    config = with_threshold(load_config(config_file, sets), threshold)
    try:
        rules = Benchmark(benchmark)
    except ValueError as err:
        known = ", ".join(b.value for b in Benchmark)
        raise ConfigError(f"--benchmark {benchmark!r}: expected one of {known}") from err
    max_gap_ns = int(config.io.max_sync_gap_ms * 1e6)
    out_dir = out or Path("runs") / f"{time.strftime('%Y%m%d-%H%M%S')}-score"
    folder = OutputFolder(
        out_dir, "report.json", force, command="score", names=["report.md", "report.html"]
    )
    # The output folder is checked and staged before any input is read, as for run.
    try:
        with folder:
            pairs = sequence_pairs(tracks, gt)
            rest = (config.evaluation, max_gap_ns, rules, tracks_topic, config.io.world_frame)
            if cluster is None:
                sequences = []
                # Reading and scoring make no reference cycles to speak of, only objects that
                # live until the report is written (millions on MOT17): the collector stays
                # off while a sequence is built, and its objects are frozen after it, so that
                # the full passes of the writing stop rescanning them (together a third of
                # the command's CPU time on MOT17-train).
                collecting = gc.isenabled()
                gc.disable()
                try:
                    for name, t, g in pairs:
                        sequences.append(score_sequence(name, t, g, *rest))
                        gc.freeze()
                finally:
                    if collecting:
                        gc.enable()
            else:  # a task per sequence; results come back, this process writes the report
                from rgbd_eval.engine import connect, map_ordered, parse_cluster
                from rgbd_eval.sweep import warm_up

                spec = parse_cluster(cluster, tasks=len(pairs))
                if spec.address is not None:  # remote workers do not share our working directory
                    pairs = [(name, t.resolve(), g.resolve()) for name, t, g in pairs]
                with connect(spec, warm_up=warm_up) as client:
                    sequences = map_ordered(client, score_sequence, [(*p, *rest) for p in pairs])
            analysis = analyse(
                inputs_of_score(sequences), config.evaluation, curve_points if curve else None
            )
            report = write_report(
                folder,
                sequences,
                config.evaluation,
                max_gap_ns,
                lambda staging, rep: write_score_html(
                    staging, sequences, rep, config.evaluation.gating, analysis
                ),
                analysis,
            )
    finally:  # the objects frozen here (and any before) are collectable again
        gc.unfreeze()
    if json_out:
        typer.echo(json.dumps(report, indent=2))
        return
    from rgbd_eval.report.run import table_header

    ev = config.evaluation
    title = (
        f"gating {ev.gating.value} (threshold {ev.effective_threshold()}), "
        f"convention {ev.convention.value}"
    )
    console.print(metrics_table(title, table_header(), table_rows(sequences, ev.gating)))
    console.print(
        f"report: {out_dir / 'report.html'}, {out_dir / 'report.md'} "
        f"(machine-readable: {out_dir / 'report.json'})"
    )
    for s in sequences:  # also in report.json: each sequence's "warnings"
        for w in s.warnings:
            err_console.print(
                f"warning: {s.name}: {w}", markup=False, highlight=False, soft_wrap=True
            )
