"""The analysis' cost on top of scoring: breakdowns and intervals against scoring alone.

    .venv/bin/python bench/analysis_cost.py [--runs 40] [--rounds 3] [--ours SRC ...]
        [--demo RECORDING] [--json FILE]

Two inputs, as issue 33 states its budget (the analysis at most 20 % on top of scoring):

- the TUD MOTChallenge folder shipped in the motmetrics 1.4 wheel (a dev dependency):
  TUD-Campus and TUD-Stadtmitte, as ``score`` reads them;
- the demo: ``rgbd-eval synth demo`` (written once into a temporary folder, not timed;
  ``--demo`` reuses a recording with its ``.gt.csv``) run by the default method (basso2012)
  as ``make run`` does, its tracks scored against the ground truth.

Each measurement runs in a child process pinned to one CPU, once per ``--ours`` source
folder (``PYTHONPATH``; default: the rgbd_eval the interpreter finds), alternating
over ``--rounds`` rounds (the machine may be shared). A child prepares its inputs (the
demo run, not timed), then times in one process by CPU time (``time.process_time``),
interleaved, the fastest of ``--runs``: scoring alone (TUD: ``report.scoring.
score_sequence`` of each sequence, reading, aligning and scoring; demo:
``pipeline.match_ground_truth`` + ``pipeline.score_sequence`` of the run's tracks) and
``report.analysis.analyse()`` of the scored sequences (1000 replicates, the default;
breakdowns, intervals and the per-frame tables). Each input's first call of
``analyse()`` is reported on its own: the TUD folder's comes first in the process, as in
``score`` (numba's runtime started and the bootstrap's kernels loaded from their cache, or
compiled if none is there), the demo's after the run (whose detector started numba).
Prints each child's figures, the ratios analysis / scoring per input over the rounds, the
CPU model and the load average.
"""

from __future__ import annotations

import argparse
import functools
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

#: The TUD sequences of the motmetrics wheel.
TUD = ("TUD-Campus", "TUD-Stadtmitte")

CHILD = """
import json, sys, time
from pathlib import Path
sys.path.insert(0, {bench!r})
from analysis_cost import child
print(json.dumps(child(Path(sys.argv[1]), Path(sys.argv[2]), int(sys.argv[3]))))
"""


def cpu_model() -> str:
    """The CPU's model name (:func:`rgbd_eval.machine.machine_info`)."""
    from rgbd_eval.machine import machine_info

    return machine_info()["cpu"] or "unknown"


def race(functions: list[Callable[[], object]], runs: int) -> list[float]:
    """CPU milliseconds of each function, the fastest of ``runs``, called in turn."""
    best = [float("inf")] * len(functions)
    for _ in range(runs):
        for k, f in enumerate(functions):
            start = time.process_time()
            f()
            best[k] = min(best[k], time.process_time() - start)
    return [t * 1e3 for t in best]


