"""``rgbd-eval reproduce basso2012``: the thesis' tables, paper beside measured."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated

import typer

from rgbd_eval.cli.common import console, err_console, handle_errors
from rgbd_eval.errors import ConfigError


@handle_errors
def reproduce(
    system: Annotated[str, typer.Argument(help="which paper: basso2012")],
    out: Annotated[
        Path | None, typer.Option(help="output folder (default runs/reproduce-<time>)")
    ] = None,
    jobs: Annotated[
        int | None, typer.Option(help="worker processes (default: one per usable CPU)")
    ] = None,
    cache: Annotated[Path | None, typer.Option(help="detection cache folder")] = None,
) -> None:
    """Redo the thesis' experiments on the six synthetic scenarios, plus the two clutter ones
    for the tracker's static variant (all generated if absent)."""
    if system != "basso2012":
        raise ConfigError(f"reproduce {system!r}: only basso2012 is available")
    from rgbd_eval.atomic import write_json, write_text
    from rgbd_eval.datasets import scenarios_dir
    from rgbd_eval.reproduce import (
        CLUTTER,
        SCENARIOS,
        paper_values,
        render_markdown,
        reproduce_basso2012,
        to_json,
    )
    from rgbd_eval.sim import dataset_path, load_scenario, synthesize
    from rgbd_eval.sweep import default_jobs

    recordings = {}
    for name in (*SCENARIOS, *CLUTTER):
        path = dataset_path(name)
        if not path.exists():
            err_console.print(f"generating {path} ...")
            synthesize(load_scenario(scenarios_dir() / f"{name}.yaml"), path)
        recordings[name] = path
    out_dir = out or Path("runs") / f"reproduce-{time.strftime('%Y%m%d-%H%M%S')}"
    res = reproduce_basso2012(
        recordings,
        jobs=jobs if jobs is not None else default_jobs(),
        cache=cache,
        progress=lambda m: err_console.print(m),
    )
    text = render_markdown(res, paper_values())
    write_text(out_dir / "reproduce.md", text)
    write_json(out_dir / "reproduce.json", to_json(res))
    console.print(text, markup=False)
    console.print(f"written: {out_dir / 'reproduce.md'}, {out_dir / 'reproduce.json'}")
