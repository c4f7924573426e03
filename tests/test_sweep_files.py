"""The sweep files in configs/sweeps/ name real keys and values that validate."""

from __future__ import annotations

from pathlib import Path

import pytest

from rgbd_eval.config import load_config, load_yaml, repo_root
from rgbd_eval.datasets import known_names
from rgbd_eval.sweep import SweepParam, expand_grid, point_configs

FILES = sorted((repo_root() / "configs" / "sweeps").glob("*.yaml"))


@pytest.mark.parametrize("path", FILES, ids=[p.stem for p in FILES])
def test_sweep_file_validates(path: Path) -> None:
    data = load_yaml(path)
    assert set(data) <= {"params", "datasets", "set"}
    params = [SweepParam(k, tuple(v)) for k, v in data["params"].items()]
    base = load_config(method="basso2012").model_dump(mode="json")
    assert point_configs(base, [], expand_grid(params))
    assert set(data["datasets"]) <= set(known_names())
