"""``rgbd-eval bench``: frames per second and milliseconds per stage, against the decode floor."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.table import Table

from rgbd_eval.cli.common import (
    ConfigOption,
    SetOption,
    TopicOption,
    advance_callback,
    console,
    handle_errors,
    progress_bar,
    topic_overrides,
)
from rgbd_eval.config import load_config
from rgbd_eval.outdir import check_output_file

if TYPE_CHECKING:
    from rgbd_eval.bench import BenchResult

#: Human names of the stages.
STAGE_LABELS = {
    "index": "index + sync",
    "decode": "read + decode",
    "pointcloud": "point cloud",
    "voxel": "voxel grid",
    "ground": "ground plane",
    "clustering": "clustering",
    "subclustering": "sub-clustering",
    "features": "features",
    "hog": "HOG",
    "detections": "detector (rest of the call)",
    "track": "tracking",
    "score": "scoring",
    "other": "other (loop)",
}


def print_bench(result: BenchResult) -> None:
    """The human table: per-stage milliseconds, fps, and the decode floor."""
    (rw, rh), (dw, dh) = result.rgb_size, result.depth_size
    table = Table(
        title=(
            f"{result.method} on {Path(result.path).name}: {result.frames} frames, "
            f"RGB {rw}x{rh}, depth {dw}x{dh}"
        ),
        title_justify="left",
        min_width=76,
    )
    table.add_column("stage")
    table.add_column("ms/frame", justify="right")
    table.add_column("share", justify="right")
    table.add_column("fps alone", justify="right")
    for stage, ms in result.stage_ms.items():
        fps = result.stage_fps(stage)
        table.add_row(
            STAGE_LABELS.get(stage, stage),
            f"{ms:.3f}",
            f"{100.0 * ms / result.total_ms:.1f}%",
            "-" if fps == float("inf") else f"{fps:.0f}",
        )
    table.add_row(
        "pipeline",
        f"{result.total_ms:.3f}",
        "",
        f"{result.fps:.1f}",
        style="bold",
        end_section=True,
    )
    if result.cpu_ms_repeats:
        table.add_row("pipeline, CPU time", f"{result.cpu_ms:.3f}", "", f"{result.cpu_fps:.1f}")
    table.add_row("decode alone (floor)", f"{result.floor_ms:.3f}", "", f"{result.floor_fps:.1f}")
    table.add_row(f"raw bytes ({result.raw_reader})", f"{result.raw_ms:.3f}", "", "")
    table.add_row(
        "tracking alone (cached detections)",
        f"{result.track_alone_ms:.3f}",
        "",
        f"{result.track_alone_fps:.0f}",
    )
    console.print(table)
    threads = result.openblas_threads or "unset"
    cpus = "unknown" if result.cpus is None else ",".join(map(str, result.cpus))
    console.print(
        f"median of {result.repeats} repeat{'s' if result.repeats > 1 else ''}; "
        f"pipeline/floor = {result.ratio:.2f}; {result.detections_per_frame:.2f} detections and "
        f"{result.tracks_per_frame:.2f} tracks per frame; "
        f"{'scored' if result.scored else 'no ground truth, scoring not timed'}; "
        f"peak RSS {result.peak_rss_mib:.0f} MiB; OPENBLAS_NUM_THREADS={threads}; CPUs {cpus}"
    )
    if result.cpu_ms_repeats:
        console.print(
            f"CPU time / wall time = {result.cpu_ms / result.total_ms:.2f} "
            "(below 1: other processes shared the core; the CPU-time fps is what an idle core "
            f"gives); load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}"
        )


@handle_errors
def bench(
    path: Annotated[
        Path | None, typer.Argument(help="recording to time (default: the demo)")
    ] = None,
    method: Annotated[
        str | None, typer.Option(help="method by name (`rgbd-eval methods`; default: basso2012)")
    ] = None,
    repeat: Annotated[int, typer.Option(help="repeats; figures are medians")] = 3,
    config_file: ConfigOption = None,
    overrides: SetOption = None,
    json_out: Annotated[
        bool, typer.Option("--json", help="print the result as JSON instead of a table")
    ] = False,
    all_cores: Annotated[
        bool,
        typer.Option("--all-cores", help="do not pin to one CPU (OpenCV may use threads)"),
    ] = False,
    html_file: Annotated[
        Path | None, typer.Option("--html", help="also write the figures as an HTML page")
    ] = None,
    topics: TopicOption = None,
) -> None:
    """Time each pipeline stage on one recording, against the floor of decoding it alone.

    One-core figures: the process is pinned to one CPU, OpenCV and BLAS to one thread.
    """
    from rgbd_eval.bench import benchmark, one_core  # heavy imports only when needed
    from rgbd_eval.cli.run import ensure_demo

    config = load_config(
        config_file,
        [*(overrides or []), *topic_overrides(topics)],
        method=method or (None if config_file else "basso2012"),
    )
    if html_file is not None:  # before any work; never the recording itself
        check_output_file(html_file, "bench", [path] if path is not None else [])
    target = path if path is not None else ensure_demo()
    if not all_cores:
        one_core()
    with progress_bar() as bar:
        task = bar.add_task(f"bench {target.name}", total=None)
        result = benchmark(target, config, repeat, advance_callback(bar, task))
    if html_file is not None:
        from rgbd_eval.atomic import write_text
        from rgbd_eval.report.html.pages import bench_page

        write_text(html_file, bench_page(result, STAGE_LABELS), "bench")
    if json_out:
        typer.echo(json.dumps(result.to_json(), indent=2))
    else:
        print_bench(result)
