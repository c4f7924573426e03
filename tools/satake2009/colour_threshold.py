"""Choose satake2009's colour-test threshold on a tuning recording (issue 31).

    .venv/bin/python -m rgbd_eval synth configs/scenarios/tuning/satake2009_clutter.yaml \
        --out /tmp/tune/satake2009_clutter_tuning.mcap
    PYTHONPATH=src .venv/bin/python tools/satake2009/colour_threshold.py \
        /tmp/tune/satake2009_clutter_tuning.mcap

Every template match of the detector (colour test off) in every frame is labelled a person
when its head point lies within ``--gate`` metres (ground plane) of a ground-truth person,
else an object. Its head-torso chroma (:func:`rgbd_eval.methods.satake2009.colour.
head_torso_chroma`; None: no head) is measured. The chosen threshold is the one with the
fewest errors (people rejected + objects kept); where several thresholds tie, the middle of
the widest best interval (:func:`rgbd_eval.tuning.fewest_errors`). Prints the percentiles
per label and the errors at a few thresholds.
Run it on tuning recordings only: the value is written to
``methods/satake2009/method.yaml`` and judged on the scored scenes.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

from rgbd_eval.config import load_config
from rgbd_eval.detect import stereo
from rgbd_eval.io.groundtruth import load_ground_truth
from rgbd_eval.methods.satake2009 import colour, search
from rgbd_eval.methods.satake2009.detector import Satake2009Detector, head_point
from rgbd_eval.pipeline import open_for, sidecar_path
from rgbd_eval.tuning import fewest_errors


def measure(path: Path, gate_m: float) -> tuple[list[float], list[float], int, int]:
    """Chroma of person matches and of object matches; matches without a head per label."""
    config = load_config(method="satake2009")
    c = config.detector
    det = Satake2009Detector(c)  # type: ignore[arg-type]
    rec = open_for(path, config)
    side = sidecar_path(path)
    if side is None:
        raise SystemExit(f"error: {path}: no <name>.gt.csv beside it")
    gt = load_ground_truth(side)
    frames = list(rec.frames())
    truth, _, _ = gt.match([f.stamp_ns for f in frames], int(config.io.max_sync_gap_ms * 1e6))
    people: list[float] = []
    objects: list[float] = []
    headless = [0, 0]
    for frame, objs in zip(frames, truth, strict=True):
        left = frame.stream("left")
        sd = search.frame_depth(frame, c.size, c.sgbm)
        rgb = stereo.resized(left.image, c.size)
        for m in det.candidates(sd.depth, sd.camera.fx, sd.far):
            D = search.body_distance(sd.depth, m, c.band_m)
            wx, wy, _ = left.pose.transform_points(head_point(sd.camera, m, D)[None, :])[0]
            near = any(
                o.world_xyz is not None
                and math.hypot(o.world_xyz[0] - wx, o.world_xyz[1] - wy) <= gate_m
                for o in objs
            )
            value = colour.head_torso_chroma(rgb, sd.depth, m, D, c.band_m)
            if value is None:
                headless[0 if near else 1] += 1
            else:
                (people if near else objects).append(value)
    return people, objects, headless[0], headless[1]


def choose(people: list[float], objects: list[float]) -> tuple[float, int]:
    """The threshold with the fewest errors (people rejected + objects kept; a match is kept
    when chroma >= t), the middle of the widest best interval
    (:func:`rgbd_eval.tuning.fewest_errors`), and the errors."""
    c = fewest_errors(people, objects, "at_or_above", floor=0.0)
    return c.value, c.errors


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("recordings", type=Path, nargs="+")
    ap.add_argument("--gate", type=float, default=0.5, help="person if within (m)")
    ap.add_argument("--at", type=float, nargs="*", default=[], help="also print these thresholds")
    args = ap.parse_args(argv)
    people: list[float] = []
    objects: list[float] = []
    headless = [0, 0]
    for path in args.recordings:
        p, o, hp, ho = measure(path, args.gate)
        people += p
        objects += o
        headless[0] += hp
        headless[1] += ho
    for name, values, nohead in (
        ("people", people, headless[0]),
        ("objects", objects, headless[1]),
    ):
        q = np.percentile(values, [0, 5, 50, 95, 100]) if values else [math.nan] * 5
        print(
            f"{name:<8} {len(values):4d} matches (+{nohead} without a head): chroma "
            f"min {q[0]:.1f}  5% {q[1]:.1f}  median {q[2]:.1f}  95% {q[3]:.1f}  max {q[4]:.1f}"
        )
    threshold, errors = choose(people, objects)
    for t in (2.0, 3.0, 4.0, 6.0, 8.0, *args.at, threshold):
        lost = sum(v < t for v in people)
        kept = sum(v >= t for v in objects)
        print(f"threshold {t:5.2f}: people rejected {lost:4d}  objects kept {kept:4d}")
    print(f"fewest errors: {threshold:.2f} ({errors} errors)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