def child(demo: Path, tud: Path, runs: int) -> dict[str, Any]:
    """In one process: scoring and ``analyse()`` of the TUD folder and of the demo."""
    from rgbd_eval import pipeline
    from rgbd_eval.config import EvaluationConfig, load_config
    from rgbd_eval.report import analysis
    from rgbd_eval.report.scoring import score_sequence

    out: dict[str, Any] = {}
    evaluation = EvaluationConfig()

    def score_tud() -> list[Any]:
        return [
            score_sequence(n, tud / n / "test.txt", tud / n / "gt.txt", evaluation, 0) for n in TUD
        ]

    def first_call(items: list[Any], ev: EvaluationConfig) -> float:
        start = time.process_time()
        analysis.analyse(items, ev)
        return (time.process_time() - start) * 1e3

    # The TUD folder first, as ``score`` meets it: nothing compiled has run in the process.
    tud_items = analysis.inputs_of_score(score_tud())
    firsts = {"tud": first_call(tud_items, evaluation)}
    config = load_config(method="basso2012")
    result = pipeline.run_sequence(demo, config)
    gt = pipeline.ground_truth_file(demo, None)
    if gt is None:
        sys.exit(f"{demo}: no ground truth beside it (<name>.gt.csv)")

    def score_demo() -> object:
        match = pipeline.match_ground_truth(gt, result.detections.stamps_ns, config)
        return pipeline.score_sequence(match, result.tracks, config)

    demo_items = analysis.inputs_of_run([result])
    firsts["demo"] = first_call(demo_items, config.evaluation)
    inputs = {
        "tud": (score_tud, tud_items, evaluation),
        "demo": (score_demo, demo_items, config.evaluation),
    }
    for name, (score, items, ev) in inputs.items():
        analyse = functools.partial(analysis.analyse, items, ev)
        scoring, analysed = race([score, analyse], runs)
        out[name] = {"scoring_ms": scoring, "analysis_ms": analysed, "first_call_ms": firsts[name]}
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=40, help="timed calls of each (fastest)")
    parser.add_argument("--rounds", type=int, default=3, help="child processes per source")
    parser.add_argument(
        "--ours",
        action="append",
        metavar="SRC",
        help="a source folder holding rgbd_eval (PYTHONPATH); repeat to compare versions",
    )
    parser.add_argument("--demo", type=Path, help="the demo recording (default: synthesized)")
    parser.add_argument("--json", type=Path, help="also write the numbers here")
    args = parser.parse_args()
    try:
        import motmetrics
    except ImportError:
        sys.exit("the TUD folder comes with motmetrics 1.4 (a dev dependency): not installed")
    tud = Path(motmetrics.__file__).parent / "data"
    cpu = min(os.sched_getaffinity(0))
    variants = args.ours or [None]
    with tempfile.TemporaryDirectory(prefix="analysis_cost-") as tmp:
        demo = args.demo
        if demo is None:
            demo = Path(tmp) / "demo.mcap"
            synth = [sys.executable, "-m", "rgbd_eval", "synth", "demo", "-o", str(demo)]
            subprocess.run(synth, check=True, capture_output=True, env=_env(variants[0]))
        code = CHILD.format(bench=str(Path(__file__).resolve().parent))
        results: dict[str, list[dict[str, Any]]] = {}
        for r in range(args.rounds):
            for src in variants:
                label = src or "ours"
                cmd = [sys.executable, "-c", code, str(demo), str(tud), str(args.runs)]
                done = subprocess.run(
                    cmd,
                    env=_env(src),
                    capture_output=True,
                    text=True,
                    preexec_fn=lambda: os.sched_setaffinity(0, {cpu}),
                )
                if done.returncode != 0:
                    sys.exit(f"{label} failed ({done.returncode}):\n{done.stderr[-2000:]}")
                figures = json.loads(done.stdout.splitlines()[-1])
                results.setdefault(label, []).append(figures)
                print(f"round {r} {label}: {_line(figures)}  (load {_load()})")
    print(f"CPU: {cpu_model()}, one core (cpu {cpu}); {args.runs} calls each, fastest")
    summary: dict[str, dict[str, list[float]]] = {}
    for label, rounds in results.items():
        ratios = {
            name: sorted(f[name]["analysis_ms"] / f[name]["scoring_ms"] for f in rounds)
            for name in ("tud", "demo")
        }
        summary[label] = ratios
        print(
            f"  {label}: analysis / scoring over {len(rounds)} rounds: "
            + ", ".join(
                f"{name} {100 * r[0]:.1f} to {100 * r[-1]:.1f} % (median "
                f"{100 * statistics.median(r):.1f} %)"
                for name, r in ratios.items()
            )
        )
    print(f"load average {_load()}")
    if args.json:
        doc = {"cpu": cpu_model(), "runs": args.runs, "rounds": results, "ratios": summary}
        args.json.write_text(json.dumps(doc, indent=1) + "\n")


def _line(figures: dict[str, Any]) -> str:
    return "  ".join(
        f"{name} {f['analysis_ms']:.2f} ms on {f['scoring_ms']:.1f} ms "
        f"({100 * f['analysis_ms'] / f['scoring_ms']:.1f} %, first call {f['first_call_ms']:.0f} ms)"
        for name, f in figures.items()
    )


def _load() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def _env(src: str | None) -> dict[str, str]:
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1")
    if src is not None:
        env["PYTHONPATH"] = src
    return env


if __name__ == "__main__":
    main()
