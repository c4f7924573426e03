"""Per-stage timing of the basso2012 detector on ray-cast frames (not a test).

Run: ``.venv/bin/python -m tests.detect.bench_detector`` from the repository root.
A room with three people (two side by side), a cabinet and a low box, seen by a
camera 1.0 m high that moves and pitches; depth at 160x120 and 320x240, RGB
640x480. Frames are rendered first; only ``detect`` is timed, on one thread.
"""

from __future__ import annotations

import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")

import cv2
import numpy as np

from rgbd_eval.config import DetectorConfig
from rgbd_eval.detect.basso2012 import STAGES, Basso2012Detector

from .scenes import Block, Person, Scene, camera_pose, render


def main(frames: int = 40) -> None:
    cv2.setNumThreads(1)
    scene = Scene(
        people=[Person(3.0, 0.6, 1.72), Person(3.0, 0.1, 1.80), Person(4.5, -0.9, 1.65)],
        blocks=[Block(4.0, 1.4, (0.5, 0.6, 1.9)), Block(2.5, -0.6, (0.5, 0.5, 0.8))],
    )
    for size in ((160, 120), (320, 240)):
        rendered = [
            render(
                scene,
                camera_pose(x=0.02 * k, height=1.0, pitch_deg=np.sin(k / 5.0)),
                size,
                index=k,
            )
            for k in range(frames)
        ]
        det = Basso2012Detector(DetectorConfig())
        det.detect(rendered[0])  # warm-up: ground initialisation, caches
        totals = dict.fromkeys(STAGES, 0.0)
        counts = []
        start = time.perf_counter()
        for f in rendered:
            counts.append(len(det.detect(f)))
            for k, v in det.last_timings.items():
                totals[k] += v
        wall = time.perf_counter() - start
        per = {k: 1e3 * v / frames for k, v in totals.items()}
        print(
            f"depth {size[0]}x{size[1]}: {1e3 * wall / frames:.2f} ms/frame "
            f"({frames / wall:.0f} fps), detections/frame {np.mean(counts):.1f}"
        )
        print("  " + "  ".join(f"{k} {v:.2f}" for k, v in per.items()) + "  (ms)")


if __name__ == "__main__":
    main()
