"""``rgbd-eval run``: detect, track and score recordings; write a report folder."""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from rgbd_eval.cli.common import (
    CLUSTER_HELP,
    DEFAULT_CURVE_POINTS,
    ConfigOption,
    CurveOption,
    CurvePointsOption,
    SetOption,
    TopicOption,
    advance_callback,
    console,
    err_console,
    handle_errors,
    metrics_table,
    progress_bar,
    topic_overrides,
    with_threshold,
)
from rgbd_eval.config import RunConfig, load_config
from rgbd_eval.errors import GroundTruthError, InputError
from rgbd_eval.outdir import OutputFolder

if TYPE_CHECKING:
    from rgbd_eval.pipeline import SequenceResult

RECORDING_SUFFIXES = (".bag", ".mcap", ".db3")


def default_demo() -> Path:
    from rgbd_eval.sim.synth import DEMO, dataset_path

    return dataset_path(DEMO)


def expand_inputs(paths: list[Path]) -> list[Path]:
    """Recordings named on the command line; a plain folder stands for the recordings in it."""
    out: list[Path] = []
    for p in paths:
        if p.is_dir() and not (p / "metadata.yaml").exists():
            found = sorted(
                c
                for c in p.iterdir()
                if (c.is_file() and c.suffix in RECORDING_SUFFIXES)
                or (c.is_dir() and (c / "metadata.yaml").exists())
            )
            if not found:
                raise InputError(
                    p, "folder holds no recordings (.bag, .mcap, .db3 or ROS2 bag folders)"
                )
            out.extend(found)
        else:
            out.append(p)
    names = [p.name for p in out]
    dupes = {n for n in names if names.count(n) > 1}
    if dupes:
        raise InputError(
            out[0], f"two inputs share the name {sorted(dupes)[0]!r}; reports would collide"
        )
    return out


def ensure_demo() -> Path:
    """The demo recording, generated on first use (deterministic, a few seconds)."""
    from rgbd_eval.sim.synth import demo_recording  # imported lazily: open3d is slow to import

    path = default_demo()
    if not path.exists():
        err_console.print(f"generating the demo recording {path} (first use) ...")
    return demo_recording()


def print_table(results: list[SequenceResult], config: RunConfig) -> None:
    from rgbd_eval.report.run import run_notes, table_header, table_rows

    scored = [r for r in results if r.scores is not None]
    if scored:
        title = (
            f"{config.method}, gating {config.evaluation.gating.value} "
            f"(threshold {config.evaluation.effective_threshold()})"
        )
        rows = table_rows(results, config.evaluation.gating)
        console.print(metrics_table(title, table_header(), rows))
    for note in run_notes(results, warnings=False):
        console.print(note)


