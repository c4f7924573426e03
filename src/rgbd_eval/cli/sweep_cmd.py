"""``rgbd-eval sweep``: a parameter grid over datasets, with cached detections."""

from __future__ import annotations

import csv
import io
import json
import time
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.table import Table

from rgbd_eval.cli.common import (
    CACHE_MODE_HELP,
    CLUSTER_HELP,
    SCHEMA_VERSION,
    JobsOption,
    TopicOption,
    cluster_of,
    console,
    err_console,
    handle_errors,
    parse_cache_mode,
    progress_bar,
    topic_overrides,
)
from rgbd_eval.config import Gating, load_yaml, parse_overrides
from rgbd_eval.errors import ConfigError, TaskError
from rgbd_eval.outdir import OutputFolder

if TYPE_CHECKING:
    from rgbd_eval.sweep import SweepResult


def _csv(rows: list[dict[str, Any]]) -> str:
    if not rows:
        return ""
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=list(rows[0]), lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return buf.getvalue()


def _write_outputs(
    folder: OutputFolder,
    result: SweepResult,
    wall: float,
    method: str,
    recordings: list[Path],
    fixed: list[str],
    gating: Gating,
    cluster: str,
) -> None:
    """``sweep.csv``, ``sweep.json``, ``sweep.html`` (and ``sweep.png``) into the staging
    folder, then publish."""
    from rgbd_eval.report.html.pages import write_sweep_html

    tmp = folder.staging
    rows = result.rows()
    (tmp / "sweep.csv").write_text(_csv(rows), encoding="utf-8")
    write_sweep_html(tmp, result, method, [str(p) for p in recordings], fixed, gating)
    record = {
        "schema_version": SCHEMA_VERSION,
        "params": list(result.params),
        "method": method,
        "datasets": [str(p) for p in recordings],
        "fixed": fixed,
        "records": rows,
        "failures": [
            {**f.point, "sequence": f.sequence, "error": f.error, "exit_code": f.exit_code}
            for f in result.failures
        ],
        "cluster": cluster,
        "seconds": {
            "wall": wall,
            "detect_tasks": result.detect_seconds,
            "track_score_tasks": result.track_seconds,
        },
        "cache": {
            "hits": result.cache_hits,
            "misses": result.cache_misses,
            "rejected": list(result.warnings),
        },
    }
    text = json.dumps(record, indent=2, allow_nan=False) + "\n"
    (tmp / "sweep.json").write_text(text, encoding="utf-8")
    folder.commit()


def _failed(result: SweepResult, where: str) -> TaskError:
    """One line: how many (point, sequence) tasks failed, and the first failure in grid order."""
    first = result.failures[0]
    label = ", ".join(f"{k}={v}" for k, v in first.point.items())
    n, units = len(result.failures), len(result.failures) + len(result.records)
    return TaskError(
        f"{n} of {units} sweep point(s) failed{where}; first: {label} on {first.sequence}: "
        f"{first.error}",
        first.exit_code,
    )


