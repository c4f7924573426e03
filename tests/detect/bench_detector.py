"""Per-stage timing of the basso2012 detector (a script, not a test).

Run from the repository root, on one thread::

    OMP_NUM_THREADS=1 .venv/bin/python -m tests.detect.bench_detector [RECORDING ...]

With recordings (``.bag``/``.mcap``, read by ``rgbd_eval.io``) every frame of
each is timed. Without, a ray-cast room (three people, two side by side, a
cabinet, a low box; camera 1.0 m high, moving and pitching) is rendered with
depth at 160x120 and 320x240 and RGB at 640x480. Frames are decoded/rendered
first; only ``detect`` is timed.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Sequence

import cv2
import numpy as np

from rgbd_eval.methods.basso2012.detector import STAGES, Basso2012Detector
from rgbd_eval.methods.basso2012.detector_config import Basso2012DetectorConfig as DetectorConfig
from rgbd_eval.types import Frame

from .scenes import Block, Person, Scene, camera_pose, render


def time_frames(label: str, frames: Sequence[Frame]) -> None:
    """Print mean per-stage milliseconds and frames per second of ``detect``."""
    det = Basso2012Detector(DetectorConfig())
    totals = dict.fromkeys(STAGES, 0.0)
    counts = []
    start = time.perf_counter()
    for f in frames:
        counts.append(len(det.detect(f)))
        for k, v in det.last_timings.items():
            totals[k] += v
    wall = time.perf_counter() - start
    n = len(frames)
    h, w = frames[0].depth.shape
    print(
        f"{label} depth {w}x{h}, {n} frames: {1e3 * wall / n:.2f} ms/frame "
        f"({n / wall:.0f} fps), detections/frame {np.mean(counts):.2f}"
    )
    print("  " + "  ".join(f"{k} {1e3 * v / n:.2f}" for k, v in totals.items()) + "  (ms)")


def rendered_frames(size: tuple[int, int], n: int = 40) -> list[Frame]:
    scene = Scene(
        people=[Person(3.0, 0.6, 1.72), Person(3.0, 0.1, 1.80), Person(4.5, -0.9, 1.65)],
        blocks=[Block(4.0, 1.4, (0.5, 0.6, 1.9)), Block(2.5, -0.6, (0.5, 0.5, 0.8))],
    )
    return [
        render(scene, camera_pose(x=0.02 * k, height=1.0, pitch_deg=np.sin(k / 5.0)), size, index=k)
        for k in range(n)
    ]


def main(argv: Sequence[str]) -> None:
    cv2.setNumThreads(1)
    if argv:
        from rgbd_eval.io.recording import open_recording

        for path in argv:
            time_frames(path, list(open_recording(path).frames()))
        return
    for size in ((160, 120), (320, 240)):
        time_frames("ray-cast room", rendered_frames(size))


if __name__ == "__main__":
    main(sys.argv[1:])
