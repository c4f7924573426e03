"""Synthetic detection streams for tracker tests and the tracking benchmark.

People are points moving on the ground plane with a colour; each frame yields a
:class:`~rgbd_eval.types.Detection` with a noisy theoretical centroid and the
normalised 3D RGB histogram of pixels drawn around the person's colour.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rgbd_eval.types import Box2D, Detection

#: Frames of ``(stamp_ns, detections)``.
Stream = list[tuple[int, list[Detection]]]


def colour_histogram(
    rng: np.random.Generator,
    colour: tuple[float, float, float],
    bins: int = 8,
    pixels: int = 300,
    spread: float = 20.0,
) -> NDArray[np.float32]:
    """Flattened ``bins**3`` histogram (sum 1) of pixels ~ N(colour, spread^2) in 0..255."""
    if pixels < 1:
        raise ValueError(f"pixels={pixels} must be >= 1")
    px = np.clip(rng.normal(colour, spread, size=(pixels, 3)), 0.0, 255.999)
    idx = (px * (bins / 256.0)).astype(np.int64)
    flat = (idx[:, 0] * bins + idx[:, 1]) * bins + idx[:, 2]
    hist = np.bincount(flat, minlength=bins**3).astype(np.float32)
    return hist / np.float32(pixels)


def person_detection(
    x: float,
    y: float,
    *,
    height: float = 1.75,
    confidence: float = 0.0,
    histogram: NDArray[np.float32] | None = None,
    occluded: bool = False,
    sensor_xy: tuple[float, float] = (0.0, 0.0),
) -> Detection:
    """A detection at ground position ``(x, y)`` seen from a sensor at ``sensor_xy``."""
    distance = math.hypot(x - sensor_xy[0], y - sensor_xy[1])
    # a plausible box: 525 px focal length, 640 px wide image, sensor looking along +x
    depth = max(distance, 0.5)
    h_px = 525.0 * height / depth
    u = 320.0 - 525.0 * (y - sensor_xy[1]) / depth
    box = Box2D(u - 0.2 * h_px, 240.0 - 0.5 * h_px, 0.4 * h_px, h_px)
    return Detection(
        position=(x, y, height / 2.0),
        height=height,
        confidence=confidence,
        box2d=box,
        distance=distance,
        occluded=occluded,
        appearance=histogram,
    )


@dataclass(frozen=True)
class WalkingPerson:
    """A person pacing along x between ``x_min`` and ``x_max`` at ``speed`` m/s, at fixed y."""

    y: float
    colour: tuple[float, float, float]
    x_min: float = 2.0
    x_max: float = 5.0
    speed: float = 1.0
    phase: float = 0.0

    def position(self, t: float) -> tuple[float, float]:
        """Position at time ``t`` (s): a triangle wave between the two ends."""
        span = self.x_max - self.x_min
        s = (self.speed * t + self.phase) % (2.0 * span)
        return (self.x_min + (s if s <= span else 2.0 * span - s), self.y)


def walking_stream(
    people: Sequence[WalkingPerson],
    frames: int,
    rate_hz: float = 30.0,
    seed: int = 0,
    position_noise: float = 0.03,
    bins: int = 8,
) -> Stream:
    """``frames`` frames at ``rate_hz`` with every person detected in every frame."""
    if frames < 0 or rate_hz <= 0:
        raise ValueError(f"frames={frames} must be >= 0 and rate_hz={rate_hz} > 0")
    rng = np.random.default_rng(seed)
    out: Stream = []
    for k in range(frames):
        t = k / rate_hz
        dets = []
        for p in people:
            x, y = p.position(t)
            nx, ny = rng.normal(0.0, position_noise, 2)
            hist = colour_histogram(rng, p.colour, bins)
            dets.append(person_detection(x + nx, y + ny, histogram=hist))
        out.append((round(k * 1e9 / rate_hz), dets))
    return out


THREE_PEOPLE = (
    WalkingPerson(y=-1.2, colour=(200.0, 40.0, 40.0), speed=1.0),
    WalkingPerson(y=0.0, colour=(40.0, 40.0, 200.0), speed=1.3, phase=1.5),
    WalkingPerson(y=1.2, colour=(40.0, 200.0, 40.0), speed=0.8, phase=3.0),
)


def time_tracker(
    name: str = "basso2012", frames: int = 750, classifier: bool = True
) -> tuple[float, float]:
    """Mean wall-clock and CPU seconds per ``update`` for :data:`THREE_PEOPLE` at 30 Hz."""
    from rgbd_eval.components import create_tracker
    from rgbd_eval.config import build_config

    config = build_config({"tracker": {"name": name, "classifier": classifier}})
    stream = walking_stream(THREE_PEOPLE, frames)
    tracker = create_tracker(config)
    wall, cpu = time.perf_counter(), time.process_time()
    for stamp, dets in stream:
        tracker.update(stamp, dets)
    n = max(frames, 1)
    return (time.perf_counter() - wall) / n, (time.process_time() - cpu) / n


def main() -> None:
    """``python -m rgbd_eval.track.synthetic``: print the tracking time per frame.

    Run with ``OPENBLAS_NUM_THREADS=1`` for the one-core figure.
    """
    for classifier in (True, False):
        wall, cpu = time_tracker(classifier=classifier)
        print(
            f"basso2012 tracker, 3 people, 750 frames, classifier={'on' if classifier else 'off'}: "
            f"{wall * 1e3:.3f} ms/frame wall ({1.0 / wall:.0f} fps), {cpu * 1e3:.3f} ms/frame CPU"
        )


if __name__ == "__main__":
    main()
