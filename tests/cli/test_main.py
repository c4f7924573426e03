"""The console script builds only the command it runs; ``app`` has them all."""

from __future__ import annotations

import subprocess
import sys

import typer.main

from rgbd_eval.cli import main as cli_main

# Runs `rgbd-eval methods` through main() and lists which command modules were imported.
_PROBE = """
import sys
sys.argv = ["rgbd-eval", "methods"]
from rgbd_eval.cli.main import main
try:
    main()
except SystemExit as err:
    code = err.code
print(code, sorted(m for m in sys.modules if m.startswith("rgbd_eval.cli.") and m.endswith(("_cmd", ".run"))))
"""


def test_a_command_imports_only_its_own_module() -> None:
    done = subprocess.run(
        [sys.executable, "-c", _PROBE], capture_output=True, text=True, check=True
    )
    last = done.stdout.strip().splitlines()[-1]
    assert last == "0 ['rgbd_eval.cli.methods_cmd']"


def test_app_has_every_command() -> None:
    group = typer.main.get_group(cli_main.app)
    assert sorted(group.commands) == sorted(cli_main.COMMAND_NAMES)


def test_unknown_command_gets_the_full_listing() -> None:
    done = subprocess.run(
        [sys.executable, "-m", "rgbd_eval", "scor"], capture_output=True, text=True
    )
    assert done.returncode == 2
    assert "No such command 'scor'. Did you mean 'score'?" in done.stderr
