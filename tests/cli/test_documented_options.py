"""Every option that the README or an error message tells a user to type exists.

An error that says "choose one with --rgb-topic" when no command has that option
sends the user nowhere; so does a README example with a stale flag.
"""

from __future__ import annotations

import re
from pathlib import Path

import typer.main

from rgbd_eval.cli.main import app

ROOT = Path(__file__).resolve().parents[2]
OPTION = re.compile(r"(?<![\w-])--[a-z][a-z0-9-]+")
#: Flags that belong to other programs quoted in the README (pip, pytest, dask, rerun, chromium).
FOREIGN = {"--no-deps", "--upgrade", "--strict-markers", "--nworkers", "--nthreads"}
FOREIGN |= {"--headless", "--web-viewer", "--use-angle", "--enable-unsafe-swiftshader"}
FOREIGN |= {"--pcd", "--ours"}  # bench/peers/speed_ratio.py, bench/score_vs_trackeval.py
FOREIGN |= {"--people", "--sensitivity"}  # tools/realism/measure.py


def _options() -> dict[str, set[str]]:
    group = typer.main.get_command(app)
    out = {"": {"--version", "--help"}}
    for name, command in group.commands.items():  # type: ignore[attr-defined]
        out[name] = {opt for p in command.params for opt in p.opts} | {"--help"}
        for sub, subcommand in getattr(command, "commands", {}).items():  # `annotate export`
            out[f"{name} {sub}"] = {opt for p in subcommand.params for opt in p.opts} | {"--help"}
    return out


def test_readme_examples_use_existing_options() -> None:
    options = _options()
    everything = set().union(*options.values())
    for line in (ROOT / "README.md").read_text().splitlines():
        words = line.strip().split()
        if len(words) > 1 and words[0] == "rgbd-eval" and words[1] in options:
            command = " ".join(words[1:3]) if " ".join(words[1:3]) in options else words[1]
            for flag in OPTION.findall(line.split("#")[0]):
                assert flag in options[command], f"README: `{line.strip()}`: {flag} unknown"
    for flag in set(OPTION.findall((ROOT / "README.md").read_text())) - FOREIGN:
        assert flag in everything, f"README names {flag}, which no command accepts"


def test_error_messages_name_existing_options() -> None:
    everything = set().union(*_options().values())
    for path in (ROOT / "src" / "rgbd_eval").rglob("*.py"):
        for flag in set(OPTION.findall(path.read_text())):
            assert flag in everything, f"{path.relative_to(ROOT)} names {flag}: no command has it"
