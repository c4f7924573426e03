"""Every supported image encoding, decoded from hand-built messages."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from rgbd_eval.io import images


def image_msg(
    arr: np.ndarray, encoding: str, big_endian: bool = False, pad: int = 0
) -> SimpleNamespace:
    """A sensor_msgs/Image look-alike with optional row padding (``pad`` bytes per row)."""
    h, w = arr.shape[:2]
    dtype = arr.dtype.newbyteorder(">" if big_endian else "<")
    rows = np.ascontiguousarray(arr.astype(dtype)).view(np.uint8).reshape(h, -1)
    padded = np.concatenate([rows, np.full((h, pad), 0xAB, np.uint8)], axis=1)
    return SimpleNamespace(
        height=h,
        width=w,
        encoding=encoding,
        is_bigendian=int(big_endian),
        step=padded.shape[1],
        data=padded.reshape(-1),
    )


RGB = np.arange(4 * 5 * 3, dtype=np.uint8).reshape(4, 5, 3)


@pytest.mark.parametrize("pad", [0, 3])
def test_rgb8_bgr8_mono8(pad: int) -> None:
    np.testing.assert_array_equal(images.decode_color(image_msg(RGB, "rgb8", pad=pad)), RGB)
    np.testing.assert_array_equal(
        images.decode_color(image_msg(RGB[..., ::-1], "bgr8", pad=pad)), RGB
    )
    rgba = np.concatenate([RGB, np.full((4, 5, 1), 255, np.uint8)], axis=2)
    np.testing.assert_array_equal(images.decode_color(image_msg(rgba, "rgba8", pad=pad)), RGB)
    bgra = np.concatenate([RGB[..., ::-1], np.full((4, 5, 1), 255, np.uint8)], axis=2)
    np.testing.assert_array_equal(images.decode_color(image_msg(bgra, "bgra8", pad=pad)), RGB)
    mono = RGB[..., 0]
    out = images.decode_color(image_msg(mono, "mono8", pad=pad))
    assert out.shape == (4, 5, 3) and all(np.array_equal(out[..., c], mono) for c in range(3))


def test_jpeg_decodes_to_rgb_order() -> None:
    # Flat colour patches survive jpeg almost exactly; red must stay in channel 0.
    rgb = np.zeros((16, 16, 3), np.uint8)
    rgb[..., 0] = 200
    rgb[..., 2] = 30
    out = images.decode_color(SimpleNamespace(**images.encode_color_jpeg(rgb)))
    assert out.shape == (16, 16, 3) and out.flags.c_contiguous
    np.testing.assert_allclose(out.mean(axis=(0, 1)), [200, 0, 30], atol=3)


@pytest.mark.parametrize("big_endian", [False, True])
@pytest.mark.parametrize("pad", [0, 2])
def test_16uc1_millimetres(big_endian: bool, pad: int) -> None:
    mm = np.array([[0, 1000, 65535], [1500, 2, 7999]], dtype=np.uint16)
    depth = images.decode_depth(image_msg(mm, "16UC1", big_endian, pad))
    expected = np.array([[np.nan, 1.0, 65.535], [1.5, 0.002, 7.999]], dtype=np.float32)
    np.testing.assert_allclose(depth, expected, rtol=1e-6)
    assert depth.dtype == np.float32


@pytest.mark.parametrize("big_endian", [False, True])
def test_32fc1_metres(big_endian: bool) -> None:
    m = np.array([[np.nan, 1.25, 0.0], [np.inf, 3.5, -1.0]], dtype=np.float32)
    depth = images.decode_depth(image_msg(m, "32FC1", big_endian, pad=4))
    # NaN, inf, zero and negative depths are all invalid.
    np.testing.assert_array_equal(np.isnan(depth), [[True, False, True], [True, False, True]])
    assert depth[0, 1] == 1.25 and depth[1, 1] == 3.5


def test_unsupported_encoding_is_named() -> None:
    with pytest.raises(images.ImageFormatError, match="'yuv422'"):
        images.decode_color(image_msg(RGB[..., :2].copy(), "yuv422"))
    with pytest.raises(images.ImageFormatError, match="expected a depth encoding"):
        images.decode_depth(image_msg(RGB, "rgb8"))


def test_truncated_data_is_reported() -> None:
    msg = image_msg(RGB, "rgb8")
    msg.data = msg.data[:-1]
    with pytest.raises(images.ImageFormatError, match="bytes"):
        images.decode_color(msg)


def test_compressed_depth_header_and_payload() -> None:
    depth = np.array([[1.0, np.nan], [2.345, 9.5]], dtype=np.float32)
    fields = images.encode_depth_compressed(depth, "16UC1")
    assert fields["format"] == "16UC1; compressedDepth png"
    # 12-byte header (int32 format, float32 A, float32 B), then the PNG signature.
    assert bytes(fields["data"][12:16]) == b"\x89PNG"
    out = images.decode_depth(SimpleNamespace(**fields))
    np.testing.assert_allclose(out, [[1.0, np.nan], [2.345, 9.5]], atol=5e-4)
    bad = SimpleNamespace(format="16UC1; compressedDepth png", data=fields["data"][:10])
    with pytest.raises(images.ImageFormatError, match="12-byte header"):
        images.decode_depth(bad)


def test_a_compressed_header_claiming_too_many_pixels_is_not_decoded() -> None:
    from tests.fuzz.corpus import png_claiming

    bomb = SimpleNamespace(format="png", data=np.frombuffer(png_claiming(30000, 30000), np.uint8))
    with pytest.raises(images.ImageFormatError, match="declares 30000x30000 pixels"):
        images.decode_color(bomb)
    jpeg = images.encode_color_jpeg(np.zeros((48, 64, 3), np.uint8))["data"]
    assert images.declared_size(jpeg.tobytes()) == (64, 48)
