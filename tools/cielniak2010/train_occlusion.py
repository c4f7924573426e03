"""Train the cielniak2010 occlusion classifier and write the shipped model file.

    .venv/bin/python tools/cielniak2010/train_occlusion.py [--out PATH] [--train-pairs N]
        [--test-pairs N] [--rounds R] [--train-seed S] [--test-seed S]

Renders ``--train-pairs`` overlapping pairs for the training seed and ``--test-pairs`` for
the held-out seed (:mod:`rgbd_eval.sim.occlusion_pairs`), trains one discrete AdaBoost per
feature group (thermal, colour, both; :mod:`rgbd_eval.methods.cielniak2010.occlusion_training`), prints
the held-out accuracy per group and writes the stumps with their provenance to
``src/rgbd_eval/methods/cielniak2010/occlusion.json`` (atomically). Same arguments, same file
(on one machine and library versions: the features go through numpy's floating point).
About 0.3 s of CPU per rendered pair.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from rgbd_eval.atomic import write_json
from rgbd_eval.methods.cielniak2010.occlusion import MODEL_PATH
from rgbd_eval.methods.cielniak2010.occlusion_training import (
    TrainingPlan,
    evaluate,
    model_document,
    render_features,
    train_groups,
)


def main(argv: list[str]) -> int:
    d = TrainingPlan()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=MODEL_PATH)
    ap.add_argument("--train-seed", type=int, default=d.train_seed)
    ap.add_argument("--train-pairs", type=int, default=d.train_pairs)
    ap.add_argument("--test-seed", type=int, default=d.test_seed)
    ap.add_argument("--test-pairs", type=int, default=d.test_pairs)
    ap.add_argument("--jitter", type=float, default=d.jitter)
    ap.add_argument("--rounds", type=int, default=d.rounds)
    a = ap.parse_args(argv)
    if a.train_seed == a.test_seed:
        ap.error("the held-out seed must differ from the training seed")
    plan = TrainingPlan(a.train_seed, a.train_pairs, a.test_seed, a.test_pairs, a.jitter, a.rounds)
    t0 = time.process_time()
    train = render_features(plan.train_seed, plan.train_pairs, plan.jitter)
    test = render_features(plan.test_seed, plan.test_pairs, plan.jitter)
    t1 = time.process_time()
    classifiers = train_groups(train, plan.rounds)
    held_out = evaluate(classifiers, test)
    t2 = time.process_time()
    for group, r in held_out.items():
        print(
            f"{group:8s} accuracy {r['accuracy']:.3f} on {r['pairs']} held-out pairs; "
            f"{r['accuracy_half_hidden']} on the {r['pairs_half_hidden']} with the back "
            f"person at most half visible; {r['stumps']} stumps"
        )
    print(f"CPU: rendering {t1 - t0:.1f} s, training and evaluation {t2 - t1:.2f} s")
    write_json(a.out, model_document(classifiers, plan, held_out))
    print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
