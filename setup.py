"""Build hook: ship ``configs/`` (methods, papers, scenarios, sweeps, baselines) inside the package.

The checkout keeps ``configs/`` at its root, where users and the README find it; a
wheel has no checkout, so ``build_py`` copies the folder to ``rgbd_eval/configs``,
where :func:`rgbd_eval.config.config_dir` looks when not running from a checkout.
Everything else is in ``pyproject.toml``.
"""

from __future__ import annotations

import shutil
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py


class BuildPyWithConfigs(build_py):
    def run(self) -> None:
        super().run()
        source = Path(__file__).resolve().parent / "configs"
        target = Path(self.build_lib) / "rgbd_eval" / "configs"
        if target.exists():
            shutil.rmtree(target)
        shutil.copytree(source, target)


setup(cmdclass={"build_py": BuildPyWithConfigs})
