"""Scaling of the 9-point ``tracker.min_confidence`` sweep (issue 20) with 1 and 2 Dask workers.

Runs the sweep on ``local:1`` and ``local:2``, cold cache (a fresh folder) and warm
(the folder the cold run of the same cluster left), ``--reps`` times, interleaved
(cold 1, cold 2, warm 1, warm 2, then again), on two clusters started once and kept
(as a lab keeps a running scheduler and its workers; the start-up is reported
apart). Prints, per run, the sweep's wall clock, the CPU seconds of the client and
of every worker process, the load average before and after, the CPU time the
hypervisor stole (``/proc/stat``), and from the Dask task stream each worker's busy
seconds and the makespan; then the medians and ratios, and the ratio of each
repetition's pair (run back to back, so sharing the moment's load).

The wall-clock ratio is what an idle machine shows. On a shared one it is noise,
so the script also gives an estimate that the load moves less: the thread CPU
seconds of every task (each task function records its own, :func:`_instrument`; the
per-prefix sums are Dask's fine performance metrics) placed on the task graph
``run_sweep`` submits, list-scheduled on one slot for ``local:1``'s run and on two
for ``local:2``'s: the makespans an idle machine would give, without transfer,
scheduling or start-up costs. The JSON holds each run's per-task CPU seconds and
its timeline (task, action, worker, start, stop).

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

import rgbd_eval.cli  # noqa: F401  # first: the CLI's one-thread environment
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


def _steal_s() -> float | None:
    """Seconds the hypervisor ran something else while this machine's CPUs wanted to run
    (``steal`` in ``/proc/stat``, all CPUs), or None where there is no such count."""
    try:
        fields = Path("/proc/stat").read_text().split("\n", 1)[0].split()
        return int(fields[8]) / os.sysconf("SC_CLK_TCK")
    except (OSError, IndexError, ValueError):
        return None


def _worker_cpu() -> float:
    import psutil

    t = psutil.Process().cpu_times()
    return float(t.user + t.system)


def _process_cpu(client: Any, in_process: bool) -> float:
    """CPU seconds of the client process, plus the worker processes when they are others."""
    if in_process:
        return _cpu_here()
    return _cpu_here() + float(sum(client.run(_worker_cpu).values()))


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


def _timeline(records: list[dict[str, Any]]) -> list[tuple[str, str, str, float, float]]:
    """``(task, action, worker, start, stop)`` of every span of the task stream (compute, and
    transfer of the task's inputs to its worker), seconds from the first start."""
    spans = [
        (
            str(rec["key"]).rsplit("-", 1)[0],
            str(s["action"]),
            str(rec["worker"]),
            s["start"],
            s["stop"],
        )
        for rec in records
        for s in rec.get("startstops", ())
    ]
    t0 = min((s[3] for s in spans), default=0.0)
    return sorted(
        ((k, a, w[-5:], round(b - t0, 3), round(c - t0, 3)) for k, a, w, b, c in spans),
        key=lambda span: span[3],
    )


async def _heartbeat(dask_worker: Any) -> None:
    """Send the worker's metrics to the scheduler now (they travel with heartbeats)."""
    await dask_worker.heartbeat()


def _execute_metrics(dask_scheduler: Any) -> dict[str, float]:
    """Thread CPU seconds of the tasks run so far, per task prefix (Dask's fine metrics)."""
    out: dict[str, float] = {}
    for key, value in dask_scheduler.cumulative_worker_metrics.items():
        if isinstance(key, tuple) and key[0] == "execute" and key[2:] == ("thread-cpu", "seconds"):
            name = str(key[1]).lstrip("_")
            out[name] = out.get(name, 0.0) + value
    return out


def _task_cpu(client: Any) -> dict[str, float]:
    client.run(_heartbeat)
    result: dict[str, float] = client.run_on_scheduler(_execute_metrics)
    return result


def _schedule(tasks: list[tuple[str, float, list[str]]], workers: int) -> float:
    """Makespan of ``(name, seconds, dependencies)`` (in submission order, the scheduler's
    priority) on ``workers`` slots by list scheduling: each free slot takes the first
    ready task. No transfer or scheduling cost: the estimate of an idle machine."""
    done: dict[str, float] = {}
    free = [0.0] * workers
    pending = list(tasks)
    while pending:
        slot = min(range(workers), key=lambda i: free[i])
        ready = [t for t in pending if all(d in done for d in t[2])]
        # The first task (submission order) whose inputs are ready soonest.
        name, seconds, deps = min(ready, key=lambda t: max([done[d] for d in t[2]] + [0.0]))
        start = max([free[slot], *(done[d] for d in deps)])
        done[name] = free[slot] = start + seconds
        pending.remove((name, seconds, deps))
    return max(done.values())


#: The sweep's task functions (rgbd_eval.sweep), each timed by :func:`_instrument`.
TASKS = ("_prepare", "_advance", "_detect_chunk", "_join", "_brief", "_track", "_score")


def _instrument() -> None:
    """Make the sweep's task functions in this process record their thread CPU seconds in
    their task's metadata, which the task stream carries (run on every worker)."""
    import functools

    from distributed import get_worker

    from rgbd_eval import sweep

    def timed(func: Any) -> Any:
        @functools.wraps(func)
        def run(*args: Any) -> Any:
            start = time.thread_time()
            try:
                return func(*args)
            finally:
                worker = get_worker()
                task = worker.state.tasks.get(worker.get_current_task())
                if task is not None:
                    task.metadata["thread_cpu_s"] = time.thread_time() - start

        return run

    for name in TASKS:
        func = getattr(sweep, name)
        if not hasattr(func, "__wrapped__"):
            setattr(sweep, name, timed(func))


def _task_costs(records: list[dict[str, Any]]) -> dict[str, float]:
    """Thread CPU seconds of each task, by its name (``prefix`` or ``prefix-index``)."""
    from dask.utils import key_split

    out = {}
    for rec in records:
        key = str(rec["key"])
        prefix = key_split(key).lstrip("_")
        parts = key.split("-")
        name = f"{prefix}-{parts[1]}" if len(parts) == 3 and parts[1].isdigit() else prefix
        out[name] = float((rec.get("metadata") or {}).get("thread_cpu_s", 0.0))
    return out


def _sweep_graph(costs: dict[str, float]) -> list[tuple[str, float, list[str]]]:
    """The task graph ``run_sweep`` submits for one recording, in submission order, each task
    with its thread CPU seconds (:func:`_task_costs`)."""

    def named(prefix: str) -> list[str]:
        return sorted(
            (n for n in costs if n.split("-")[0] == prefix), key=lambda n: int(n[len(prefix) + 1 :])
        )

    graph: list[tuple[str, float, list[str]]] = [("prepare", costs["prepare"], [])]
    last = "prepare"
    chunks = named("detect_chunk")
    if chunks:
        advances = named("advance")
        for k, name in enumerate(advances):
            graph.append((name, costs[name], ["prepare"] + advances[k - 1 : k] * (k > 0)))
        for k, name in enumerate(chunks):
            graph.append((name, costs[name], ["prepare"] + advances[k - 1 : k] * (k > 0)))
        graph.append(("join", costs["join"], ["prepare", *chunks]))
        last = "join"
    graph.append(("brief", costs["brief"], [last]))
    tracks = named("track")
    graph += [(name, costs[name], [last]) for name in tracks]
    graph += [
        (f"score-{name.split('-')[1]}", costs[f"score-{name.split('-')[1]}"], [last, name])
        for name in tracks
    ]
    return graph


def _one_run(
    client: Any, workers: int, recording: Path, cache: Path, configs: Any, grid: Any
) -> dict[str, Any]:
    from dask.utils import key_split
    from distributed import get_task_stream

    load_before = os.getloadavg()[0]
    steal0 = _steal_s()
    tasks0 = _task_cpu(client)
    cpu0 = _process_cpu(client, workers == 1)
    start = time.perf_counter()
    with get_task_stream(client) as stream:
        result = run_sweep([recording], grid, configs, client, cache_root=cache)
    wall = time.perf_counter() - start
    steal1 = _steal_s()
    cpu = _process_cpu(client, workers == 1) - cpu0
    tasks1 = _task_cpu(client)
    task_cpu = {k: round(v - tasks0.get(k, 0.0), 3) for k, v in tasks1.items()}
    task_cpu = {k: v for k, v in task_cpu.items() if v > 0}
    counts: dict[str, int] = {}
    for rec in stream.data:
        prefix = key_split(rec["key"]).lstrip("_")
        counts[prefix] = counts.get(prefix, 0) + 1
    costs = _task_costs(stream.data)
    graph = _sweep_graph(costs)
    if result.failures:
        raise SystemExit(f"sweep failed: {result.failures[0].error}")
    return {
        "wall_s": round(wall, 3),
        "cpu_s": round(cpu, 3),
        "load_before": round(load_before, 2),
        "load_after": round(os.getloadavg()[0], 2),
        "steal_s": None if steal0 is None or steal1 is None else round(steal1 - steal0, 2),
        "detect_task_s": round(result.detect_seconds, 3),
        "track_task_s": round(result.track_seconds, 3),
        "cache_hits": result.cache_hits,
        "records": [(r.point, r.counts) for r in result.records],
        "task_cpu_s": task_cpu,
        "task_counts": counts,
        "task_cpu_each_s": {k: round(v, 3) for k, v in costs.items()},
        "timeline": _timeline(stream.data),
        # Idle-machine makespans of this run's graph from its tasks' CPU seconds.
        "estimate_1_s": round(_schedule(graph, 1), 3),
        "estimate_2_s": round(_schedule(graph, 2), 3),
        **_stream_stats(stream.data),
    }


def _summary(runs: list[dict[str, Any]]) -> dict[str, float]:
    keys = ("wall_s", "cpu_s", "makespan_s", "utilisation", "load_before")
    out = {k: round(statistics.median(r[k] for r in runs), 3) for k in keys}
    for k in ("estimate_1_s", "estimate_2_s"):
        out[k] = round(statistics.median(r[k] for r in runs), 3)
    return out


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
                clients[n].run(_instrument)
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
                            f"->{run['load_after']:5.2f}  steal {run['steal_s']} s  "
                            f"busy {run['busy_s']} of makespan "
                            f"{run['makespan_s']:.2f} s (utilisation {run['utilisation']:.2f}), "
                            f"{run['tasks']} tasks, cache hits {run['cache_hits']}; "
                            f"task CPU {run['task_cpu_s']}; idle estimate on 1 / 2 slots "
                            f"{run['estimate_1_s']:.2f} / {run['estimate_2_s']:.2f} s"
                        )
    finally:
        shutil.rmtree(scratch, ignore_errors=True)

    summary: dict[str, Any] = {"startup_wall_s": startup}
    print("\nmedians and ratios (local:1 / local:2):")
    for mode in ("cold", "warm"):
        one, two = _summary(runs[(mode, 1)]), _summary(runs[(mode, 2)])
        wall_ratio = one["wall_s"] / two["wall_s"]
        with_startup = (one["wall_s"] + startup[1]) / (two["wall_s"] + startup[2])
        # Idle machine: local:1's graph on one slot over local:2's graph on two, every task
        # taking the thread CPU seconds it took in its run.
        estimate = one["estimate_1_s"] / two["estimate_2_s"]
        # Each repetition's pair ran back to back, so its ratio shares most of the moment's load.
        per_rep = [
            round(a["wall_s"] / b["wall_s"], 3)
            for a, b in zip(runs[(mode, 1)], runs[(mode, 2)], strict=True)
        ]
        summary[mode] = {
            "local1": one,
            "local2": two,
            "wall_ratio": round(wall_ratio, 3),
            "wall_ratio_with_startup": round(with_startup, 3),
            "estimate_ratio": round(estimate, 3),
            "wall_ratio_per_rep": per_rep,
        }
        print(
            f"{mode}: wall {one['wall_s']:.2f} / {two['wall_s']:.2f} s = {wall_ratio:.2f}x "
            f"({with_startup:.2f}x counting cluster start-up), load {one['load_before']:.1f} / "
            f"{two['load_before']:.1f}; process CPU {one['cpu_s']:.2f} / {two['cpu_s']:.2f} s; "
            f"task-stream utilisation of local:2 {two['utilisation']:.2f}; critical path from "
            f"task CPU: {one['estimate_1_s']:.2f} / {two['estimate_2_s']:.2f} s = {estimate:.2f}x"
        )
        print(
            f"{mode}: per repetition {', '.join(f'{r:.2f}' for r in per_rep)}x "
            f"(median {statistics.median(per_rep):.2f}x)"
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