@handle_errors
def sweep(
    param: Annotated[
        str | None, typer.Argument(help="dotted config key to sweep, e.g. tracker.min_confidence")
    ] = None,
    values: Annotated[list[str] | None, typer.Argument(help="values of PARAM")] = None,
    params: Annotated[
        list[str] | None, typer.Option("--param", help="NAME=V1,V2,... (repeatable)")
    ] = None,
    file: Annotated[
        Path | None, typer.Option("--file", help="sweep file (configs/sweeps/*.yaml)")
    ] = None,
    dataset: Annotated[
        list[str] | None, typer.Option("--dataset", help="dataset name or path (repeatable)")
    ] = None,
    method: Annotated[str, typer.Option(help="detector/tracker pairing")] = "basso2012",
    overrides: Annotated[
        list[str] | None, typer.Option("--set", help="fixed KEY=VALUE override")
    ] = None,
    gating: Annotated[str | None, typer.Option(help="'iou' or 'metric'")] = None,
    cluster: Annotated[str, typer.Option(help=CLUSTER_HELP)] = "local",
    jobs: JobsOption = None,
    out: Annotated[
        Path | None, typer.Option(help="output folder (default runs/sweep-<time>)")
    ] = None,
    cache: Annotated[Path | None, typer.Option(help="detection cache folder")] = None,
    cache_mode: Annotated[str, typer.Option(help=CACHE_MODE_HELP)] = "shared",
    force: Annotated[
        bool,
        typer.Option(help="write into a non-empty --out folder we did not write (keeps its files)"),
    ] = False,
    topics: TopicOption = None,
) -> None:
    """Sweep config keys over datasets; records as CSV + JSON, a plot and a table."""
    from rgbd_eval import datasets
    from rgbd_eval.cache import DetectionCache
    from rgbd_eval.config import load_config
    from rgbd_eval.engine import connect, parse_cluster
    from rgbd_eval.metrics import summarize
    from rgbd_eval.report.run import format_value
    from rgbd_eval.sweep import (
        SweepParam,
        expand_grid,
        parse_param,
        point_configs,
        run_sweep,
        warm_up,
    )

    specs: list[SweepParam] = [parse_param(p) for p in params or []]
    names = list(dataset or [])
    fixed = [*(overrides or []), *topic_overrides(topics)]
    if file is not None:
        data = load_yaml(file)
        unknown = set(data) - {"params", "datasets", "set"}
        if unknown:
            raise ConfigError(
                f"{file}: unknown keys {sorted(unknown)} (known: params, datasets, set)"
            )
        for key, vals in (data.get("params") or {}).items():
            specs.append(SweepParam(str(key), tuple(vals if isinstance(vals, list) else [vals])))
        names += [str(d) for d in data.get("datasets") or []]
        fixed += [f"{k}={v}" for k, v in (data.get("set") or {}).items()]
    if param is not None:
        if not values:
            raise ConfigError(
                f"sweep {param}: give the values to try, e.g. `sweep {param} -1 -0.5 0`"
            )
        specs.insert(
            0,
            SweepParam(param, tuple(v for _, v in parse_overrides(f"{param}={x}" for x in values))),
        )
    if not specs:
        raise ConfigError("nothing to sweep: give PARAM VALUE..., --param or --file")
    if gating is not None:
        fixed.append(f"evaluation.gating={gating}")
    base = load_config(method=method).model_dump(mode="json")
    grid = expand_grid(specs)
    configs = point_configs(base, parse_overrides(fixed), grid)
    recordings = [datasets.resolve(n) for n in (names or ["demo"])]
    out_dir = out or Path("runs") / f"sweep-{time.strftime('%Y%m%d-%H%M%S')}"
    mode = parse_cache_mode(cache_mode)
    DetectionCache(cache)  # refuses a cache path that is a file before a cluster starts
    spec = parse_cluster(cluster_of(cluster, jobs), tasks=len(grid) * len(recordings))
    console.print(f"sweep: {len(grid)} points x {len(recordings)} sequences, {spec.describe()}")
    g = configs[0].evaluation.gating if configs else Gating.IOU
    folder = OutputFolder(
        out_dir,
        "sweep.json",
        force,
        command="sweep",
        names=["sweep.csv", "sweep.html", "sweep.png"],
    )
    with folder:  # checked and staged before the sweep; published whole or not at all
        start = time.perf_counter()
        with connect(spec, warm_up=warm_up) as client, progress_bar() as bar:
            tasks = {name: bar.add_task(name, total=None) for name in ("detect", "track+score")}
            result = run_sweep(
                recordings,
                grid,
                configs,
                client,
                cache_root=cache,
                cache_mode=mode,
                progress=lambda stage, done, n: bar.update(tasks[stage], completed=done, total=n),
            )
        wall = time.perf_counter() - start
        for warning in result.warnings:
            err_console.print(f"warning: {warning}", markup=False, highlight=False, soft_wrap=True)
        if not result.records:  # nothing scored: no output folder, one error line
            raise _failed(result, "")
        _write_outputs(folder, result, wall, method, recordings, fixed, g, spec.describe())
    table = Table(title=f"{', '.join(result.params)} (all sequences summed)", title_justify="left")
    heads = [*result.params, "MOTP", "MOTA", "FP", "FN", "ID Sw.", "Main Tr.", "All Tr."]
    for h in heads:
        table.add_column(h, justify="right")
    for point, counts in result.overall():
        s = summarize(counts)
        cells = [
            format_value(s, k, kind, g)
            for k, kind in (
                ("motp", "motp"),
                ("mota", "pct"),
                ("fp_rate", "pct"),
                ("fn_rate", "pct"),
                ("id_switches", "int"),
                ("main_tr", "pct"),
                ("all_tr", "pct"),
            )
        ]
        table.add_row(*[str(point[p]) for p in result.params], *cells)
    console.print(table)
    console.print(
        f"wall {wall:.1f} s (task seconds: detect {result.detect_seconds:.1f}, "
        f"track+score {result.track_seconds:.1f}); detection cache: {result.cache_hits} hit(s), "
        f"{result.cache_misses} miss(es); records: {out_dir / 'sweep.csv'}, "
        f"page: {out_dir / 'sweep.html'}"
    )
    if result.failures:
        raise _failed(result, f"; all are listed in {out_dir / 'sweep.json'}")
