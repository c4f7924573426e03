"""The ``rgbd-eval`` application."""

from __future__ import annotations

import signal
import sys
from types import FrameType

import typer

try:  # typer >= 0.22 vendors click; older releases use the click package
    from typer._click import ClickException
except ImportError:  # pragma: no cover - depends on the installed typer
    from click import ClickException  # type: ignore[assignment,unused-ignore]

from rgbd_eval import __version__
from rgbd_eval.cli.annotate_cmd import annotate
from rgbd_eval.cli.bench_cmd import bench
from rgbd_eval.cli.common import Interrupted, interrupted_line, interruption, one_line
from rgbd_eval.cli.compare_cmd import compare
from rgbd_eval.cli.import_cmd import import_
from rgbd_eval.cli.inspect_cmd import inspect
from rgbd_eval.cli.methods_cmd import methods
from rgbd_eval.cli.reproduce_cmd import reproduce
from rgbd_eval.cli.run import run
from rgbd_eval.cli.score_cmd import score
from rgbd_eval.cli.sweep_cmd import sweep
from rgbd_eval.cli.synth_cmd import synth
from rgbd_eval.cli.view_cmd import view

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
app.command("import")(import_)
app.add_typer(annotate)
app.command("view")(view)


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


def _terminate(signum: int, frame: FrameType | None) -> None:
    """SIGTERM (and SIGHUP) unwind like Ctrl-C, so temporary outputs are removed."""
    raise Interrupted(signum)


def main() -> None:
    """Console-script entry point: usage errors as one line (exit 2), signals as 128 + number."""
    for signum in (signal.SIGTERM, signal.SIGHUP):
        signal.signal(signum, _terminate)
    if len(sys.argv) < 2:
        commands = ", ".join(c.name or "" for c in app.registered_commands)
        typer.echo(f"error: no command given; one of {commands} (see rgbd-eval --help)", err=True)
        sys.exit(2)
    try:
        code = app(standalone_mode=False)
    except ClickException as err:  # usage errors (exit 2): unknown option, bad number, ...
        message = one_line(err.format_message())
        ctx = getattr(err, "ctx", None)
        command = ctx.command_path if ctx is not None else "rgbd-eval"
        typer.echo(f"error: {message} (see {command} --help)", err=True)
        sys.exit(err.exit_code)
    except Interrupted as err:
        typer.echo(f"error: interrupted by signal {err.signum}", err=True)
        sys.exit(128 + err.signum)
    except typer.Abort:  # Ctrl-C (click turns KeyboardInterrupt into Abort)
        typer.echo("error: interrupted", err=True)
        sys.exit(128 + signal.SIGINT)
    except SystemError as err:  # a signal that surfaced through a C extension (see interruption)
        number = interruption(err)
        if number is None:
            raise
        typer.echo(interrupted_line(number), err=True)
        sys.exit(128 + number)
    sys.exit(code if isinstance(code, int) else 0)
