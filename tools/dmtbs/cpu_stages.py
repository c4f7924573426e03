"""CPU time per DMT-BS stage on scene 2's four 512x424 ToF cameras, on one core.

Wall-clock figures from ``rgbd-eval bench`` are meaningless on a loaded machine; this times
the same stages with the thread's CPU clock (the detector and tracker time their stages with
``time.perf_counter``, replaced here by ``time.thread_time``). Frames are rendered in memory
first (not timed); the background's initialisation frames are not timed either.

    .venv/bin/python tools/dmtbs/cpu_stages.py [seconds of scene 2] [cameras] [KEY=VALUE ...]

e.g. ``tools/dmtbs/cpu_stages.py 4 4 detector.background=mog2``.
"""

from __future__ import annotations

import os
import sys
import time
from types import SimpleNamespace

import cv2

from rgbd_eval.config import config_dir, load_config
from rgbd_eval.methods.dmtbs import detector as detect_dmtbs
from rgbd_eval.methods.dmtbs import tracker as track_dmtbs
from rgbd_eval.methods.dmtbs.detector import DepthView, DmtbsDetector, DmtbsDetectorConfig
from rgbd_eval.methods.dmtbs.tracker import DmtbsTracker, DmtbsTrackerConfig
from rgbd_eval.sim.scenario import load_scenario
from rgbd_eval.sim.tof import TofRig


def main() -> None:
    seconds = float(sys.argv[1]) if len(sys.argv) > 1 else 4.0
    n_cams = int(sys.argv[2]) if len(sys.argv) > 2 else 4
    os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})
    cv2.setNumThreads(1)
    cpu_clock = SimpleNamespace(perf_counter=time.thread_time)
    detect_dmtbs.time = cpu_clock  # type: ignore[attr-defined]
    track_dmtbs.time = cpu_clock  # type: ignore[attr-defined]
    scenario = load_scenario(
        config_dir() / "scenarios" / "dmtbs" / "scene2.yaml", [("duration_s", seconds)]
    )
    config = load_config(
        method="dmtbs", overrides=["detector.roi=[-2.5,-2.5,2.5,2.5]", *sys.argv[3:]]
    )
    det_cfg, trk_cfg = config.detector, config.tracker
    assert isinstance(det_cfg, DmtbsDetectorConfig) and isinstance(trk_cfg, DmtbsTrackerConfig)
    frames = list(TofRig(scenario).frames())
    det, trk = DmtbsDetector(det_cfg), DmtbsTracker(trk_cfg)
    timed = 0
    track_s = 0.0
    start = 0.0
    for k, frame in enumerate(frames):
        if k == det_cfg.init_frames:
            det.stage_seconds = dict.fromkeys(det.stage_seconds, 0.0)
            start = time.thread_time()
        views = [DepthView(i.name, i.depth, i.camera, i.pose) for i in frame.images[:n_cams]]
        result = det.detect_views(frame.stamp_ns, views)
        t0 = time.thread_time()
        trk.update(frame.stamp_ns, result.detections)
        if k >= det_cfg.init_frames:
            track_s += time.thread_time() - t0
            timed += 1
    total = time.thread_time() - start
    print(f"{timed} frames, {n_cams} cameras of 512x424, one core, load {os.getloadavg()[0]:.1f}")
    for stage, s in det.stage_seconds.items():
        print(f"  {stage:12s} {1000 * s / timed:7.2f} ms CPU/frame")
    print(f"  {'tracking':12s} {1000 * track_s / timed:7.2f} ms CPU/frame")
    print(f"  {'total':12s} {1000 * total / timed:7.2f} ms CPU/frame = {timed / total:.0f} fps")


if __name__ == "__main__":
    main()
