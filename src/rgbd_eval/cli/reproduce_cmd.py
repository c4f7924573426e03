"""``rgbd-eval reproduce [METHOD]``: a paper's tables, paper beside measured; no METHOD lists them."""

from __future__ import annotations

import resource
import time
from dataclasses import replace
from pathlib import Path
from typing import Annotated

import typer

from rgbd_eval.cli.common import (
    CLUSTER_HELP,
    JobsOption,
    cluster_of,
    console,
    err_console,
    handle_errors,
)
from rgbd_eval.errors import OutputError
from rgbd_eval.outdir import OutputFolder
from rgbd_eval.verdicts import tally


def cpu_seconds() -> float:
    """CPU seconds of this process and of its ended children (a local cluster's workers).

    Children count once they have ended: a local cluster's workers when it shuts down.
    """
    own = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


def cpu_summary(
    generate_s: float, experiments_s: float, data: dict[str, object], seeded_s: float = 0.0
) -> str:
    """One line on where the CPU went: generating recordings, rendering inside, the method.

    Rendering inside the experiments is ``seeded_s`` (recordings at other scenario seeds,
    :func:`rgbd_eval.sim.synth.rendering_cpu_s`) plus what a paper's experiments that render
    scenes their own way (closed loops, camera layouts) report as ``data["cpu_s"]["render"]``.
    """
    inner = data.get("cpu_s")
    own = float(inner.get("render", 0.0)) if isinstance(inner, dict) else 0.0
    render_inside = own + seeded_s
    render = generate_s + render_inside
    method = max(0.0, experiments_s - render_inside)
    return (
        f"CPU time: {generate_s + experiments_s:.0f} s, of which rendering {render:.0f} s and "
        f"the experiments {method:.0f} s (all processes, this machine: {_machine()})"
    )


def _machine() -> str:
    from rgbd_eval.machine import machine_info

    return machine_info()["cpu"] or "unknown CPU"


@handle_errors
def reproduce(
    system: Annotated[
        str | None, typer.Argument(help="the method whose paper to reproduce (none: list them)")
    ] = None,
    out: Annotated[
        Path | None, typer.Option(help="output folder (default runs/reproduce-<method>-<time>)")
    ] = None,
    cluster: Annotated[str, typer.Option(help=CLUSTER_HELP)] = "local",
    jobs: JobsOption = None,
    cache: Annotated[Path | None, typer.Option(help="detection cache folder")] = None,
    data: Annotated[
        Path | None,
        typer.Option(help="folder of the generated recordings (default: the datasets folder)"),
    ] = None,
    force: Annotated[
        bool,
        typer.Option(help="write into a non-empty --out folder we did not write (keeps its files)"),
    ] = False,
) -> None:
    """Redo a paper's experiments on synthetic scenarios (generated if absent)."""
    from rgbd_eval.plugins import ReproduceOptions, known, paper_spec

    if system is None:
        for name in known("papers"):
            spec = paper_spec(name)
            console.print(f"{name}: {spec.title} ({len(spec.scenarios)} scenarios)")
        return
    spec = paper_spec(system)  # ConfigError listing the known papers
    from rgbd_eval.atomic import write_json, write_text
    from rgbd_eval.cache import DetectionCache
    from rgbd_eval.engine import connect, parse_cluster
    from rgbd_eval.report.html.pages import reproduce_page
    from rgbd_eval.sim.synth import ensure_scenario, rendering_cpu_s
    from rgbd_eval.sweep import warm_up

    # Every option is checked before the scenarios are generated (that takes minutes).
    if data is not None and data.exists() and not data.is_dir():  # was FileExistsError
        raise OutputError(data, "--data is not a folder (it holds the generated recordings)")
    cluster_spec = parse_cluster(cluster_of(cluster, jobs))
    DetectionCache(cache)  # refuses a cache path that is a file
    out_dir = out or Path("runs") / f"reproduce-{system}-{time.strftime('%Y%m%d-%H%M%S')}"
    names = ["reproduce.md", "reproduce.html"]
    # The output folder is checked and staged before the scenarios are generated and run.
    with OutputFolder(out_dir, "reproduce.json", force, command="reproduce", names=names) as folder:
        cpu_start = cpu_seconds()
        recordings = {
            Path(name).stem: ensure_scenario(name, data, lambda m: err_console.print(m))
            for name in spec.scenarios
        }
        cpu_generated = cpu_seconds()
        seeded_start = rendering_cpu_s()
        with connect(cluster_spec, warm_up=warm_up) as client:
            options = ReproduceOptions(
                client=client,
                cache=cache,
                progress=lambda m: err_console.print(m),
                data=data,
            )
            result = spec.experiments()(recordings, options)
        # After the cluster's shutdown, so that its workers' CPU is counted (a remote
        # cluster's is not: the figure is then this process's only).
        generate_s, experiments_s = cpu_generated - cpu_start, cpu_seconds() - cpu_generated
        seeded_s = rendering_cpu_s() - seeded_start
        payload = {
            "method": system,
            **result.data,
            "cpu_total_s": {
                "generate": round(generate_s, 1),
                "experiments": round(experiments_s, 1),
                "rendered_in_experiments": round(seeded_s, 1),
            },
        }
        line = cpu_summary(generate_s, experiments_s, dict(result.data), seeded_s)
        result = replace(result, markdown=f"{result.markdown.rstrip()}\n\n{line}\n")
        staging = folder.staging
        write_text(staging / "reproduce.md", result.markdown)
        write_json(staging / "reproduce.json", payload)
        write_text(staging / "reproduce.html", reproduce_page(result, system, cpu_line=line))
        folder.commit()
    console.print(result.markdown, markup=False)
    if result.claims:
        console.print("claims: " + tally([v for _, v in result.verdicts()]))
    console.print(
        f"written: {out_dir / 'reproduce.md'}, {out_dir / 'reproduce.json'}, "
        f"{out_dir / 'reproduce.html'}"
    )
