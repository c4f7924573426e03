"""Choose dmtbs's smallest blob (``detector.min_blob_area_m2``) on a tuning scene (issue 31).

    PYTHONPATH=src .venv/bin/python tools/dmtbs/min_blob_area.py \
        configs/scenarios/tuning/dmtbs_hall_tuning.yaml

The scene is rendered in memory (every ``static_depth`` camera of its rig, its own sensor
noise, nothing added) and the detector of ``methods/dmtbs/method.yaml`` runs on it with
every blob kept (``min_blob_area_m2 = 0``; the map's region is the scene's room). In each
frame after the background's initialisation, a person present is *found at threshold t*
when a blob of surface >= t lies within ``--gate`` metres of them (on the floor), and a blob
farther than the gate from every person is a *false blob*. The rule, fixed before looking:
the threshold with the fewest errors (people not found + false blobs kept), the middle of
the widest interval of thresholds with that count. Blobs near a person other than their
largest (fragments) count as neither. Prints the surfaces per label and the errors at a few
thresholds. Run it on tuning scenes only: the value is written to
``methods/dmtbs/method.yaml`` and judged on the scored scenes.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

from rgbd_eval.config import load_config
from rgbd_eval.detect.blobs import blob_mask, find_blobs
from rgbd_eval.methods.dmtbs.detector import DepthView, DmtbsDetector, DmtbsDetectorConfig
from rgbd_eval.sim.scenario import load_scenario
from rgbd_eval.sim.tof import TofRig
from rgbd_eval.tuning import errors_at as _errors_at
from rgbd_eval.tuning import fewest_errors


def measure(path: Path, gate_m: float) -> tuple[list[float], list[float], int]:
    """Per person and frame the largest blob surface within the gate (0: no blob near), the
    surface of every false blob, and the number of scored person-frames."""
    scenario = load_scenario(path)
    room = scenario.room
    config = load_config(
        method="dmtbs",
        overrides=[
            "detector.min_blob_area_m2=0",
            f"detector.roi=[{room.x_min},{room.y_min},{room.x_max},{room.y_max}]",
        ],
    )
    det_cfg = config.detector
    if not isinstance(det_cfg, DmtbsDetectorConfig):
        raise SystemExit("error: the dmtbs method config must select the dmtbs detector")
    det = DmtbsDetector(det_cfg)
    grid = det_cfg.grid()
    rig = TofRig(scenario)
    people: list[float] = []
    false: list[float] = []
    for k, frame in enumerate(rig.frames()):
        views = [DepthView(im.name, im.depth, im.camera, im.pose) for im in frame.images]
        result = det.detect_views(frame.stamp_ns, views)
        if k < det_cfg.init_frames:
            continue
        binary, blurred = blob_mask(
            result.density,
            grid,
            det_cfg.blur_sigma_m,
            det_cfg.density_threshold,
            det_cfg.closing_radius_m,
        )
        blobs, _ = find_blobs(binary, blurred, grid, 0.0)
        truth = [g.world_xyz[:2] for g in frame.ground_truth if g.world_xyz is not None]
        near = [
            [math.hypot(b.centroid[0] - x, b.centroid[1] - y) <= gate_m for (x, y) in truth]
            for b in blobs
        ]
        for j in range(len(truth)):
            people.append(
                max((b.area_m2 for b, n in zip(blobs, near, strict=True) if n[j]), default=0.0)
            )
        false += [b.area_m2 for b, n in zip(blobs, near, strict=True) if not any(n)]
    return people, false, len(people)


def errors_at(people: list[float], false: list[float], t: float) -> int:
    """People not found (their largest near blob below ``t``, or none) + false blobs kept."""
    missed = sum(a == 0.0 for a in people)
    return missed + _errors_at([a for a in people if a > 0.0], false, t, "at_or_above")


def choose(people: list[float], false: list[float]) -> tuple[float, float, float, int]:
    """The threshold with the fewest errors: the middle of the widest best interval
    (:func:`rgbd_eval.tuning.fewest_errors`; a blob is kept when its surface >= t). Returns
    (threshold, interval low, interval high, errors), the people without a blob counted."""
    missed = sum(a == 0.0 for a in people)
    c = fewest_errors([a for a in people if a > 0.0], false, "at_or_above", floor=0.0)
    return c.value, c.low, c.high, c.errors + missed


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("scenes", type=Path, nargs="+", help="tuning scenario YAMLs")
    ap.add_argument("--gate", type=float, default=0.5, help="a blob is a person's within (m)")
    ap.add_argument("--at", type=float, nargs="*", default=[], help="also print these thresholds")
    args = ap.parse_args(argv)
    people: list[float] = []
    false: list[float] = []
    for path in args.scenes:
        p, f, _ = measure(path, args.gate)
        people += p
        false += f
    found = [a for a in people if a > 0.0]
    for name, values in (("people", found), ("false", false)):
        q = np.percentile(values, [0, 1, 5, 50, 95, 100]) if values else [math.nan] * 6
        print(
            f"{name:<6} {len(values):5d} blobs: m^2 min {q[0]:.4f}  1% {q[1]:.4f}  "
            f"5% {q[2]:.4f}  median {q[3]:.4f}  95% {q[4]:.4f}  max {q[5]:.4f}"
        )
    print(
        f"person-frames {len(people)}, without any blob within {args.gate} m: "
        f"{len(people) - len(found)}"
    )
    threshold, low, high, errs = choose(people, false)
    for t in sorted({0.01, 0.02, 0.03, 0.04, 0.05, 0.06, 0.08, 0.1, *args.at, threshold}):
        lost = sum(0.0 < a < t for a in people)
        kept = sum(a >= t for a in false)
        print(f"t {t:.4f} m^2: people lost {lost:5d}  false blobs kept {kept:5d}")
    print(f"fewest errors: {errs} for t in ({low:.4f}, {high:.4f}] m^2; middle {threshold:.4f}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
