"""Shared CLI plumbing: error mapping, output console, option types."""

from __future__ import annotations

import functools
import signal
import sys
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, ParamSpec, TypeVar

import typer
from rich import box
from rich.console import Console
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TaskID,
    TextColumn,
    TimeRemainingColumn,
)
from rich.table import Table
from rich.text import Text

from rgbd_eval.errors import ConfigError, RgbdEvalError

if TYPE_CHECKING:
    from rgbd_eval.config import RunConfig
    from rgbd_eval.sweep import CacheMode

P = ParamSpec("P")
R = TypeVar("R")

#: Piped output is not cut at 80 columns: tables keep their topic names whole.
console = Console(highlight=False, width=None if sys.stdout.isatty() else 140)
err_console = Console(stderr=True, highlight=False)

SCHEMA_VERSION = 1


def metrics_table(title: str, header: Sequence[str], rows: Sequence[Sequence[str]]) -> Table:
    """The metrics table of ``run`` and ``score``, its cells plain text, the overall row bold.

    Rules under the header only and one space of padding: its 16 columns fit the
    140 columns of piped output on one line each.
    """
    table = Table(
        title=Text(title), title_justify="left", box=box.SIMPLE_HEAD, padding=(0, 0, 0, 1)
    )
    for i, head in enumerate(header):
        table.add_column(head, justify="left" if i == 0 else "right")
    for row in rows:
        table.add_row(*map(Text, row), style="bold" if row[0] == "overall" else None)
    return table


CLUSTER_HELP = (
    "where tasks run: local (one worker per usable CPU), local:N, or tcp://scheduler:8786"
)
#: ``--jobs N``, the option before Dask, kept hidden for old scripts: ``--cluster local:N``.
JobsOption = Annotated[int | None, typer.Option(hidden=True, help="same as --cluster local:N")]


def cluster_of(cluster: str, jobs: int | None) -> str:
    """``--cluster``, or ``local:N`` from the hidden ``--jobs N``."""
    if jobs is None:
        return cluster
    if cluster != "local":
        raise ConfigError("--jobs and --cluster: give one (--jobs N is --cluster local:N)")
    return f"local:{jobs}"


CACHE_MODE_HELP = (
    "shared: workers use the cache folder (same path everywhere); "
    "client: only this process does (workers share no disk)"
)


def parse_cache_mode(text: str) -> CacheMode:
    """``--cache-mode`` value -> CacheMode."""
    from rgbd_eval.sweep import CacheMode

    try:
        return CacheMode(text)
    except ValueError:
        raise ConfigError(f"--cache-mode {text!r}: expected shared or client") from None


def progress_bar() -> Progress:
    """A transient progress bar on stderr, shown only on a terminal."""
    return Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeRemainingColumn(),
        console=err_console,
        transient=True,
        disable=not err_console.is_terminal,
    )


def advance_callback(bar: Progress, task: TaskID) -> Callable[[int, int], None]:
    """A ``progress(done, total)`` callback that moves ``task`` of ``bar``."""

    def advance(done: int, total: int) -> None:
        bar.update(task, completed=done, total=total)

    return advance


#: Longest error line printed; longer messages (e.g. a value that expanded) are cut.
MAX_MESSAGE_CHARS = 600


class Interrupted(BaseException):
    """A termination signal (SIGTERM, SIGHUP) turned into an exception, as SIGINT is."""

    def __init__(self, signum: int) -> None:
        super().__init__(f"signal {signum}")
        self.signum = signum


def interruption(err: BaseException) -> int | None:
    """The signal behind ``err`` when it is an interruption, else None.

    A signal handled while a C extension runs Python code (numba's dispatcher loading its
    cache, say) can reach us as a ``SystemError`` ("returned a result with an exception
    set") whose cause is the :class:`Interrupted` or ``KeyboardInterrupt`` we raised.
    """
    seen: BaseException | None = err
    for _ in range(20):  # a cause chain is short; never loop on a cycle
        if seen is None:
            return None
        if isinstance(seen, Interrupted):
            return seen.signum
        if isinstance(seen, KeyboardInterrupt):
            return int(signal.SIGINT)
        if not isinstance(seen, SystemError):
            return None
        seen = seen.__cause__ or seen.__context__
    return None


