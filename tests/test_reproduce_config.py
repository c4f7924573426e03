"""Figure 7.9 reads the cluster sizes from the config (issue 21: 30 and 600 were hard-coded)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

import rgbd_eval.methods.basso2012.experiments as reproduce
from rgbd_eval.config import RunConfig, load_config
from tests.io.conftest import Spec, write_recording


class _Idle:
    """Stands in for the detector: Figure 7.9's timing loop only needs detect()."""

    def __init__(self) -> None:
        self.last_timings: dict[str, float] = {}

    def detect(self, frame: object) -> list[object]:
        return []


def test_figure_7_9_scales_the_configured_cluster_sizes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    seen: dict[float, tuple[int, int]] = {}

    def capture(cfg: RunConfig) -> _Idle:
        det: Any = cfg.detector
        seen[round(det.voxel_size, 3)] = (det.min_points, det.max_points)
        return _Idle()

    monkeypatch.setattr(reproduce, "create_detector", capture)
    rec = write_recording(tmp_path / "rec.mcap", "mcap", Spec(n=2))
    base = load_config(
        method="basso2012", overrides=["detector.min_points=40", "detector.max_points=800"]
    ).model_dump(mode="json")
    reproduce.voxel_timing(rec, base)
    # Sizes scale with the voxel area, (0.06 / v)^2 of the configured 40 and 800 at 0.06 m:
    # 0.04 m: x2.25 -> 90, 1800; 0.12 m: x0.25 -> 10, 200; 0.15 m: x0.16 -> 6.4 -> 6, 128.
    assert seen[0.06] == (40, 800)
    assert seen[0.04] == (90, 1800)
    assert seen[0.12] == (10, 200)
    assert seen[0.15] == (6, 128)
    assert len(seen) == len(reproduce.VOXEL_SIZES)
