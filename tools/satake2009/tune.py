"""Choose satake2009's measured search and stereo settings on tuning scenes (issue 31).

    PYTHONPATH=src .venv/bin/python tools/satake2009/tune.py \
        configs/scenarios/tuning/satake2009_crossing_tuning.yaml \
        configs/scenarios/tuning/satake2009_clutter.yaml --work /tmp/satake2009_tune

Each scene is rendered once to ``--work/<name>.mcap`` (kept; ``synth`` gives the same bytes
again), then the method of ``methods/satake2009/method.yaml`` runs on every recording
(:func:`rgbd_eval.pipeline.run_sequence`, scored with the method's metric gating) once
per candidate value of each parameter of :data:`SWEEPS`, one parameter at a time, in that
order, the others at the values chosen so far. The errors (FN + FP + ID switches) are
summed over the scenes. The rule, fixed before looking: the candidate with the fewest
errors (the best MOTA over the scenes); among candidates with as few, the first in its
list, which lists them cheapest first (fewer pixels, distances, disparities or search
steps; equal cost: the method's current value first). MOTP and CPU time are printed, not
used: CPU time depends on the machine and its load, and the rule must not. CPU is this
process's CPU time with OpenCV on one thread, per frame. Run it on tuning scenes only:
the values are written to ``methods/satake2009/method.yaml`` and judged on the scored
scenes.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import cv2

from rgbd_eval.config import RunConfig, config_to_dict, load_config
from rgbd_eval.detect import stereo
from rgbd_eval.methods.satake2009.detector import Satake2009DetectorConfig
from rgbd_eval.pipeline import open_for, run_sequence
from rgbd_eval.sim import load_scenario, synthesize

#: Parameter (one or more keys set together) -> candidates, cheapest first (equal cost: the
#: method's value before this tuning first). The alternatives are those the method's
#: comments named when the values were chosen on a scored scene, plus a neighbour where
#: only one side was named.
SWEEPS: tuple[tuple[tuple[str, ...], tuple[tuple[str, ...], ...]], ...] = (
    # OpenCV's post-filters, off first (less work): (uniqueness %, speckle window px)
    (
        ("detector.uniqueness_ratio", "detector.speckle_window"),
        (("0", "0"), ("10", "0"), ("0", "100"), ("10", "100")),
    ),
    (("detector.num_disparities",), (("32",), ("64",))),
    (("detector.template_rows",), (("12",), ("16",), ("24",))),
    # fewer distances first: 1..6 m in steps of 1.25 (9), 1.2 (10), 1.15 (13)
    (("detector.distance_ratio",), (("1.25",), ("1.2",), ("1.15",))),
    (("detector.min_score",), (("0.8",), ("0.7",), ("0.9",))),
    (("tracker.search_rows",), (("16",), ("24",), ("40",))),
    (("tracker.search_steps",), (("0",), ("1",))),
)


@dataclass(frozen=True)
class Outcome:
    """One candidate's scores, summed over the scenes."""

    errors: int
    num_gt: int
    fp: int
    fn: int
    id_switches: int
    motp: float | None  # metres, over all matches
    cpu_ms: float  # per frame

    @property
    def mota(self) -> float:
        return 1.0 - self.errors / self.num_gt if self.num_gt else float("nan")


def choose(outcomes: Sequence[Outcome]) -> int:
    """Index of the candidate with the fewest errors; ties: the first (cheapest) of them."""
    if not outcomes:
        raise ValueError("no candidates")
    best = min(o.errors for o in outcomes)
    return next(i for i, o in enumerate(outcomes) if o.errors == best)


def render(scene: Path, work: Path) -> Path:
    """The scene's recording under ``work`` (rendered when missing)."""
    scenario = load_scenario(scene)
    if not scenario.name.endswith("_tuning"):
        raise SystemExit(f"error: {scene} [scenario]: a tuning scene (name ending _tuning)")
    out = work / f"{scenario.name}.mcap"
    if not out.exists():
        work.mkdir(parents=True, exist_ok=True)
        synthesize(scenario, out)
    return out


