"""The ``rgbd-eval`` application."""

from __future__ import annotations

import typer

from rgbd_eval import __version__
from rgbd_eval.cli.bench_cmd import bench
from rgbd_eval.cli.compare_cmd import compare
from rgbd_eval.cli.inspect_cmd import inspect
from rgbd_eval.cli.methods_cmd import methods
from rgbd_eval.cli.reproduce_cmd import reproduce
from rgbd_eval.cli.run import run
from rgbd_eval.cli.score_cmd import score
from rgbd_eval.cli.sweep_cmd import sweep
from rgbd_eval.cli.synth_cmd import synth

app = typer.Typer(
    name="rgbd-eval",
    help="Batch evaluation of RGB-D people trackers on recorded robot data.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
app.command("run")(run)
# Negative sweep values (`sweep tracker.min_confidence -3 -2`) are values, not options.
app.command("sweep", context_settings={"ignore_unknown_options": True})(sweep)
app.command("inspect")(inspect)
app.command("compare")(compare)
app.command("synth")(synth)
app.command("reproduce")(reproduce)
app.command("bench")(bench)
app.command("score")(score)
app.command("methods")(methods)


def _version(value: bool) -> None:
    if value:
        typer.echo(f"rgbd-eval {__version__}")
        raise typer.Exit(0)


@app.callback()
def _root(
    version: bool = typer.Option(
        False, "--version", callback=_version, is_eager=True, help="print the version"
    ),
) -> None:
    """Batch evaluation of RGB-D people trackers on recorded robot data."""


def main() -> None:
    """Console-script entry point."""
    app()
