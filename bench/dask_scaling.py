"""Scaling of the 9-point ``tracker.min_confidence`` sweep (issue 20) with 1 and 2 Dask workers.

Runs the sweep on ``local:1`` and ``local:2``, cold cache (a fresh folder) and warm
(the folder the cold run of the same cluster left), ``--reps`` times, interleaved
(cold 1, cold 2, warm 1, warm 2, then again), on two clusters started once and kept
(as a lab keeps a running scheduler and its workers; the start-up is reported
apart). Prints, per run, the sweep's wall clock, the CPU seconds of the client and
of every worker process, the load average before and after, and from the Dask task
stream each worker's busy seconds and the makespan; then the medians and ratios.

The wall-clock ratio is what an idle machine shows. On a shared one it is noise,
so the script also gives a load-independent estimate: ``CPU(local:1) /
(CPU(local:2) / (2 x utilisation))``, the 1-worker CPU seconds over the CPU seconds
the 2-worker run needed per worker slot, where utilisation is the workers' mean busy
share of the makespan (task stream). It equals the wall-clock ratio when each worker
has a core to itself.

    .venv/bin/python bench/dask_scaling.py               # moving_complex, 3 reps: ~2.5 min idle
    .venv/bin/python bench/dask_scaling.py --json runs/bench/dask_scaling.json

The recording is generated first when missing (``rgbd-eval synth moving_complex``, not
timed; about 80 CPU s).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from contextlib import ExitStack
from pathlib import Path
from typing import Any

from rgbd_eval import datasets
from rgbd_eval.config import load_config
from rgbd_eval.engine import ClusterSpec, connect
from rgbd_eval.errors import InputError
from rgbd_eval.sweep import SweepParam, expand_grid, point_configs, run_sweep

#: Table 7.6 of the thesis (seed 000): the 9 values of the sweep in issue 20.
VALUES = (-3.0, -2.5, -2.0, -1.75, -1.5, -1.0, -0.5, 0.0, 0.5)


def _cpu_here() -> float:
    """CPU seconds of this process (user + system), all threads."""
    t = os.times()
    return t.user + t.system


def _worker_cpu() -> float:
    import psutil

    t = psutil.Process().cpu_times()
    return float(t.user + t.system)


def _process_cpu(client: Any, in_process: bool) -> float:
    """CPU seconds of the client process, plus the worker processes when they are others."""
    if in_process:
        return _cpu_here()
    return _cpu_here() + sum(client.run(_worker_cpu).values())


def _stream_stats(records: list[dict[str, Any]]) -> dict[str, Any]:
    """Busy seconds per worker and the makespan, from Dask's task stream (compute spans)."""
    busy: dict[str, float] = {}
    starts, stops = [], []
    for rec in records:
        for span in rec.get("startstops", ()):
            if span.get("action") != "compute":
                continue
            busy[rec["worker"]] = busy.get(rec["worker"], 0.0) + span["stop"] - span["start"]
            starts.append(span["start"])
            stops.append(span["stop"])
    makespan = max(stops) - min(starts) if stops else 0.0
    utilisation = statistics.mean(b / makespan for b in busy.values()) if makespan else 0.0
    return {
        "tasks": len(records),
        "busy_s": sorted(round(b, 3) for b in busy.values()),
        "makespan_s": round(makespan, 3),
        "utilisation": round(utilisation, 3),
    }


def _one_run(
    client: Any, workers: int, recording: Path, cache: Path, configs: Any, grid: Any
) -> dict[str, Any]:
    from distributed import get_task_stream

    load_before = os.getloadavg()[0]
    cpu0 = _process_cpu(client, workers == 1)
    start = time.perf_counter()
    with get_task_stream(client) as stream:
        result = run_sweep([recording], grid, configs, client, cache_root=cache)
    wall = time.perf_counter() - start
    cpu = _process_cpu(client, workers == 1) - cpu0
    if result.failures:
        raise SystemExit(f"sweep failed: {result.failures[0].error}")
    return {
        "wall_s": round(wall, 3),
        "cpu_s": round(cpu, 3),
        "load_before": round(load_before, 2),
        "load_after": round(os.getloadavg()[0], 2),
        "detect_task_s": round(result.detect_seconds, 3),
        "track_task_s": round(result.track_seconds, 3),
        "cache_hits": result.cache_hits,
        "records": [(r.point, r.counts) for r in result.records],
        **_stream_stats(stream.data),
    }


