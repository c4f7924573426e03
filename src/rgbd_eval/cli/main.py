"""The ``rgbd-eval`` application."""

from __future__ import annotations

import importlib
import signal
import sys
from collections.abc import Iterable
from types import FrameType
from typing import Any

import typer

try:  # typer >= 0.22 vendors click; older releases use the click package
    from typer._click import ClickException
except ImportError:  # pragma: no cover - depends on the installed typer
    from click import ClickException  # type: ignore[assignment,unused-ignore]

from rgbd_eval import __version__
from rgbd_eval.cli.common import Interrupted, interrupted_line, interruption, one_line

#: Every command: name, module, attribute and how it is registered (``annotate`` is a group
#: of subcommands). A command's module is imported only when that command is built, so
#: ``rgbd-eval score`` does not pay for the imports of ``run``, ``view`` or ``import``.
_COMMANDS: tuple[tuple[str, str, str, dict[str, Any]], ...] = (
    ("run", "rgbd_eval.cli.run", "run", {}),
    # Negative sweep values (`sweep tracker.min_confidence -3 -2`) are values, not options.
    ("sweep", "rgbd_eval.cli.sweep_cmd", "sweep", {"ignore_unknown_options": True}),
    ("inspect", "rgbd_eval.cli.inspect_cmd", "inspect", {}),
    ("compare", "rgbd_eval.cli.compare_cmd", "compare", {}),
    ("synth", "rgbd_eval.cli.synth_cmd", "synth", {}),
    ("reproduce", "rgbd_eval.cli.reproduce_cmd", "reproduce", {}),
    ("bench", "rgbd_eval.cli.bench_cmd", "bench", {}),
    ("score", "rgbd_eval.cli.score_cmd", "score", {}),
    ("methods", "rgbd_eval.cli.methods_cmd", "methods", {}),
    ("import", "rgbd_eval.cli.import_cmd", "import_", {}),
    ("annotate", "rgbd_eval.cli.annotate_cmd", "annotate", {}),
    ("view", "rgbd_eval.cli.view_cmd", "view", {}),
)
COMMAND_NAMES = tuple(name for name, *_ in _COMMANDS)


def _version(value: bool) -> None:
    if value:
        typer.echo(f"rgbd-eval {__version__}")
        raise typer.Exit(0)


def _root(
    version: bool = typer.Option(
        False, "--version", callback=_version, is_eager=True, help="print the version"
    ),
) -> None:
    """Batch evaluation of RGB-D people trackers on recorded robot data."""


def build_app(names: Iterable[str] = COMMAND_NAMES) -> typer.Typer:
    """The application with the commands ``names`` (default: all, in the order of --help)."""
    wanted = set(names)
    app = typer.Typer(
        name="rgbd-eval",
        help="Batch evaluation of RGB-D people trackers on recorded robot data.",
        no_args_is_help=True,
        add_completion=False,
        pretty_exceptions_enable=False,
    )
    app.callback()(_root)
    for name, module, attribute, settings in _COMMANDS:
        if name not in wanted:
            continue
        command = getattr(importlib.import_module(module), attribute)
        if isinstance(command, typer.Typer):
            app.add_typer(command)
        else:
            app.command(name, context_settings=settings or None)(command)
    return app


def __getattr__(name: str) -> Any:
    """``app``: the application with every command (built on first use, for tests and
    embedding; the console script builds only the command it runs)."""
    if name == "app":
        app = build_app()
        globals()["app"] = app
        return app
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _terminate(signum: int, frame: FrameType | None) -> None:
    """SIGTERM (and SIGHUP) unwind like Ctrl-C, so temporary outputs are removed."""
    raise Interrupted(signum)


def main() -> None:
    """Console-script entry point: usage errors as one line (exit 2), signals as 128 + number."""
    for signum in (signal.SIGTERM, signal.SIGHUP):
        signal.signal(signum, _terminate)
    if len(sys.argv) < 2:
        commands = ", ".join(COMMAND_NAMES)
        typer.echo(f"error: no command given; one of {commands} (see rgbd-eval --help)", err=True)
        sys.exit(2)
    # Only the command named is built (and its module imported); anything else (--help,
    # --version, a mistyped command) gets every command, so help lists them all.
    app = build_app([sys.argv[1]] if sys.argv[1] in COMMAND_NAMES else COMMAND_NAMES)
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
