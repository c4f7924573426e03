"""Dataset names resolve to the synthetic recordings' locations."""

from __future__ import annotations

from pathlib import Path

import pytest

from rgbd_eval import datasets
from rgbd_eval.errors import InputError


def test_names_and_paths(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(datasets, "datasets_dir", lambda: tmp_path)
    (tmp_path / "generated").mkdir()
    (tmp_path / "generated" / "moving_complex.mcap").write_bytes(b"x")
    (tmp_path / "demo.mcap").write_bytes(b"x")
    assert datasets.resolve("moving_complex") == tmp_path / "generated" / "moving_complex.mcap"
    assert (
        datasets.resolve("thesis-moving-complex") == tmp_path / "generated" / "moving_complex.mcap"
    )
    assert datasets.resolve("demo") == tmp_path / "demo.mcap"
    assert datasets.resolve(str(tmp_path / "demo.mcap")) == tmp_path / "demo.mcap"
    with pytest.raises(InputError, match="not generated yet; run `make datasets`"):
        datasets.resolve("static_simple")
    with pytest.raises(InputError, match="not a dataset name"):
        datasets.resolve("nope")
