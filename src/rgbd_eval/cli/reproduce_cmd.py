"""``rgbd-eval reproduce basso2012``: the thesis' tables, paper beside measured."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated

import typer

from rgbd_eval.cli.common import CLUSTER_HELP, console, err_console, handle_errors
from rgbd_eval.errors import ConfigError


@handle_errors
def reproduce(
    system: Annotated[str, typer.Argument(help="which paper: basso2012")],
    out: Annotated[
        Path | None, typer.Option(help="output folder (default runs/reproduce-<time>)")
    ] = None,
    cluster: Annotated[str, typer.Option(help=CLUSTER_HELP)] = "local",
    cache: Annotated[Path | None, typer.Option(help="detection cache folder")] = None,
) -> None:
    """Redo the thesis' experiments on the six synthetic scenarios (generated if absent)."""
    if system != "basso2012":
        raise ConfigError(f"reproduce {system!r}: only basso2012 is available")
    from rgbd_eval.atomic import write_json, write_text
    from rgbd_eval.datasets import scenarios_dir
    from rgbd_eval.engine import connect, parse_cluster
    from rgbd_eval.reproduce import (
        SCENARIOS,
        paper_values,
        render_markdown,
        reproduce_basso2012,
        to_json,
    )
    from rgbd_eval.sim import dataset_path, load_scenario, synthesize

    recordings = {}
    for name in SCENARIOS:
        path = dataset_path(name)
        if not path.exists():
            err_console.print(f"generating {path} ...")
            synthesize(load_scenario(scenarios_dir() / f"{name}.yaml"), path)
        recordings[name] = path
    out_dir = out or Path("runs") / f"reproduce-{time.strftime('%Y%m%d-%H%M%S')}"
    with connect(parse_cluster(cluster)) as client:
        res = reproduce_basso2012(
            recordings, client=client, cache=cache, progress=lambda m: err_console.print(m)
        )
    text = render_markdown(res, paper_values())
    write_text(out_dir / "reproduce.md", text)
    write_json(out_dir / "reproduce.json", to_json(res))
    console.print(text, markup=False)
    console.print(f"written: {out_dir / 'reproduce.md'}, {out_dir / 'reproduce.json'}")
