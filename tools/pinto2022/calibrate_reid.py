"""Measure the re-ID embedders on ground-truth boxes and calibrate pinto2022's thresholds.

    .venv/bin/python tools/pinto2022/calibrate_reid.py datasets/demo.mcap [more.mcap ...]

For every recording (with its ``<name>.gt.csv``), every ground-truth box that is nearly
fully visible (visibility >= 0.95), inside the image and at least 80 px tall is embedded by
each embedder. Same-person pairs are taken at least 15 frames (0.5 s) apart, so pose has
changed; different-person pairs within the same recording. Prints, per embedder: the
separation (ROC AUC), the thresholds of :mod:`rgbd_eval.methods.pinto2022.reid_calibration`, and
milliseconds per crop on one thread; writes the numbers as JSON to stdout with --json.
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

from rgbd_eval.detect.reid import ColourTextureEmbedder, Embedder, builtin_mobilenet
from rgbd_eval.io.groundtruth import read_csv
from rgbd_eval.io.recording import open_recording
from rgbd_eval.methods.pinto2022.reid_calibration import calibrate, pair_distances, roc_auc

MIN_VISIBILITY = 0.95
MIN_HEIGHT_PX = 80.0
MIN_FRAME_GAP = 15
EVERY_NTH_FRAME = 3


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
    out = {"recordings": [str(p) for p in paths], "crops": crops, "embedders": {}}
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
            f"T_recover {r['t_recover']:.3f}  {r['ms_per_crop']:.2f} ms/crop"
        )


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--json"]
    main([Path(a) for a in args], "--json" in sys.argv)
