"""Measure the re-ID embedders on tuning scenes and calibrate pinto2022's thresholds (issue 31).

    PYTHONPATH=src nice -n 10 .venv/bin/python tools/pinto2022/calibrate_reid.py \
        configs/scenarios/tuning/pinto2022_corridor_tuning.yaml \
        configs/scenarios/tuning/pinto2022_lounge_tuning.yaml

It takes TUNING scenes only (a scenario whose name ends ``_tuning``; never a scene that
``reproduce`` scores): each is rendered with ``synth`` into a temporary folder and read back,
so the embedders see the decoded frames the method sees. The values it prints are written
with this measurement in ``methods/pinto2022/method.yaml`` and judged on the scored scenes.

For every recording (with its ``<name>.gt.csv``), every ground-truth box that is nearly
fully visible (visibility >= 0.95), inside the image and at least 80 px tall is embedded by
each embedder. Same-person pairs are taken at least 15 frames (0.5 s) apart, so pose has
changed; different-person pairs within the same recording. Prints, per embedder: the
separation (ROC AUC), the thresholds of :mod:`rgbd_eval.methods.pinto2022.reid_calibration`, and
milliseconds per crop on one thread (the only number that varies between runs); writes the
numbers as JSON to stdout with --json. T_recover is chosen by the project's rule (fewest wrong
recover decisions, middle of the widest best interval); the equal-error distance is printed
beside it.
"""

from __future__ import annotations

import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from rgbd_eval.detect.reid import ColourTextureEmbedder, Embedder, builtin_mobilenet
from rgbd_eval.io.groundtruth import read_csv
from rgbd_eval.io.recording import open_recording
from rgbd_eval.methods.pinto2022.reid_calibration import (
    calibrate,
    equal_error_threshold,
    pair_distances,
    roc_auc,
)
from rgbd_eval.sim.scenario import load_scenario
from rgbd_eval.sim.synth import synthesize

MIN_VISIBILITY = 0.95
MIN_HEIGHT_PX = 80.0
MIN_FRAME_GAP = 15
EVERY_NTH_FRAME = 3


def render(scenes: list[Path], folder: Path) -> list[Path]:
    """Each tuning scene rendered to ``folder`` (SystemExit for a scene not named ``*_tuning``)."""
    out = []
    for scene in scenes:
        scenario = load_scenario(scene)
        if not scenario.name.endswith("_tuning"):
            raise SystemExit(f"error: {scene}: not a tuning scene (its name must end _tuning)")
        path = folder / f"{scenario.name}.mcap"
        print(f"rendering {scene} ({scenario.duration_s:g} s) ...", file=sys.stderr)
        synthesize(scenario, path, "mcap")
        out.append(path)
    return out


def main(paths: list[Path], as_json: bool) -> None:
    embedders: dict[str, Embedder] = {
        "colour_texture": ColourTextureEmbedder(),
        "mobilenet": builtin_mobilenet(),
    }
    same: dict[str, list[np.ndarray]] = {k: [] for k in embedders}
    diff: dict[str, list[np.ndarray]] = {k: [] for k in embedders}
    seconds = dict.fromkeys(embedders, 0.0)
    crops = 0
    for path in paths:
        gt = read_csv(path.with_name(path.name.rsplit(".", 1)[0] + ".gt.csv"))
        rec = open_recording(path)
        frames = list(rec.frames())
        per_frame, _ = gt.align([f.stamp_ns for f in frames], 1_000_000)
        vecs: dict[str, list[np.ndarray]] = {k: [] for k in embedders}
        ids: list[int] = []
        idx: list[int] = []
        for f, objs in zip(frames, per_frame, strict=True):
            if f.index % EVERY_NTH_FRAME:
                continue
            h, w = f.rgb.shape[:2]
            boxes = [
                o
                for o in objs
                if o.box2d is not None
                and not o.ignore
                and o.visibility >= MIN_VISIBILITY
                and o.box2d.height >= MIN_HEIGHT_PX
                and o.box2d.left >= 0
                and o.box2d.top >= 0
                and o.box2d.right <= w
                and o.box2d.bottom <= h
            ]
            if not boxes:
                continue
            for name, emb in embedders.items():
                t = time.perf_counter()
                vecs[name].append(emb.embed(f.rgb, [o.box2d for o in boxes if o.box2d]))
                seconds[name] += time.perf_counter() - t
            ids += [o.object_id for o in boxes]
            idx += [f.index] * len(boxes)
            crops += len(boxes)
        for name in embedders:
            s, d = pair_distances(
                np.concatenate(vecs[name]), np.asarray(ids), np.asarray(idx), MIN_FRAME_GAP
            )
            same[name].append(s)
            diff[name].append(d)
    out = {"recordings": [p.name for p in paths], "crops": crops, "embedders": {}}
    for name in embedders:
        s, d = np.concatenate(same[name]), np.concatenate(diff[name])
        th = calibrate(s, d)
        out["embedders"][name] = {
            "auc": roc_auc(s, d),
            "same_median": float(np.median(s)),
            "different_median": float(np.median(d)),
            "t_lower": th.t_lower,
            "t_upper": th.t_upper,
            "t_recover": th.t_recover,
            "equal_error": equal_error_threshold(s, d),
            "ms_per_crop": 1000 * seconds[name] / max(crops, 1),
            "pairs_same": int(s.size),
            "pairs_different": int(d.size),
        }
    if as_json:
        json.dump(out, sys.stdout, indent=2)
        print()
        return
    print(f"{crops} crops from {len(paths)} recordings")
    for name, r in out["embedders"].items():
        print(
            f"{name:15s} AUC {r['auc']:.3f}  median same {r['same_median']:.3f} / different "
            f"{r['different_median']:.3f}  T_lower {r['t_lower']:.3f}  T_upper {r['t_upper']:.3f}  "
            f"T_recover {r['t_recover']:.3f} (equal error {r['equal_error']:.3f})  "
            f"pairs {r['pairs_same']} same / {r['pairs_different']} different  "
            f"{r['ms_per_crop']:.2f} ms/crop"
        )


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--json"]
    if not args:
        raise SystemExit("usage: calibrate_reid.py TUNING_SCENE.yaml [...] [--json]")
    with tempfile.TemporaryDirectory(prefix="calibrate_reid-") as tmp:
        main(render([Path(a) for a in args], Path(tmp)), "--json" in sys.argv)
