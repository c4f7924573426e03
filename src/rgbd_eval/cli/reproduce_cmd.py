"""``rgbd-eval reproduce [METHOD]``: a paper's tables, paper beside measured; no METHOD lists them."""

from __future__ import annotations

import time
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
    from rgbd_eval.sim.synth import ensure_scenario
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
        recordings = {
            Path(name).stem: ensure_scenario(name, data, lambda m: err_console.print(m))
            for name in spec.scenarios
        }
        with connect(cluster_spec, warm_up=warm_up) as client:
            options = ReproduceOptions(
                client=client,
                cache=cache,
                progress=lambda m: err_console.print(m),
                data=data,
            )
            result = spec.experiments()(recordings, options)
        staging = folder.staging
        write_text(staging / "reproduce.md", result.markdown)
        write_json(staging / "reproduce.json", {"method": system, **result.data})
        write_text(staging / "reproduce.html", reproduce_page(result, system))
        folder.commit()
    console.print(result.markdown, markup=False)
    if result.claims:
        console.print("claims: " + tally([v for _, v in result.verdicts()]))
    console.print(
        f"written: {out_dir / 'reproduce.md'}, {out_dir / 'reproduce.json'}, "
        f"{out_dir / 'reproduce.html'}"
    )
