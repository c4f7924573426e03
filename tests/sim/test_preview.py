"""The contact sheet written by ``rgbd-eval synth --preview``."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from rgbd_eval.errors import OutputError
from rgbd_eval.outdir import MANIFEST
from rgbd_eval.sim.preview import contact_sheet, default_frames, depth_colour, write_preview
from rgbd_eval.sim.scenario import Scenario


def test_write_preview(tmp_path: Path, tiny: Scenario) -> None:
    out = write_preview(tiny, tmp_path / "sub" / "sheet.png", seed=0, frames=[0, 2, 5], columns=2)
    img = cv2.imread(str(out))
    assert img is not None
    # 3 tiles of 160x120 in 2 columns -> 2 rows: 320 x 240
    assert img.shape == (240, 320, 3)
    assert not np.any(img[120:, 160:])  # the missing fourth tile stays black
    # No temporary file left; the folder's manifest records the sheet as synth's.
    assert sorted(p.name for p in (tmp_path / "sub").iterdir()) == [MANIFEST, "sheet.png"]
    write_preview(tiny, out, seed=1, frames=[0])  # synth's own preview: replaced
    out.write_bytes(b"edited")
    with pytest.raises(OutputError, match="changed since"):
        write_preview(tiny, out, seed=0, frames=[0])
    assert out.read_bytes() == b"edited"


def test_helpers() -> None:
    assert default_frames(750, 6) == [0, 150, 300, 449, 599, 749]
    assert default_frames(1, 6) == [0]
    d = np.array([[np.nan, 1.0]], dtype=np.float32)
    assert depth_colour(d)[0, 0].tolist() == [0, 0, 0]
    tiles = [np.full((2, 3, 3), k, dtype=np.uint8) for k in (1, 2, 3)]
    sheet = contact_sheet(tiles, 3)
    assert sheet.shape == (2, 9, 3) and sheet[0, 8, 0] == 3
    with pytest.raises(ValueError, match="columns=0"):
        contact_sheet(tiles, 0)
    with pytest.raises(ValueError, match="count=0"):
        default_frames(10, 0)
