"""Image message decoding and encoding (``sensor_msgs/Image`` and ``CompressedImage``).

Decoded colour images are ``HxWx3 uint8`` RGB; decoded depth is ``float32`` metres
with NaN for invalid pixels (0 in the 16-bit millimetre encodings).

``compressedDepth`` (the ``compressed_depth_image_transport`` format) is a 12-byte
header ``int32 format, float32 depthQuantA, float32 depthQuantB`` followed by a PNG.
16UC1 depth is stored as is; 32FC1 depth is stored as quantised inverse depth
``q = A / d + B`` (0 = invalid) and restored as ``d = A / (q - B)``.
"""

from __future__ import annotations

import struct
from typing import Any

import cv2
import numpy as np
from numpy.typing import NDArray

COLOR_ENCODINGS = ("rgb8", "bgr8", "rgba8", "bgra8", "mono8")
DEPTH_ENCODINGS = ("16UC1", "mono16", "32FC1")
#: Single-channel encodings of thermal and grey cameras (raw counts).
MONO_ENCODINGS = ("mono8", "mono16", "16UC1")
_COMPRESSED_DEPTH_HEADER = struct.Struct("<iff")
#: Quantisation of 32FC1 compressedDepth: depth_quantization 100, depth_max 10 m.
_DEPTH_Z0 = 100.0
_DEPTH_MAX = 10.0
_QUANT_A = _DEPTH_Z0 * (_DEPTH_Z0 + 1.0)
_QUANT_B = 1.0 - _QUANT_A / _DEPTH_MAX


#: OpenCV conversions to RGB of the colour encodings that are not RGB already.
_TO_RGB = {
    "bgr8": cv2.COLOR_BGR2RGB,
    "bgra8": cv2.COLOR_BGRA2RGB,
    "mono8": cv2.COLOR_GRAY2RGB,
}


class ImageFormatError(ValueError):
    """An image message cannot be decoded; the reader adds file and topic."""


#: Most pixels a compressed image may declare before it is decoded (an 8K frame has 33
#: million): the decoder allocates what the header says, and a few bytes can say 30000^2.
MAX_COMPRESSED_PIXELS = 1 << 25
_PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
#: JPEG start-of-frame markers (baseline, progressive, ...): height and width follow.
_JPEG_SOF = frozenset(
    {0xC0, 0xC1, 0xC2, 0xC3, 0xC5, 0xC6, 0xC7, 0xC9, 0xCA, 0xCB, 0xCD, 0xCE, 0xCF}
)


def declared_size(data: bytes) -> tuple[int, int] | None:
    """``(width, height)`` a PNG or JPEG stream declares in its header (None: not found)."""
    if data.startswith(_PNG_MAGIC) and len(data) >= 24 and data[12:16] == b"IHDR":
        width, height = struct.unpack_from(">II", data, 16)
        return int(width), int(height)
    if not data.startswith(b"\xff\xd8"):
        return None
    pos = 2
    while pos + 4 <= len(data):
        if data[pos] != 0xFF:
            return None
        marker = data[pos + 1]
        if marker == 0xFF:  # fill byte
            pos += 1
            continue
        if marker in (0x01, *range(0xD0, 0xD9)):  # no length
            pos += 2
            continue
        (length,) = struct.unpack_from(">H", data, pos + 2)
        if marker in _JPEG_SOF and pos + 9 <= len(data):
            height, width = struct.unpack_from(">HH", data, pos + 5)
            return int(width), int(height)
        pos += 2 + length
    return None


def _imdecode(buf: NDArray[np.uint8], flags: int, what: str) -> NDArray[Any] | None:
    """``cv2.imdecode`` once the header's size is bounded (None when it does not decode)."""
    size = declared_size(buf[: 1 << 18].tobytes())  # the header, past any EXIF block
    if size is not None and size[0] * size[1] > MAX_COMPRESSED_PIXELS:
        raise ImageFormatError(
            f"{what} declares {size[0]}x{size[1]} pixels, more than the "
            f"{MAX_COMPRESSED_PIXELS} an image may have"
        )
    decoded: NDArray[Any] | None = cv2.imdecode(buf, flags)
    return decoded


def bytes_per_pixel(encoding: str) -> tuple[int, int]:
    """``(channels, bytes per channel)`` of a raw ``Image`` encoding (ImageFormatError if unknown)."""
    channels, kind = _pixel_layout(encoding)
    return channels, np.dtype(kind).itemsize


def _pixel_layout(encoding: str) -> tuple[int, str]:
    table = {
        "rgb8": (3, "u1"),
        "bgr8": (3, "u1"),
        "rgba8": (4, "u1"),
        "bgra8": (4, "u1"),
        "mono8": (1, "u1"),
        "16UC1": (1, "u2"),
        "mono16": (1, "u2"),
        "32FC1": (1, "f4"),
    }
    if encoding not in table:
        supported = ", ".join(COLOR_ENCODINGS + DEPTH_ENCODINGS)
        raise ImageFormatError(f"unsupported image encoding {encoding!r} (supported: {supported})")
    return table[encoding]