@handle_errors
def run(
    paths: Annotated[
        list[Path] | None,
        typer.Argument(help="recordings or folders of recordings (default: the demo)"),
    ] = None,
    method: Annotated[
        str | None, typer.Option(help="method by name (`rgbd-eval methods`; default: basso2012)")
    ] = None,
    gt: Annotated[
        Path | None, typer.Option(help="ground-truth file (CSV or KTP) for a single recording")
    ] = None,
    gating: Annotated[
        str | None, typer.Option(help="'iou' (image boxes) or 'metric' (ground plane)")
    ] = None,
    threshold: Annotated[
        float | None, typer.Option(help="IoU >= x, or distance <= x metres")
    ] = None,
    config_file: ConfigOption = None,
    overrides: SetOption = None,
    out: Annotated[
        Path | None, typer.Option(help="output folder (default: runs/<time>-<method>)")
    ] = None,
    json_out: Annotated[
        bool, typer.Option("--json", help="print report.json on stdout instead of a table")
    ] = False,
    video: Annotated[
        bool,
        typer.Option("--video", help="also write <name>.overlay.mp4: tracks on the RGB frames"),
    ] = False,
    force: Annotated[
        bool,
        typer.Option(help="write into a non-empty --out folder we did not write (keeps its files)"),
    ] = False,
    topics: TopicOption = None,
    cluster: Annotated[
        str | None,
        typer.Option(help=f"{CLUSTER_HELP} (default: in this process for one recording)"),
    ] = None,
    curve: CurveOption = False,
    curve_points: CurvePointsOption = DEFAULT_CURVE_POINTS,
    rerun: Annotated[
        Path | None,
        typer.Option(
            "--rerun",
            help="also write the run as a Rerun recording (FILE.rrd; one recording; "
            "needs pip install 'rgbd-eval[rerun]')",
        ),
    ] = None,
) -> None:
    """Run the pipeline on recordings and score it against their ground truth."""
    from rgbd_eval.pipeline import run_sequence, sequence_name  # heavy imports only when needed
    from rgbd_eval.report.analysis import analyse, inputs_of_run
    from rgbd_eval.report.html.pages import write_run_html
    from rgbd_eval.report.run import REPORT_FILE, sequence_warnings, write_run

    sets = [*(overrides or []), *topic_overrides(topics)]
    if gating is not None:
        sets.append(f"evaluation.gating={gating}")
    config = load_config(config_file, sets, method=method or (None if config_file else "basso2012"))
    config = with_threshold(config, threshold)
    inputs = list(paths or [])
    if not inputs:
        inputs = [ensure_demo()]
    recordings = expand_inputs(inputs)
    if gt is not None and len(recordings) > 1:  # which recording it annotates is unknown
        raise GroundTruthError(
            gt, "--gt applies to a single recording; use <name>.gt.csv sidecars for several"
        )
    rrd = None
    if rerun is not None:  # checked before any work, like the output folder
        from rgbd_eval.report.rerun import RrdOutput

        if len(recordings) > 1:
            raise typer.BadParameter(
                "takes one recording; for several, `rgbd-eval view` writes each run's",
                param_hint="'--rerun'",
            )
        rrd = RrdOutput(rerun, "run", recordings)
    out_dir = out or Path("runs") / f"{time.strftime('%Y%m%d-%H%M%S')}-{config.method}"
    results: list[SequenceResult] = []
    # What this run will write, checked against what the folder holds before any work.
    names = ["report.md", "report.html"]
    kinds = ["detections.csv", "tracks.csv", "birdseye.png", "frames.npz"]
    kinds += ["overlay.mp4"] if video else []
    for p in recordings:
        names += [f"{sequence_name(p)}.{k}" for k in kinds]
    with OutputFolder(out_dir, REPORT_FILE, force, command="run", names=names) as folder:
        # The output folder is checked and staged before this work.
        if cluster is None and len(recordings) == 1:
            with progress_bar() as bar:  # one recording: a bar over its frames
                task = bar.add_task(recordings[0].name, total=None)
                results.append(run_sequence(recordings[0], config, gt, advance_callback(bar, task)))
        else:  # a task per recording on the cluster; results come back, this process writes
            from rgbd_eval.engine import connect, map_ordered, parse_cluster
            from rgbd_eval.sweep import warm_up

            spec = parse_cluster(cluster, tasks=len(recordings))
            remote = spec.address is not None  # remote workers do not share our working dir
            args = [
                (p.resolve() if remote else p, config, gt.resolve() if gt and remote else gt)
                for p in recordings
            ]
            with connect(spec, warm_up=warm_up) as client, progress_bar() as bar:
                task = bar.add_task(f"recordings ({spec.describe()})", total=len(recordings))
                results = map_ordered(client, run_sequence, args, advance_callback(bar, task))
        analysis = analyse(
            inputs_of_run(results), config.evaluation, curve_points if curve else None
        )
        with progress_bar() as bar:
            task = bar.add_task("report.html" + (" + video" if video else ""), total=None)
            report = write_run(
                folder,
                results,
                config,
                lambda staging, rep: write_run_html(
                    staging, results, config, rep, video, advance_callback(bar, task), analysis
                ),
                analysis,
            )
    if rrd is not None:  # re-reads the recording for its images and depth, as --video does
        with progress_bar() as bar:
            task = bar.add_task(rrd.path.name, total=None)
            rrd.write(results[0], config, advance_callback(bar, task))
    if json_out:
        typer.echo(json.dumps(report, indent=2))
    else:
        print_table(results, config)
        console.print(
            f"report: {out_dir / 'report.html'}, {out_dir / 'report.md'} "
            f"(machine-readable: {out_dir / 'report.json'})"
        )
        if rrd is not None:
            console.print(f"Rerun: rerun {rrd.path}")
    for r in results:  # also in report.json: each sequence's "warnings"
        for w in sequence_warnings(r):
            err_console.print(
                f"warning: {r.name}: {w}", markup=False, highlight=False, soft_wrap=True
            )
