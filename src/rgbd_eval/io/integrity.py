"""Per-message checks for recordings that carry no checksum, and the count of what was skipped.

A ROS1 bag (and a ROS2 sqlite3 database) has no CRC: a flipped or lost byte inside a
message is read back as a message with other values. The reader therefore checks every
message it uses in its index pass, whatever the container:

- it must deserialise against its definition, consuming exactly its bytes (rosbags'
  ``deserialize_ros1``/``deserialize_cdr`` refuse a size mismatch);
- a ``sensor_msgs/Image`` must agree with itself: a known encoding, ``step`` at least
  ``width * bytes per pixel``, ``data`` exactly ``step * height`` bytes (REP 118 /
  the message definition), and its size must be that of its CameraInfo;
- a ``sensor_msgs/CompressedImage`` must hold data (``compressedDepth``: more than its
  12-byte header);
- a ``sensor_msgs/CameraInfo`` must describe a camera: a size of 1 to 16384 pixels a side,
  a finite ``K`` with positive focal lengths (an uncalibrated driver publishes ``K`` all
  zero) giving a field of view of 1 to 170 degrees, the principal point within one image
  size of the image, finite ``D``.

A message that fails is skipped and counted per topic (:class:`SkipLog`); the counts go
into a warning, ``report.json`` and ``inspect``. When nothing usable is left (no valid
CameraInfo, no frame with every stream) the reader refuses the recording (exit 3).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from rgbd_eval.io.images import ImageFormatError, bytes_per_pixel

#: ``compressedDepth`` payloads start with ``int32 format, float32 A, float32 B``.
_COMPRESSED_DEPTH_HEADER = 12
#: Largest image side a CameraInfo may state (pixels): sizes are allocated from it.
MAX_IMAGE_SIDE = 16384
#: Field of view (degrees, per axis, from the focal length) a pinhole camera may have: a
#: focal length of 1e-300 pixels (a view of 180 degrees) made every back-projected point
#: land at infinity.
FOV_RANGE_DEG = (1.0, 170.0)


@dataclass(frozen=True)
class SkippedMessages:
    """Messages of one topic that were skipped, with the first reason."""

    topic: str
    count: int
    total: int
    first_problem: str


def image_problem(msg: Any) -> str | None:
    """Why an ``Image``/``CompressedImage`` message is unusable (None when it is usable)."""
    if hasattr(msg, "format"):
        size = len(msg.data)
        if size == 0:
            return "compressed image holds no data"
        if "compressedDepth" in str(msg.format) and size <= _COMPRESSED_DEPTH_HEADER:
            return f"compressedDepth data is {size} bytes, not more than its 12-byte header"
        return None
    try:
        channels, itemsize = bytes_per_pixel(str(msg.encoding))
    except ImageFormatError as err:
        return str(err)
    width, height, step, size = int(msg.width), int(msg.height), int(msg.step), len(msg.data)
    if width <= 0 or height <= 0:
        return f"{msg.encoding} image is {width}x{height}"
    if int(msg.is_bigendian) not in (0, 1):
        return f"is_bigendian is {int(msg.is_bigendian)}, not 0 or 1"
    row = width * channels * itemsize
    if step < row:
        return f"step {step} is less than width {width} x {channels * itemsize} bytes per pixel"
    if size != step * height:
        return f"data holds {size} bytes, step {step} x height {height} needs {step * height}"
    return None


def _finite(values: Any) -> bool:
    return all(math.isfinite(float(v)) for v in values)


def camera_info_problem(msg: Any) -> str | None:
    """Why a ``CameraInfo`` message cannot describe a camera (None when it can)."""
    K = list(msg.K if hasattr(msg, "K") else msg.k)
    D = list(msg.D if hasattr(msg, "D") else msg.d)
    width, height = int(msg.width), int(msg.height)
    if not (0 < width <= MAX_IMAGE_SIDE and 0 < height <= MAX_IMAGE_SIDE):
        return f"CameraInfo size is {width}x{height} (sides of 1 to {MAX_IMAGE_SIDE} pixels)"
    if len(K) != 9 or not _finite(K):
        return f"CameraInfo K is not 9 finite numbers: {K}"
    if not any(K):
        return "CameraInfo K is all zero (uncalibrated camera)"
    fx, cx, fy, cy = float(K[0]), float(K[2]), float(K[4]), float(K[5])
    if not (fx > 0 and fy > 0):
        return f"CameraInfo focal lengths must be positive, K has fx={fx}, fy={fy}"
    low, high = FOV_RANGE_DEG
    for axis, focal, side in (("x", fx, width), ("y", fy, height)):
        fov = math.degrees(2.0 * math.atan(side / (2.0 * focal)))
        if not low <= fov <= high:
            return (
                f"CameraInfo f{axis}={focal:g} gives a {fov:.4g} degree field of view over "
                f"{side} pixels, outside {low:g}..{high:g}"
            )
    if not (-width <= cx <= 2 * width and -height <= cy <= 2 * height):
        return f"CameraInfo principal point ({cx:g}, {cy:g}) lies far outside the {width}x{height} image"
    if not _finite(D):
        return f"CameraInfo D is not finite: {D}"
    return None


@dataclass
class SkipLog:
    """Skipped messages per topic (the first problem kept, the rest counted)."""

    counts: dict[str, int] = field(default_factory=dict)
    first: dict[str, str] = field(default_factory=dict)

    def add(self, topic: str, problem: str) -> None:
        self.counts[topic] = self.counts.get(topic, 0) + 1
        self.first.setdefault(topic, problem)

    def summary(self, totals: dict[str, int]) -> tuple[SkippedMessages, ...]:
        """One record per topic with skipped messages, by topic name."""
        return tuple(
            SkippedMessages(t, n, max(totals.get(t, n), n), self.first[t])
            for t, n in sorted(self.counts.items())
        )


def skipped_warning(skipped: tuple[SkippedMessages, ...]) -> str | None:
    """One warning line with the per-topic counts (None when nothing was skipped)."""
    if not skipped:
        return None
    parts = [f"{s.topic} {s.count} of {s.total} ({s.first_problem})" for s in skipped]
    return "damaged messages skipped: " + "; ".join(parts)