def image_array(msg: Any) -> NDArray[Any]:
    """The pixel array of a ``sensor_msgs/Image``, row padding removed, native byte order."""
    channels, kind = _pixel_layout(msg.encoding)
    dtype = np.dtype(kind).newbyteorder(">" if msg.is_bigendian else "<")
    height, width, step = int(msg.height), int(msg.width), int(msg.step)
    row_bytes = width * channels * dtype.itemsize
    data = np.asarray(msg.data, dtype=np.uint8)
    if step < row_bytes or data.size != step * height:  # ROS: data holds step * height bytes
        raise ImageFormatError(
            f"{msg.encoding} image {width}x{height} needs {row_bytes} bytes per row and "
            f"{step * height} in all, message has step {step} and {data.size} bytes"
        )
    rows = data[: step * height].reshape(height, step)[:, :row_bytes]
    arr = np.ascontiguousarray(rows).view(dtype).reshape(height, width, channels)
    arr = arr.astype(dtype.newbyteorder("="), copy=False)
    return arr if channels > 1 else arr[..., 0]


def decode_color(msg: Any) -> NDArray[np.uint8]:
    """Decode an RGB ``Image`` or ``CompressedImage`` to ``HxWx3`` RGB."""
    if hasattr(msg, "format"):
        buf = np.asarray(msg.data, dtype=np.uint8)
        bgr = _imdecode(buf, cv2.IMREAD_COLOR, f"compressed image ({msg.format!r})")
        if bgr is None:
            raise ImageFormatError(f"compressed image ({msg.format!r}) could not be decoded")
        # In place, and ~40x faster than copying the reversed-channel view.
        return np.asarray(cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB, dst=bgr), dtype=np.uint8)
    if msg.encoding not in COLOR_ENCODINGS:
        raise ImageFormatError(
            f"expected a colour encoding ({', '.join(COLOR_ENCODINGS)}), got {msg.encoding!r}"
        )
    arr = image_array(msg)
    conversion = _TO_RGB.get(msg.encoding)
    if conversion is not None:
        return np.asarray(cv2.cvtColor(arr, conversion), dtype=np.uint8)
    return np.ascontiguousarray(arr[..., :3])


def decode_mono(msg: Any) -> NDArray[Any]:
    """Decode a single-channel ``Image`` (mono8, mono16/16UC1) or PNG/JPEG ``CompressedImage``
    to its raw counts (``uint8`` or ``uint16``): thermal and grey cameras."""
    if hasattr(msg, "format"):
        buf = np.asarray(msg.data, dtype=np.uint8)
        img = _imdecode(buf, cv2.IMREAD_UNCHANGED, f"compressed image ({msg.format!r})")
        if img is None:
            raise ImageFormatError(f"compressed image ({msg.format!r}) could not be decoded")
        if img.ndim == 3:
            img = cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)
        return np.asarray(img)
    if msg.encoding not in MONO_ENCODINGS:
        raise ImageFormatError(
            f"expected a single-channel encoding ({', '.join(MONO_ENCODINGS)}), got {msg.encoding!r}"
        )
    return np.ascontiguousarray(image_array(msg))


def _depth_from_array(arr: NDArray[Any]) -> NDArray[np.float32]:
    if arr.dtype == np.uint16:
        depth = arr.astype(np.float32) * np.float32(0.001)
        depth[arr == 0] = np.nan
        return depth
    depth = arr.astype(np.float32, copy=True)
    depth[~np.isfinite(depth) | (depth <= 0)] = np.nan
    return depth


def decode_depth(msg: Any) -> NDArray[np.float32]:
    """Decode a depth ``Image`` (16UC1 mm, 32FC1 m) or ``compressedDepth`` to metres."""
    if hasattr(msg, "format"):
        fmt = str(msg.format)
        raw = bytes(np.asarray(msg.data, dtype=np.uint8))
        if "compressedDepth" not in fmt:
            raise ImageFormatError(f"depth CompressedImage format {fmt!r} is not compressedDepth")
        if len(raw) <= _COMPRESSED_DEPTH_HEADER.size:
            raise ImageFormatError("compressedDepth message shorter than its 12-byte header")
        _, quant_a, quant_b = _COMPRESSED_DEPTH_HEADER.unpack_from(raw)
        png = np.frombuffer(raw, dtype=np.uint8, offset=_COMPRESSED_DEPTH_HEADER.size)
        img = _imdecode(png, cv2.IMREAD_UNCHANGED, "compressedDepth payload")
        if img is None or img.dtype != np.uint16 or img.ndim != 2:
            raise ImageFormatError("compressedDepth payload is not a 16-bit single-channel PNG")
        if fmt.startswith("32FC1"):
            q = img.astype(np.float32)
            with np.errstate(divide="ignore"):
                depth = np.float32(quant_a) / (q - np.float32(quant_b))
            depth[img == 0] = np.nan
            return depth.astype(np.float32)
        return _depth_from_array(img)
    if msg.encoding not in DEPTH_ENCODINGS:
        raise ImageFormatError(
            f"expected a depth encoding ({', '.join(DEPTH_ENCODINGS)}), got {msg.encoding!r}"
        )
    return _depth_from_array(image_array(msg))


