"""CPU time of ``rgbd-eval`` commands that do little beyond starting, for source trees side by side.

    .venv/bin/python bench/cli_start.py [--ours SRC ...] [--runs 10] [--command "score --help" ...]

Each ``--ours`` source folder (``PYTHONPATH``; default: the package imported here) is first
byte-compiled, as pip does for an installed package, and run once untimed. Then each command
(default: ``score --help``, ``methods``, ``--help``) runs ``--runs`` times per source as
``python -m rgbd_eval ...``, the sources alternating, in a child process pinned to one CPU,
timed by its CPU time (user + system, ``getrusage(RUSAGE_CHILDREN)``: the machine may be
shared). Prints the median per command and source, and the ratio of each source to the first.
"""

from __future__ import annotations

import argparse
import compileall
import os
import shlex
import statistics
import sys

from bench.score_vs_trackeval import _cpu_of_child, _env, _package_folder

DEFAULT_COMMANDS = ("score --help", "methods", "--help")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ours", action="append", help="a source folder holding rgbd_eval/")
    parser.add_argument("--runs", type=int, default=10)
    parser.add_argument("--command", action="append", help="arguments of rgbd-eval, quoted")
    args = parser.parse_args()
    if args.runs < 1:
        parser.error("--runs must be at least 1")
    cpu = min(os.sched_getaffinity(0))
    variants = args.ours or [None]
    commands = args.command or list(DEFAULT_COMMANDS)
    for src in variants:
        compileall.compile_dir(_package_folder(src), quiet=1)
    for command in commands:
        argv = [sys.executable, "-m", "rgbd_eval", *shlex.split(command)]
        for src in variants:  # untimed: the first run pays for the page cache
            _cpu_of_child(argv, _env(src), cpu)
        times: dict[str | None, list[float]] = {src: [] for src in variants}
        for _ in range(args.runs):
            for src in variants:
                times[src].append(_cpu_of_child(argv, _env(src), cpu))
        first = statistics.median(times[variants[0]])
        for src in variants:
            median = statistics.median(times[src])
            print(
                f"rgbd-eval {command}: {src or 'installed'} {median:.3f} s "
                f"(median of {args.runs}, cpu {cpu}), {median / first:.2f}x the first"
            )
    print(f"load average {' '.join(f'{v:.2f}' for v in os.getloadavg())}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
