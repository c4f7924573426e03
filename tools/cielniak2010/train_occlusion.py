"""Train the cielniak2010 occlusion classifier and write the shipped model file.

    .venv/bin/python tools/cielniak2010/train_occlusion.py [--out PATH] [--stride N]
        [--limit N] [--rounds R]

Renders the overlapping pairs of people in the frames of the tuning scenes
(``configs/scenarios/tuning/cielniak2010_*_tuning.yaml``) at the training seeds of
:class:`~rgbd_eval.methods.cielniak2010.occlusion_training.TrainingPlan`, trains one
discrete AdaBoost per feature group (thermal, colour, both), prints the accuracy per group
on the plan's held-out tuning seeds and writes the stumps with their provenance to
``src/rgbd_eval/methods/cielniak2010/occlusion.json`` (atomically). The scenes
``reproduce`` scores are never read. Same arguments, same bytes on every x86-64 CPU (the
renderer, the features and the boosting use only exact arithmetic: rgbd_eval.exact).
About 1 s of CPU per rendered pair (about 4 min for the default plan).
"""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import replace
from pathlib import Path

from rgbd_eval.atomic import write_json
from rgbd_eval.methods.cielniak2010.occlusion import MODEL_PATH
from rgbd_eval.methods.cielniak2010.occlusion_training import (
    TrainingPlan,
    evaluate,
    model_document,
    train_groups,
)


def main(argv: list[str]) -> int:
    d = TrainingPlan()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=MODEL_PATH)
    ap.add_argument("--stride", type=int, default=d.stride)
    ap.add_argument("--limit", type=int, default=d.limit)
    ap.add_argument("--held-out-stride", type=int, default=d.held_out_stride)
    ap.add_argument("--jitter", type=float, default=d.jitter)
    ap.add_argument("--rounds", type=int, default=d.rounds)
    a = ap.parse_args(argv)
    plan = replace(
        d,
        stride=a.stride,
        limit=a.limit,
        held_out_stride=a.held_out_stride,
        jitter=a.jitter,
        rounds=a.rounds,
    )
    t0 = time.process_time()
    train = plan.training_data()
    test = plan.held_out_data()
    t1 = time.process_time()
    classifiers = train_groups(train, plan.rounds)
    held_out = evaluate(classifiers, test)
    t2 = time.process_time()
    print(f"{len(train)} training pairs, {len(test)} held-out pairs (tuning scenes)")
    for group, r in held_out.items():
        print(
            f"{group:8s} accuracy {r['accuracy']:.3f} on {r['pairs']} held-out pairs; "
            f"{r['accuracy_half_hidden']} on the {r['pairs_half_hidden']} with the back "
            f"person at most half visible; {r['stumps']} stumps"
        )
    print(f"CPU: rendering {t1 - t0:.1f} s, training and evaluation {t2 - t1:.2f} s")
    write_json(a.out, model_document(classifiers, plan, held_out, len(train)))
    print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
