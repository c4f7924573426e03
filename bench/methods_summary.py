"""One line per method from ``rgbd-eval bench --json`` files: CPU fps on one core, the
decode floor, their ratio, and whether the method reaches 60 fps (issue 32's target).

    .venv/bin/python -m bench.methods_summary runs/bench/method_*.json

The CPU fps is what an idle core gives (the process's user + system time per frame);
the ratio is the pipeline's CPU time per frame over the decode floor's time per frame
(the floor is wall time: on a loaded machine it grows, and the ratio reads low).
The machine (CPU model) comes from the JSON (schema 3).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

TARGET_FPS = 60.0


def main(paths: list[str]) -> None:
    if not paths:
        sys.exit("usage: python -m bench.methods_summary BENCH.json ...")
    rows = []
    machines = set()
    for name in paths:
        data = json.loads(Path(name).read_text(encoding="utf-8"))
        machine = data.get("machine") or {}
        machines.add(machine.get("cpu", "unknown"))
        cpu_ms, floor_ms = data["cpu_ms"], data["floor_ms"]
        dw, dh = data["depth_size"]
        rw, rh = data["rgb_size"]
        fps = 1e3 / cpu_ms if cpu_ms > 0 else float("inf")
        sizes = [f"RGB {rw}x{rh}"] if rw else []
        sizes += [f"depth {dw}x{dh}"] if dw else []
        rows.append(
            (
                data["method"].split(" (")[0],  # "basso2012 (basso2012 + basso2012)"
                Path(data["path"]).name,
                ", ".join(sizes) or "other streams",
                data["frames"],
                fps,
                data["floor_fps"],
                cpu_ms / floor_ms,
            )
        )
    print(f"machine: {'; '.join(sorted(machines))}")
    print(
        f"{'method':13} {'recording':24} {'images':26} {'frames':>6} {'CPU fps':>8} "
        f"{'floor fps':>9} {'CPU/floor':>9}"
    )
    for method, rec, size, frames, fps, floor_fps, ratio in rows:
        flag = "" if fps >= TARGET_FPS else f"  below {TARGET_FPS:g} fps"
        print(
            f"{method:13} {rec:24} {size:26} {frames:6d} {fps:8.1f} {floor_fps:9.1f} "
            f"{ratio:9.2f}{flag}"
        )


if __name__ == "__main__":
    main(sys.argv[1:])
