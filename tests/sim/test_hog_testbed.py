"""The HOG test bed: each class holds what it promises; the blur is a line of the motion's length."""

from __future__ import annotations

import numpy as np
import pytest

from .hog_testbed import CLASSES, OCCLUDED_RANGE, motion_blur, windows


def test_motion_blur_spreads_a_point_along_the_motion() -> None:
    rgb = np.zeros((9, 15, 3), np.uint8)
    rgb[4, 7] = 250
    mask = np.zeros((9, 15), bool)
    mask[4, 7] = True
    out = motion_blur(rgb, mask, 4.0, 0.0)
    # a 4 px motion: the kernel is a line of 5 taps (0..4 px), each 1/5: 250 / 5 = 50 per pixel,
    # on one row, and the total brightness is kept
    row = out[4, :, 0].astype(int)
    assert sorted(row[row > 0].tolist()) == [50] * 5
    assert int(out[..., 0].sum()) == 250
    assert not out[:4].any() and not out[5:].any()
    # no motion: unchanged
    assert np.array_equal(motion_blur(rgb, mask, 0.3, 0.2), rgb)


def test_blur_only_touches_the_mask_grown_by_the_motion() -> None:
    rng = np.random.default_rng(0)
    rgb = rng.integers(0, 255, (40, 40, 3), dtype=np.uint8)
    mask = np.zeros((40, 40), bool)
    mask[18:22, 18:22] = True
    out = motion_blur(rgb, mask, 0.0, 3.0)
    changed = np.any(out != rgb, axis=2)
    # 3 px motion: a 7x7 dilation grows the 4x4 mask to rows/cols 15..24
    assert changed[18:22, 18:22].any()
    assert not changed[:15].any() and not changed[25:].any()
    assert not changed[:, :15].any() and not changed[:, 25:].any()


@pytest.mark.slow
@pytest.mark.parametrize("cls", CLASSES)
def test_every_class_yields_the_windows_it_promises(cls: str) -> None:
    found = list(windows(cls, 15))
    assert found, cls
    for w in found:
        inside = w.box.left >= 0 and w.box.top >= 0 and w.box.right <= 640 and w.box.bottom <= 480
        if cls == "border":
            assert not inside and w.visible > 0.0
        elif cls == "occluded":
            assert inside and OCCLUDED_RANGE[0] <= w.visible <= OCCLUDED_RANGE[1]
        else:
            assert inside
        if cls == "objects":
            assert w.cls.startswith("object:")
        else:
            assert w.cls == cls
