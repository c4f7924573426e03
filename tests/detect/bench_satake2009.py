"""CPU time per stage of satake2009 on one core (a script, not a test).

Run from the repository root::

    .venv/bin/python -m tests.detect.bench_satake2009 RECORDING [--set section.key=value ...]

``rgbd-eval bench`` reports wall-clock time, which a loaded machine inflates. This
script runs the same pipeline (:func:`rgbd_eval.pipeline.detect_and_track`) pinned to
one CPU with OpenCV on one thread, and makes the stages' own timers read this thread's
CPU time (``time.thread_time``) instead of the wall clock, so the figures do not depend
on what else runs. It prints CPU milliseconds per frame of each stage, the CPU frames per
second of the whole pipeline (decoding included) and the load average, and the CLEAR MOT
figures when the recording has ground truth.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import cv2


def main(argv: list[str]) -> int:
    """Print per-stage CPU ms/frame of ``run --method satake2009`` on a recording."""
    from rgbd_eval.config import load_config
    from rgbd_eval.pipeline import (
        detect_and_track,
        find_ground_truth,
        match_ground_truth,
        open_for,
        score_sequence,
    )

    if not argv:
        print(__doc__)
        return 2
    path = Path(argv[0])
    sets = [a for a in argv[1:] if a != "--set"]
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})
    cv2.setNumThreads(1)
    config = load_config(method="satake2009", overrides=sets)
    time.perf_counter = time.thread_time  # the stages' timers now read CPU time
    recording = open_for(path, config)
    start = time.thread_time()
    detections, tracks = detect_and_track(recording, config)
    total = time.thread_time() - start
    n = len(tracks)
    print(f"{path.name}: {n} frames, load average {os.getloadavg()[0]:.1f}")
    for key, sec in detections.seconds.items():
        print(f"  {key:24s} {sec / n * 1e3:7.2f} ms/frame CPU")
    print(f"  {'total':24s} {total / n * 1e3:7.2f} ms/frame CPU = {n / total:.1f} fps on one core")
    dets = sum(len(d) for d in detections.detections) / n
    print(f"  detections/frame {dets:.2f}, tracks/frame {sum(len(t) for t in tracks) / n:.2f}")
    gt = find_ground_truth(path, recording, None)
    if gt is not None:
        s = score_sequence(match_ground_truth(gt, detections.stamps_ns, config), tracks, config)
        summary = s.summary()
        keys = ("mota", "motp", "fp", "fn", "id_switches", "num_gt")
        print("  " + ", ".join(f"{k} {summary[k]}" for k in keys))
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
