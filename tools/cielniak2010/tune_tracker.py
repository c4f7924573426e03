"""Compare cielniak2010 tracker settings on held-out recordings and tracker seeds.

    .venv/bin/python tools/cielniak2010/tune_tracker.py REC.mcap [REC.mcap ...]
        --seeds 100 101 102 --variant NAME KEY=VALUE[,KEY=VALUE...] [--variant ...]
        [--workers 2]

Every variant runs on every recording for every tracker seed (``tracker.seed``); the
counts are summed over the recordings per seed and the mean (min .. max) over the seeds
of ID switches, MOTA and IDF1 printed, with the ID switches per recording. The tracker
values of ``methods/cielniak2010/method.yaml`` (surround, surround_weight, colour_scale) were
chosen with it on the tuning scenes (``configs/scenarios/tuning/cielniak2010_*_tuning.yaml``
at scenario seeds 201/211 and 202/212, tracker seeds 100-101), never on the scenes
``reproduce`` scores.
"""

from __future__ import annotations

import argparse
import statistics
import sys
from pathlib import Path
from typing import Any

import yaml

from rgbd_eval.config import load_config
from rgbd_eval.engine import ClusterSpec, connect
from rgbd_eval.metrics import summarize, total
from rgbd_eval.pipeline import sequence_name
from rgbd_eval.sweep import point_configs, run_sweep


def _overrides(text: str) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for item in filter(None, text.split(",")):
        key, _, value = item.partition("=")
        out[key] = yaml.safe_load(value)
    return out


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("recordings", type=Path, nargs="+")
    ap.add_argument("--seeds", type=int, nargs="+", default=[100, 101, 102])
    ap.add_argument("--variant", nargs=2, action="append", metavar=("NAME", "OVERRIDES"))
    ap.add_argument("--workers", type=int, default=1)
    args = ap.parse_args(argv)
    variants = {name: _overrides(text) for name, text in args.variant or [("default", "")]}
    base = load_config(method="cielniak2010").model_dump(mode="json")
    points = [{**v, "tracker.seed": s} for v in variants.values() for s in args.seeds]
    labels = [(n, s) for n in variants for s in args.seeds]
    configs = point_configs(base, [], points)
    with connect(ClusterSpec(None, args.workers)) as client:
        result = run_sweep(list(args.recordings), points, configs, client)
    for f in result.failures:
        print(f"failed: {f.point} on {f.sequence}: {f.error}", file=sys.stderr)
    per: dict[str, dict[int, dict[str, Any]]] = {}
    for r in result.records:
        name, seed = labels[points.index(r.point)]
        per.setdefault(name, {}).setdefault(seed, {})[r.sequence] = r.counts
    names = [sequence_name(p) for p in args.recordings]
    print(f"{'variant':<16} {'IDSW':>18} {'MOTA':>22} {'IDF1':>22}  IDSW per recording")
    for name, by_seed in per.items():
        sums = [summarize(total(c.values())) for c in by_seed.values()]

        def cell(m: str, sums: list[dict[str, Any]] = sums) -> str:
            v = [float(s[m]) for s in sums]
            return f"{statistics.fmean(v):.3f} ({min(v):.3f}..{max(v):.3f})"

        scen = " ".join(
            f"{n}:{statistics.fmean(summarize(c[n])['id_switches'] for c in by_seed.values()):.1f}"
            for n in names
        )
        print(f"{name:<16} {cell('id_switches'):>18} {cell('mota'):>22} {cell('idf1'):>22}  {scen}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
