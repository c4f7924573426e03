"""SGBM stereo depth (satake2009): known disparities, baseline from P, stereo's failure modes."""

from __future__ import annotations

import numpy as np
import pytest

from rgbd_eval.detect import stereo
from rgbd_eval.types import CameraModel

W, H = 256, 192


def _texture(seed: int, shape: tuple[int, int] = (H, W + 128)) -> np.ndarray:
    """Blobby random texture (noise smoothed over 3x3), 8-bit."""
    rng = np.random.default_rng(seed)
    noise = rng.uniform(0, 255, size=(shape[0] + 2, shape[1] + 2))
    smooth = sum(noise[i : i + shape[0], j : j + shape[1]] for i in range(3) for j in range(3)) / 9
    return smooth.astype(np.uint8)


def _pair(background: np.ndarray, d_bg: int, patch: tuple[slice, slice] | None, d_fg: int):
    """A rectified pair: a left pixel (u, v) at disparity d is the right pixel (u - d, v)."""
    left = background[:, 64 : 64 + W].copy()
    right = background[:, 64 + d_bg : 64 + d_bg + W].copy()
    if patch is not None:
        fg = _texture(99)
        rows, cols = patch
        left[rows, cols] = fg[rows, cols]
        shifted = slice(cols.start - d_fg, cols.stop - d_fg)
        right[rows, shifted] = fg[rows, cols]
    return left, right


def test_baseline_from_the_right_cameras_projection() -> None:
    # Bumblebee2-like: fx = 430 px, B = 0.12 m -> Tx = -fx B = -51.6.
    P = np.array([[430.0, 0, 320, -51.6], [0, 430.0, 240, 0], [0, 0, 1, 0]])
    assert stereo.baseline_from_projection(P) == pytest.approx(0.12)
    with pytest.raises(ValueError, match="not the right camera"):
        stereo.baseline_from_projection(
            np.array([[430.0, 0, 320, 0], [0, 430, 240, 0], [0, 0, 1, 0]])
        )


def test_plane_and_box_at_known_disparities() -> None:
    # fx = 200 px, B = 0.12 m: fx B = 24 px m. Background at d = 8 px -> Z = 24 / 8 = 3.0 m;
    # a box at d = 24 px -> Z = 1.0 m.
    left, right = _pair(_texture(1), 8, (slice(60, 140), slice(110, 180)), 24)
    cam = CameraModel(W, H, 200.0, 200.0, W / 2 - 0.5, H / 2 - 0.5)
    out = stereo.stereo_depth(
        left, right, cam, 0.12, (W, H), stereo.make_matcher(stereo.SgbmParams())
    )
    z = out.depth
    inner_bg = z[20:50, 80:230]
    inner_fg = z[75:125, 125:165]
    assert np.isfinite(inner_bg).mean() > 0.95
    assert np.nanmedian(inner_bg) == pytest.approx(3.0, abs=0.02)
    assert np.isfinite(inner_fg).mean() > 0.95
    assert np.nanmedian(inner_fg) == pytest.approx(1.0, abs=0.01)
    # the left border has no match (disparity range runs off the right image): NaN there.
    assert np.isnan(z[:, :8]).all()


def test_textureless_surface_gives_no_depth() -> None:
    # A uniform grey wall: every disparity matches equally well; uniqueness rejects them.
    flat = np.full((H, W + 128), 128, dtype=np.uint8)
    left, right = _pair(flat, 8, None, 0)
    cam = CameraModel(W, H, 200.0, 200.0, W / 2 - 0.5, H / 2 - 0.5)
    z = stereo.stereo_depth(
        left, right, cam, 0.12, (W, H), stereo.make_matcher(stereo.SgbmParams())
    ).depth
    assert np.isfinite(z).mean() < 0.05


def test_processed_size_scales_the_camera() -> None:
    # A 2x larger input processed at (W, H): fx 400 -> 200 at the processed size, so the
    # same texture pair (disparity 16 px at full size, 8 px processed) still gives Z = 3 m.
    tex = _texture(3, (2 * H, 2 * W + 256))
    left = tex[:, 128 : 128 + 2 * W]
    right = tex[:, 128 + 16 : 128 + 16 + 2 * W]
    cam = CameraModel(2 * W, 2 * H, 400.0, 400.0, W - 0.5, H - 0.5)
    out = stereo.stereo_depth(
        left, right, cam, 0.12, (W, H), stereo.make_matcher(stereo.SgbmParams())
    )
    assert out.camera.fx == 200.0 and out.depth.shape == (H, W)
    assert np.nanmedian(out.depth[20:170, 80:230]) == pytest.approx(3.0, abs=0.03)


def test_bad_parameters_raise() -> None:
    with pytest.raises(ValueError, match="multiple of 16"):
        stereo.SgbmParams(num_disparities=40)
    with pytest.raises(ValueError, match="odd"):
        stereo.SgbmParams(block_size=4)
    with pytest.raises(ValueError, match="sizes differ"):
        stereo.disparity(
            np.zeros((4, 4), np.uint8),
            np.zeros((4, 5), np.uint8),
            (4, 4),
            stereo.make_matcher(stereo.SgbmParams()),
        )


def test_depth_in_one_pass_is_depth_from_disparity() -> None:
    # Every raw SGBM value (1/16 px; <= 0: no match) gives the float32 depth of
    # depth_from_disparity(disparity) bit for bit, NaN included.
    raw = np.arange(-32768, 32768, dtype=np.int32).astype(np.int16).reshape(256, 256)
    disp = raw.astype(np.float32) / 16.0
    disp[raw <= 0] = np.nan
    want = stereo.depth_from_disparity(disp, 214.8, 0.12)
    got = stereo._depth_kernel(raw, np.float32(214.8 * 0.12))
    assert got.tobytes() == want.tobytes()
