"""A stereo pair's right CameraInfo keeps its baseline: P[0, 3] = Tx = -fx B round-trips."""

from __future__ import annotations

from pathlib import Path

import pytest

from rgbd_eval.detect.stereo import baseline_of
from rgbd_eval.io.decode import camera_model_from_info
from rgbd_eval.io.writer import RecordingWriter
from rgbd_eval.types import CameraModel

# Bumblebee2-like right camera at 1024x768: fx = 512 / tan(50 deg) = 429.62 px, B = 0.12 m,
# Tx = -fx B = -51.555.
FX = 512 / 1.19175359259421
RIGHT = CameraModel(1024, 768, FX, FX, 511.5, 383.5, (0.0,) * 5, "right_optical", tx=-FX * 0.12)


@pytest.mark.parametrize("container", ["ros1", "mcap"])
def test_tx_round_trips(tmp_path: Path, container: str) -> None:
    with RecordingWriter(tmp_path / f"pair.{container}", container) as w:  # type: ignore[arg-type]
        back = camera_model_from_info(w.camera_info(0, RIGHT, "/right/camera_info"))
    assert back.tx == pytest.approx(-FX * 0.12)
    assert baseline_of(back) == pytest.approx(0.12)


def test_scaling_keeps_the_baseline() -> None:
    # 1024 -> 512: fx and Tx halve, B = -Tx / fx stays 0.12 m.
    half = RIGHT.scaled(512, 384)
    assert half.tx == pytest.approx(RIGHT.tx / 2)
    assert baseline_of(half) == pytest.approx(0.12)


def test_a_left_camera_has_no_baseline() -> None:
    with pytest.raises(ValueError, match="not the right camera"):
        baseline_of(CameraModel(64, 48, 50.0, 50.0, 31.5, 23.5))