def interrupted_line(signum: int) -> str:
    """The one error line of an interruption by ``signum``."""
    return "error: interrupted" + ("" if signum == signal.SIGINT else f" by signal {signum}")


def interrupted_exit(signum: int) -> typer.Exit:
    """Print the one line of an interruption; the exit to raise (128 + the signal)."""
    typer.echo(interrupted_line(signum), err=True)
    return typer.Exit(128 + signum)


def one_line(message: str) -> str:
    """``message`` on one line (whitespace runs collapsed) and at most MAX_MESSAGE_CHARS long."""
    text = " ".join(message.split())
    if len(text) > MAX_MESSAGE_CHARS:
        cut = len(text) - MAX_MESSAGE_CHARS
        text = f"{text[:MAX_MESSAGE_CHARS]}... ({cut} more characters)"
    return text


def handle_errors(func: Callable[P, R]) -> Callable[P, R]:
    """Turn the package's errors into one ``error:`` line on stderr and their exit code."""

    @functools.wraps(func)
    def wrapper(*args: P.args, **kwargs: P.kwargs) -> R:
        try:
            return func(*args, **kwargs)
        except RgbdEvalError as err:
            typer.echo(f"error: {one_line(str(err))}", err=True)
            raise typer.Exit(err.exit_code) from None
        except KeyboardInterrupt:  # outputs were removed on the way out (staged folders)
            raise interrupted_exit(signal.SIGINT) from None
        except Interrupted as err:
            raise interrupted_exit(err.signum) from None
        except SystemError as err:  # a signal that surfaced through a C extension
            signum = interruption(err)
            if signum is None:
                raise
            raise interrupted_exit(signum) from None

    return wrapper


#: ``--topic ROLE=/name`` (repeatable), on every command that reads recordings.
TopicOption = Annotated[
    list[str] | None,
    typer.Option(
        "--topic",
        help="topic of a stream role, e.g. depth=/camera/depth/image_raw (roles: colour, "
        "depth, depth_2..., thermal, left, right, <role>_info, odometry, ground_truth); repeatable",
    ),
]
ConfigOption = Annotated[Path | None, typer.Option("--config", help="YAML run config")]
SetOption = Annotated[
    list[str] | None, typer.Option("--set", help="KEY=VALUE config override, repeatable")
]
#: ``rgbd_eval.metrics.curves.DEFAULT_POINTS`` (not imported: the CLI loads metrics lazily).
DEFAULT_CURVE_POINTS = 20
CurveOption = Annotated[
    bool,
    typer.Option(
        "--curve", help="also score at each confidence threshold present: the threshold curve"
    ),
]
CurvePointsOption = Annotated[
    int,
    typer.Option("--curve-points", min=2, help="thresholds of --curve at most (quantiles beyond)"),
]


def topic_overrides(items: list[str] | None) -> list[str]:
    """``--topic ROLE=/name`` values as ``--set io.topics.ROLE=/name`` overrides."""
    out = []
    for item in items or []:
        role, sep, topic = item.partition("=")
        if not sep or not role.strip() or not topic.strip():
            raise ConfigError(f"--topic {item!r}: expected ROLE=/topic, e.g. depth=/camera/depth")
        out.append(f"io.topics.{role.strip()}={topic.strip()}")
    return out


def with_threshold(config: RunConfig, threshold: float | None) -> RunConfig:
    """``config`` with ``--threshold`` applied: a usage error outside its gating's range.

    The range depends on the gating, which the method or config file may set: the option
    is applied after the config (``--gating`` included) is built.
    """
    from rgbd_eval.config import threshold_problem

    if threshold is None:
        return config
    problem = threshold_problem(config.evaluation.gating, threshold)
    if problem is not None:
        raise typer.BadParameter(problem, param_hint="'--threshold'")
    evaluation = config.evaluation.model_copy(update={"threshold": threshold})
    return config.model_copy(update={"evaluation": evaluation})


def jsonable(value: Any) -> Any:
    """Dataclasses, tuples and enums -> plain JSON values."""
    import dataclasses
    import enum

    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: jsonable(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, Mapping):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple | set):
        return [jsonable(v) for v in value]
    if isinstance(value, enum.Enum):
        return value.value
    if isinstance(value, float) and value != value:  # NaN
        return None
    return value