def evaluate(recordings: Sequence[Path], config: RunConfig) -> Outcome:
    """Run the method with ``config`` on every recording; the summed scores."""
    fp = fn = ids = gt = matches = frames = 0
    similarity = cpu = 0.0
    for path in recordings:
        start = time.process_time()
        result = run_sequence(path, config)
        cpu += time.process_time() - start
        if result.scores is None:
            raise SystemExit(f"error: {path} [ground truth]: no <name>.gt.csv beside it")
        c = result.scores.counts
        fp, fn, ids = fp + c.fp, fn + c.fn, ids + c.id_switches
        gt, matches, frames = gt + c.num_gt, matches + c.num_matches, frames + c.num_frames
        similarity += c.similarity_sum
    return Outcome(
        errors=fp + fn + ids,
        num_gt=gt,
        fp=fp,
        fn=fn,
        id_switches=ids,
        motp=similarity / matches if matches else None,
        cpu_ms=1e3 * cpu / max(frames, 1),
    )


#: OpenCV's SGBM modes (the method uses 3WAY: ``SgbmParams.three_way``; a code choice timed
#: here with ``--sgbm-modes``, not part of the sweep).
MODES = {
    "3WAY": cv2.STEREO_SGBM_MODE_SGBM_3WAY,
    "SGBM": cv2.STEREO_SGBM_MODE_SGBM,
    "HH4": cv2.STEREO_SGBM_MODE_HH4,
    "HH": cv2.STEREO_SGBM_MODE_HH,
}


def time_modes(recordings: Sequence[Path]) -> dict[str, float]:
    """CPU ms per pair of ``matcher.compute`` per SGBM mode, at the method's settings."""
    config = load_config(method="satake2009")
    det = config.detector
    if not isinstance(det, Satake2009DetectorConfig):
        raise SystemExit("error: the satake2009 method config must select its detector")
    pairs = []
    for path in recordings:
        for frame in open_for(path, config).frames():
            left, right = (
                stereo.resized(frame.stream(s).image, det.size) for s in ("left", "right")
            )
            grey = [
                im if im.ndim == 2 else cv2.cvtColor(im, cv2.COLOR_RGB2GRAY) for im in (left, right)
            ]
            pairs.append((grey[0], grey[1]))
    out = {}
    for name, mode in MODES.items():
        matcher = stereo.make_matcher(det.sgbm)
        matcher.setMode(mode)
        start = time.process_time()
        for a, b in pairs:
            matcher.compute(a, b)
        out[name] = 1e3 * (time.process_time() - start) / max(len(pairs), 1)
    return out


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("scenes", type=Path, nargs="+", help="tuning scenario YAMLs")
    ap.add_argument("--work", type=Path, default=Path("/tmp/satake2009_tune"))
    ap.add_argument("--sgbm-modes", action="store_true", help="also time OpenCV's SGBM modes")
    args = ap.parse_args(argv)
    cv2.setNumThreads(1)
    recordings = [render(scene, args.work) for scene in args.scenes]
    if args.sgbm_modes:
        times = time_modes(recordings)
        print("SGBM modes: " + ", ".join(f"{k} {v:.1f}" for k, v in times.items()) + " ms/pair")
    chosen: dict[str, str] = {}
    seen: dict[str, Outcome] = {}  # resolved config (JSON) -> its outcome
    for keys, candidates in SWEEPS:
        outcomes = []
        print(f"{' + '.join(keys)}:")
        for values in candidates:
            sets = {**chosen, **dict(zip(keys, values, strict=True))}
            config = load_config(
                method="satake2009", overrides=[f"{k}={v}" for k, v in sets.items()]
            )
            key = json.dumps(config_to_dict(config), sort_keys=True)
            if key not in seen:
                seen[key] = evaluate(recordings, config)
            o = seen[key]
            outcomes.append(o)
            motp = "-" if o.motp is None else f"{o.motp:.3f} m"
            print(
                f"  {', '.join(values):>8}: MOTA {100 * o.mota:5.1f} %  MOTP {motp}  "
                f"FP {o.fp:3d}  FN {o.fn:3d}  IDSW {o.id_switches:2d}  "
                f"(errors {o.errors} of {o.num_gt})  CPU {o.cpu_ms:5.1f} ms/frame",
                flush=True,
            )
        best = choose(outcomes)
        chosen.update(zip(keys, candidates[best], strict=True))
        print(f"  chosen: {', '.join(candidates[best])}")
    print("chosen: " + "  ".join(f"{k}={v}" for k, v in chosen.items()))
    config = load_config(method="satake2009", overrides=[f"{k}={v}" for k, v in chosen.items()])
    for path in recordings:
        o = evaluate([path], config)
        print(
            f"  {path.stem}: MOTA {100 * o.mota:5.1f} %  FP {o.fp}  FN {o.fn}  "
            f"IDSW {o.id_switches}  of {o.num_gt}"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
