"""Run the real console entry point in-process and capture its exit code and output."""

from __future__ import annotations

import contextlib
import os
import resource
import signal
import subprocess
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

import rgbd_eval
from rgbd_eval.cli.main import main

#: Generous bound on one in-process command (the slowest case takes a few seconds).
TIME_LIMIT_S = 120
#: The package's folder on the path of a fresh interpreter: the same sources as in-process.
SRC = Path(rgbd_eval.__file__).resolve().parents[1]


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


@contextlib.contextmanager
def file_size_limit(limit: int | None) -> Iterator[None]:
    """RLIMIT_FSIZE set to ``limit`` bytes meanwhile (None: unchanged): longer writes fail
    with EFBIG, as on a full disk (Python ignores the SIGXFSZ that comes with it)."""
    if limit is None:
        yield
        return
    old = resource.getrlimit(resource.RLIMIT_FSIZE)
    resource.setrlimit(resource.RLIMIT_FSIZE, (limit, old[1]))
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_FSIZE, old)


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


def run_isolated(args: list[str], cwd: Path, max_file_bytes: int | None = None) -> Outcome:
    """``rgbd-eval ARGS`` in a fresh interpreter; a hang is killed after TIME_LIMIT_S (-9)."""
    env = dict(os.environ, PYTHONPATH=str(SRC))

    def limit() -> None:
        if max_file_bytes is not None:
            hard = resource.getrlimit(resource.RLIMIT_FSIZE)[1]
            resource.setrlimit(resource.RLIMIT_FSIZE, (max_file_bytes, hard))

    try:
        proc = subprocess.run(
            [sys.executable, "-m", "rgbd_eval", *args],
            cwd=cwd,
            env=env,
            capture_output=True,
            text=True,
            timeout=TIME_LIMIT_S,
            preexec_fn=limit,
        )
    except subprocess.TimeoutExpired as err:
        stderr = err.stderr.decode() if isinstance(err.stderr, bytes) else (err.stderr or "")
        return Outcome(-9, "", stderr + f"\n(killed: no answer within {TIME_LIMIT_S} s)")
    return Outcome(proc.returncode, proc.stdout, proc.stderr)


def leftovers(root: Path) -> list[Path]:
    """Temporary files or folders of ours left anywhere under ``root``."""
    return [p for p in root.rglob("*") if ".tmp-" in p.name]
