"""``rgbd-eval view REPORT_DIR``: a finished run as a Rerun recording, without running it again."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from rgbd_eval.cli.common import advance_callback, console, handle_errors, progress_bar


@handle_errors
def view(
    report_dir: Annotated[Path, typer.Argument(help="a run's output folder (with report.json)")],
    out: Annotated[
        Path | None,
        typer.Option("-o", "--out", help="the .rrd to write (default: <name>.rrd in REPORT_DIR)"),
    ] = None,
    sequence: Annotated[
        str | None, typer.Option(help="the sequence to show (default: every one)")
    ] = None,
) -> None:
    """Write a run's Rerun recording (.rrd) from its report folder and the recording."""
    from rgbd_eval.report.rerun import RrdOutput, load_run, require_rerun

    require_rerun()  # before reading anything
    views, config = load_run(report_dir, sequence)
    if out is not None and len(views) > 1:
        names = ", ".join(v.name for v in views)
        raise typer.BadParameter(
            f"names one file, the run has {len(views)} sequences ({names}); add --sequence",
            param_hint="'--out'",
        )
    outputs = [RrdOutput(out or report_dir / f"{v.name}.rrd", "view", [v.recording]) for v in views]
    for v, rrd in zip(views, outputs, strict=True):
        with progress_bar() as bar:
            task = bar.add_task(rrd.path.name, total=None)
            rrd.write(v, config, advance_callback(bar, task))
        console.print(f"{v.name}: rerun {rrd.path}")