def _summary(runs: list[dict[str, Any]]) -> dict[str, float]:
    return {
        k: round(statistics.median(r[k] for r in runs), 3)
        for k in ("wall_s", "cpu_s", "makespan_s", "utilisation", "load_before")
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--dataset", default="moving_complex")
    parser.add_argument("--reps", type=int, default=3)
    parser.add_argument("--json", type=Path, help="write every run and the summary here")
    args = parser.parse_args()

    try:
        recording = datasets.resolve(args.dataset)
    except InputError:  # not generated yet
        exe = Path(sys.executable).with_name("rgbd-eval")
        subprocess.run([str(exe), "synth", args.dataset], check=True)
        recording = datasets.resolve(args.dataset)
    base = load_config(method="basso2012").model_dump(mode="json")
    grid = expand_grid([SweepParam("tracker.min_confidence", VALUES)])
    configs = point_configs(base, [], grid)
    print(f"{recording} ({recording.stat().st_size / 1e6:.1f} MB), {len(grid)} points")

    scratch = Path(tempfile.mkdtemp(prefix="dask-scaling-"))
    runs: dict[tuple[str, int], list[dict[str, Any]]] = {}
    startup: dict[int, float] = {}
    try:
        with ExitStack() as stack:
            clients = {}
            for n in (1, 2):
                t0 = time.perf_counter()
                clients[n] = stack.enter_context(connect(ClusterSpec(None, n)))
                startup[n] = round(time.perf_counter() - t0, 3)
                print(f"local:{n} started in {startup[n]:.2f} s (wall)")
            reference = None
            for rep in range(args.reps):
                caches = {n: scratch / f"rep{rep}-local{n}" for n in (1, 2)}
                for mode in ("cold", "warm"):
                    for n in (1, 2):
                        run = _one_run(clients[n], n, recording, caches[n], configs, grid)
                        # Bit-identity across worker counts and cache states, checked every run.
                        records = run.pop("records")
                        reference = reference or records
                        if records != reference:
                            raise SystemExit(f"rep {rep} {mode} local:{n}: records differ")
                        runs.setdefault((mode, n), []).append(run)
                        print(
                            f"rep {rep + 1} {mode} local:{n}: wall {run['wall_s']:6.2f} s  "
                            f"cpu {run['cpu_s']:6.2f} s  load {run['load_before']:5.2f}"
                            f"->{run['load_after']:5.2f}  busy {run['busy_s']} of makespan "
                            f"{run['makespan_s']:.2f} s (utilisation {run['utilisation']:.2f}), "
                            f"{run['tasks']} tasks, cache hits {run['cache_hits']}"
                        )
    finally:
        shutil.rmtree(scratch, ignore_errors=True)

    summary: dict[str, Any] = {"startup_wall_s": startup}
    print("\nmedians and ratios (local:1 / local:2):")
    for mode in ("cold", "warm"):
        one, two = _summary(runs[(mode, 1)]), _summary(runs[(mode, 2)])
        wall_ratio = one["wall_s"] / two["wall_s"]
        # CPU seconds of local:1 over the CPU seconds local:2 needs per busy worker slot.
        estimate = one["cpu_s"] / (two["cpu_s"] / (2 * two["utilisation"]))
        with_startup = (one["wall_s"] + startup[1]) / (two["wall_s"] + startup[2])
        summary[mode] = {
            "local1": one,
            "local2": two,
            "wall_ratio": round(wall_ratio, 3),
            "wall_ratio_with_startup": round(with_startup, 3),
            "cpu_estimate_ratio": round(estimate, 3),
        }
        print(
            f"{mode}: wall {one['wall_s']:.2f} / {two['wall_s']:.2f} s = {wall_ratio:.2f}x "
            f"({with_startup:.2f}x counting cluster start-up); CPU {one['cpu_s']:.2f} / "
            f"{two['cpu_s']:.2f} s, utilisation of local:2 {two['utilisation']:.2f}: "
            f"estimate at no load {estimate:.2f}x; load {one['load_before']:.1f} / "
            f"{two['load_before']:.1f}"
        )
    if args.json is not None:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        payload = {
            "runs": {f"{m}-local{n}": r for (m, n), r in runs.items()},
            "summary": summary,
            "cpus": os.cpu_count(),
        }
        tmp = args.json.with_suffix(".tmp")
        tmp.write_text(json.dumps(payload, indent=1))
        os.replace(tmp, args.json)
    return 0


if __name__ == "__main__":
    sys.exit(main())
