"""bench/peers/speed_ratio.py reads a user's organised PCD (ascii, binary, binary_compressed)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from bench.peers.speed_ratio import (
    PcdError,
    fit_intrinsics,
    frame_of_pcd,
    lzf_decompress,
    read_pcd,
)

HEADER = (
    "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F F\n"
    "COUNT 1 1 1 1\nWIDTH 3\nHEIGHT 2\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 6\nDATA {}\n"
)


def _cloud() -> tuple[np.ndarray, np.ndarray]:
    """A 3x2 pinhole cloud (fx 500, fy 400, cx 1, cy 0.5) and its colours."""
    v, u = np.mgrid[0:2, 0:3].astype(np.float32)
    z = np.array([[2.0, 3.0, 4.0], [5.0, 6.0, 7.0]], dtype=np.float32)
    xyz = np.stack([(u - 1.0) * z / 500.0, (v - 0.5) * z / 400.0, z], axis=-1)
    rgb = np.arange(18, dtype=np.uint8).reshape(2, 3, 3) * 10
    return xyz.astype(np.float32), rgb


def _packed(rgb: np.ndarray) -> np.ndarray:
    c = rgb.reshape(-1, 3).astype(np.uint32)
    return ((c[:, 0] << 16) | (c[:, 1] << 8) | c[:, 2]).view("<f4")


def test_binary_and_ascii_read_back(tmp_path: Path) -> None:
    xyz, rgb = _cloud()
    rec = np.empty(6, dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("rgb", "<f4")])
    flat = xyz.reshape(-1, 3)
    rec["x"], rec["y"], rec["z"], rec["rgb"] = flat[:, 0], flat[:, 1], flat[:, 2], _packed(rgb)
    binary = tmp_path / "b.pcd"
    binary.write_bytes(HEADER.format("binary").encode() + rec.tobytes())
    bits = rec["rgb"].view("<u4")  # PCL writes a packed colour as its integer bits
    lines = [
        f"{float(r['x'])!r} {float(r['y'])!r} {float(r['z'])!r} {b}"
        for r, b in zip(rec, bits, strict=True)
    ]
    ascii_ = tmp_path / "a.pcd"
    ascii_.write_text(HEADER.format("ascii") + "\n".join(lines) + "\n")
    for path in (binary, ascii_):
        got_xyz, got_rgb = read_pcd(path)
        np.testing.assert_allclose(got_xyz, xyz, rtol=1e-6)
        np.testing.assert_array_equal(got_rgb, rgb)
    frame = frame_of_pcd(binary, None)
    cam = frame.depth_camera
    assert (cam.fx, cam.fy, cam.cx, cam.cy) == pytest.approx((500, 400, 1, 0.5), rel=1e-5)
    np.testing.assert_allclose(frame.depth, xyz[..., 2])


def test_lzf_literal_and_overlapping_reference() -> None:
    # "abc" as a literal run, then 5 bytes from 3 back (overlapping what it writes).
    assert lzf_decompress(bytes([2]) + b"abc" + bytes([0x60, 0x02]), 8) == b"abcabcab"
    with pytest.raises(PcdError, match="header says 9"):
        lzf_decompress(bytes([2]) + b"abc" + bytes([0x60, 0x02]), 9)


def test_unorganised_or_colourless_refused(tmp_path: Path) -> None:
    flat = tmp_path / "flat.pcd"
    flat.write_text(HEADER.format("ascii").replace("WIDTH 3\nHEIGHT 2", "WIDTH 6\nHEIGHT 1"))
    with pytest.raises(PcdError, match="organised"):
        read_pcd(flat)
    grey = tmp_path / "grey.pcd"
    grey.write_text(HEADER.format("ascii").replace(" rgb\n", " intensity\n"))
    with pytest.raises(PcdError, match="rgb or rgba"):
        read_pcd(grey)
    with pytest.raises(PcdError, match="positive depth"):
        fit_intrinsics(np.zeros((2, 3, 3), dtype=np.float32))
