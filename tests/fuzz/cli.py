"""Run the real console entry point in-process and capture its exit code and output."""

from __future__ import annotations

import signal
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

from rgbd_eval.cli.main import main

#: Generous bound on one in-process command (the slowest case takes a few seconds).
TIME_LIMIT_S = 120


class HungError(Exception):
    """The command did not finish within TIME_LIMIT_S."""


def _hung(signum: int, frame: object) -> None:
    raise HungError(f"no answer within {TIME_LIMIT_S} s")


@dataclass(frozen=True)
class Outcome:
    code: int
    stdout: str
    stderr: str

    @property
    def error_lines(self) -> list[str]:
        return [line for line in self.stderr.splitlines() if line.strip()]


def run_cli(args: list[str], capsys: pytest.CaptureFixture[str]) -> Outcome:
    """``rgbd-eval ARGS`` through :func:`rgbd_eval.cli.main.main` (sys.exit caught)."""
    handlers = {s: signal.getsignal(s) for s in (signal.SIGTERM, signal.SIGHUP)}
    argv = sys.argv
    sys.argv = ["rgbd-eval", *args]
    capsys.readouterr()
    previous_alarm = signal.signal(signal.SIGALRM, _hung)
    signal.alarm(TIME_LIMIT_S)  # a hang (e.g. opening a named pipe) fails instead of blocking
    try:
        with pytest.raises(SystemExit) as exited:
            main()
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous_alarm)
        sys.argv = argv
        for s, h in handlers.items():
            signal.signal(s, h)
    out = capsys.readouterr()
    code = exited.value.code
    return Outcome(code if isinstance(code, int) else 1, out.out, out.err)


def leftovers(root: Path) -> list[Path]:
    """Temporary files or folders of ours left anywhere under ``root``."""
    return [p for p in root.rglob("*") if ".tmp-" in p.name]