def depth_from_disparity_message(msg: Any) -> NDArray[np.float32]:
    """Depth (m) of a ``stereo_msgs/DisparityImage``: ``Z = f T / d`` (NaN: no disparity).

    ``d`` below the message's ``min_disparity`` (or not positive) has no depth. The
    baseline field is ``T`` in ROS1 and ``t`` in ROS2.
    """
    img = msg.image
    if img.encoding != "32FC1":
        raise ImageFormatError(f"DisparityImage image must be 32FC1, got {img.encoding!r}")
    f, baseline = float(msg.f), float(msg.T if hasattr(msg, "T") else msg.t)
    if not (f > 0 and baseline > 0):
        raise ImageFormatError(f"DisparityImage has f={f:g}, T={baseline:g}: both must be > 0")
    d = np.asarray(image_array(img), dtype=np.float32)
    valid = d > max(0.0, float(msg.min_disparity))
    with np.errstate(divide="ignore", invalid="ignore"):
        depth = np.where(valid, np.float32(f * baseline) / d, np.float32(np.nan))
    return depth.astype(np.float32)


# ----------------------------------------------------------------------------- encoding


def encode_color_raw(rgb: NDArray[np.uint8]) -> dict[str, Any]:
    """Fields of an rgb8 ``Image`` (without header)."""
    h, w = rgb.shape[:2]
    return {
        "height": h,
        "width": w,
        "encoding": "rgb8",
        "is_bigendian": 0,
        "step": w * 3,
        "data": np.ascontiguousarray(rgb, dtype=np.uint8).reshape(-1),
    }


def encode_color_jpeg(rgb: NDArray[np.uint8], quality: int = 90) -> dict[str, Any]:
    """Fields of a jpeg ``CompressedImage`` (without header)."""
    ok, buf = cv2.imencode(
        ".jpg", np.ascontiguousarray(rgb[..., ::-1]), [cv2.IMWRITE_JPEG_QUALITY, quality]
    )
    if not ok:
        raise ImageFormatError("jpeg encoding failed")
    return {"format": "rgb8; jpeg compressed bgr8", "data": buf.reshape(-1)}


def depth_to_mm(depth: NDArray[np.floating]) -> NDArray[np.uint16]:
    """Metres (NaN invalid) -> uint16 millimetres (0 invalid), rounded."""
    mm = np.nan_to_num(np.asarray(depth, dtype=np.float64) * 1000.0, nan=0.0)
    return np.clip(np.rint(mm), 0, 65535).astype(np.uint16)


def encode_depth_raw(depth: NDArray[np.floating], encoding: str) -> dict[str, Any]:
    """Fields of a 16UC1 (mm) or 32FC1 (m) ``Image`` (without header)."""
    h, w = depth.shape
    if encoding == "16UC1":
        data = depth_to_mm(depth)
        step = w * 2
    elif encoding == "32FC1":
        data = np.asarray(depth, dtype=np.float32)
        step = w * 4
    else:
        raise ImageFormatError(f"cannot encode depth as {encoding!r} (use 16UC1 or 32FC1)")
    return {
        "height": h,
        "width": w,
        "encoding": encoding,
        "is_bigendian": 0,
        "step": step,
        "data": np.ascontiguousarray(data).view(np.uint8).reshape(-1),
    }


def encode_depth_compressed(depth: NDArray[np.floating], encoding: str) -> dict[str, Any]:
    """Fields of a ``compressedDepth`` ``CompressedImage`` (without header)."""
    if encoding == "16UC1":
        img = depth_to_mm(depth)
        header = _COMPRESSED_DEPTH_HEADER.pack(0, 0.0, 0.0)
    elif encoding == "32FC1":
        d = np.asarray(depth, dtype=np.float64)
        valid = np.isfinite(d) & (d > 0) & (d < _DEPTH_MAX)
        q = np.zeros(d.shape, dtype=np.float64)
        q[valid] = _QUANT_A / d[valid] + _QUANT_B
        img = np.clip(np.rint(q), 0, 65535).astype(np.uint16)
        header = _COMPRESSED_DEPTH_HEADER.pack(0, _QUANT_A, _QUANT_B)
    else:
        raise ImageFormatError(f"cannot encode depth as {encoding!r} (use 16UC1 or 32FC1)")
    ok, png = cv2.imencode(".png", img)
    if not ok:
        raise ImageFormatError("png encoding failed")
    payload = np.frombuffer(header + png.tobytes(), dtype=np.uint8)
    return {"format": f"{encoding}; compressedDepth png", "data": payload}
