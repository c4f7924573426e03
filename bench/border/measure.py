"""Measure ``detector.hog_border`` skip vs pad on recordings where people are cut by the image.

Run from the repository root (the scenarios are synthesised first)::

    for s in close_approach high_camera; do
        .venv/bin/rgbd-eval synth bench/border/$s.yaml -o runs/border/$s.mcap
    done
    .venv/bin/python -m bench.border.measure runs/border/close_approach.mcap runs/border/high_camera.mcap [more.mcap]

Each recording is run with both settings, everything else the method's defaults,
scored on image boxes (IoU 0.5, the thesis) and on the ground plane (0.5 m), and the
CLEAR MOT figures are printed side by side (from ``rgbd-eval run``'s report.json).
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

KEYS = ("mota", "fn_rate", "fp_rate", "idf1", "id_switches", "mt", "ml")


def scores(recording: Path, border: str, extra: list[str]) -> dict[str, float]:
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [
            ".venv/bin/rgbd-eval",
            "run",
            str(recording),
            "--out",
            tmp,
            "--set",
            f"detector.hog_border={border}",
            *extra,
        ]
        subprocess.run(cmd, check=True, capture_output=True)
        report = json.loads((Path(tmp) / "report.json").read_text())
    metrics: dict[str, float] = report["overall"]["metrics"]
    return metrics


def main(paths: list[str]) -> None:
    gatings = {"iou 0.5": [], "metric 0.5 m": ["--gating", "metric", "--threshold", "0.5"]}
    print("recording | gating | border | " + " | ".join(KEYS))
    for path in paths:
        for gating, extra in gatings.items():
            for border in ("skip", "pad"):
                m = scores(Path(path), border, extra)
                cells = [f"{m[k]:.3f}" if isinstance(m[k], float) else str(m[k]) for k in KEYS]
                print(f"{Path(path).stem} | {gating} | {border} | " + " | ".join(cells), flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
