"""Our basso2012 detector against the authors' C++ on the same 640x480 frame, one core.

Run from the repository root after building the oracle (README.md here)::

    .venv/bin/python -m bench.peers.speed_ratio /tmp/pcl_people_oracle [--rounds 5] [--repeat 10]

One ray-cast frame (depth and RGB at 640x480, five people 1.8-5.5 m, camera 1.1 m
high) is written as an organised PCD (``PointXYZRGBA``, depth optical frame) for
PCL's ``GroundBasedPeopleDetectionApp`` (voxel 0.06 m, the true ground plane, heights
1.4-2.3 m, 6.5 m range; its ``compute()`` timed). Ours gets the same frame and plane
(``ground_mode: plane``) and is timed over ``detect()`` (which also builds the cloud
from depth: the C++ gets the cloud ready-made). Both are pinned to the same CPU and
measured in alternating rounds by thread CPU time, so machine load hits both alike.
Prints per-round medians, the overall medians and the ratio ours / C++.
``--cpp-range 50`` gives the C++ PCL's default depth range instead of ours (6.5 m).
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np
from tests.detect.scenes import Person, Scene, camera_pose, render

from rgbd_eval.bench import one_core
from rgbd_eval.detect.basso2012 import STAGES, Basso2012Detector
from rgbd_eval.detect.basso2012_config import Basso2012DetectorConfig as DetectorConfig
from rgbd_eval.detect.basso2012_config import GroundMode
from rgbd_eval.types import Frame, Pose

MODEL = Path("src/rgbd_eval/data/pcl_people/trainedLinearSVMForPeopleDetectionWithHOG.yaml")


def five_people() -> Scene:
    return Scene(
        people=[
            Person(1.8, 0.3, 1.75),
            Person(2.6, -0.6, 1.68, yaw=0.5),
            Person(3.4, 0.9, 1.82),
            Person(4.3, -0.2, 1.60, shirt=(230, 200, 60)),
            Person(5.5, 1.1, 1.78, yaw=-0.7),
        ]
    )


def floor_in_optical(pose: Pose) -> tuple[float, float, float, float]:
    """The floor ``n . p + d = 0`` in the optical frame, ``n`` pointing up (world z = 0)."""
    n = pose.rotation_matrix().T @ np.array([0.0, 0.0, 1.0])
    return (float(n[0]), float(n[1]), float(n[2]), float(pose.translation[2]))


def write_pcd(frame: Frame, path: Path) -> None:
    """The organised cloud of ``frame`` (registered depth and RGB) as a binary PCD."""
    cam = frame.depth_camera
    pts = cam.backproject(frame.depth).reshape(-1, 3).astype(np.float32)
    rgb = frame.rgb.reshape(-1, 3).astype(np.uint32)
    rgba = (np.uint32(255) << 24) | (rgb[:, 0] << 16) | (rgb[:, 1] << 8) | rgb[:, 2]
    rec = np.empty(pts.shape[0], dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("c", "<u4")])
    rec["x"], rec["y"], rec["z"], rec["c"] = pts[:, 0], pts[:, 1], pts[:, 2], rgba
    header = (
        "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgba\nSIZE 4 4 4 4\nTYPE F F F U\n"
        f"COUNT 1 1 1 1\nWIDTH {cam.width}\nHEIGHT {cam.height}\n"
        f"VIEWPOINT 0 0 0 1 0 0 0\nPOINTS {pts.shape[0]}\nDATA binary\n"
    )
    path.write_bytes(header.encode() + rec.tobytes())


def run_cpp(
    oracle: str, pcd: Path, plane: tuple[float, ...], frame: Frame, n: int, depth_range: float
) -> list[str]:
    """The C++ app's output lines (``cpu_ms`` per call, ``person`` per cluster)."""
    cam = frame.depth_camera
    args = [oracle, "detect", str(MODEL), str(pcd), *map(repr, plane)]
    args += [repr(v) for v in (cam.fx, cam.fy, cam.cx, cam.cy)]
    args += ["0.06", str(n), repr(depth_range)]
    return subprocess.run(args, check=True, capture_output=True, text=True).stdout.splitlines()


def ours_round(frame: Frame, cfg: DetectorConfig, n: int) -> tuple[list[float], dict[str, float]]:
    det = Basso2012Detector(cfg)
    det.detect(frame)  # compile / warm caches
    times, stages = [], dict.fromkeys(STAGES, 0.0)
    for _ in range(n):
        start = time.thread_time()
        det.detect(frame)
        times.append(1e3 * (time.thread_time() - start))
        for k, v in det.last_timings.items():
            stages[k] += 1e3 * v / n
    return times, stages


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("oracle")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--repeat", type=int, default=10)
    parser.add_argument("--json", type=Path, help="also write the numbers here")
    parser.add_argument(
        "--cpp-range",
        type=float,
        default=6.5,
        help="the C++ app's depth range (m): 6.5 as ours (Table 5.1), PCL's default 50",
    )
    args = parser.parse_args()
    cpus = one_core()
    pose = camera_pose(height=1.1, pitch_deg=5.0)
    frame = render(five_people(), pose, depth_size=(640, 480))
    plane = floor_in_optical(pose)
    cfg = DetectorConfig(ground_mode=GroundMode.PLANE, ground_plane=plane)
    ours_all: list[float] = []
    cpp_all: list[float] = []
    with tempfile.TemporaryDirectory() as tmp:
        pcd = Path(tmp) / "frame.pcd"
        write_pcd(frame, pcd)
        lines = run_cpp(args.oracle, pcd, plane, frame, 1, args.cpp_range)
        print("C++ people:", *(x for x in lines if x.startswith("person")), sep="\n  ")
        dets = Basso2012Detector(cfg).detect(frame)
        print("our people:", *(f"{d.confidence:.3f} h={d.height:.2f}" for d in dets), sep="\n  ")
        stages: dict[str, float] = {}
        for r in range(args.rounds):
            lines = run_cpp(args.oracle, pcd, plane, frame, args.repeat, args.cpp_range)
            cpp = [float(x.split()[1]) for x in lines if x.startswith("cpu_ms")]
            ours, stages = ours_round(frame, cfg, args.repeat)
            cpp_all += cpp
            ours_all += ours
            print(
                f"round {r}: ours {statistics.median(ours):.2f} ms, "
                f"C++ {statistics.median(cpp):.2f} ms (median CPU per frame)"
            )
    ours_ms, cpp_ms = statistics.median(ours_all), statistics.median(cpp_all)
    print("our stages (ms, last round): " + "  ".join(f"{k} {v:.2f}" for k, v in stages.items()))
    print(
        f"cpus {cpus}: ours {ours_ms:.2f} ms, C++ {cpp_ms:.2f} ms (range {args.cpp_range} m), "
        f"ratio {ours_ms / cpp_ms:.3f}"
    )
    if args.json:
        doc = {
            "cpus": cpus,
            "ours_ms": ours_ms,
            "cpp_ms": cpp_ms,
            "cpp_range_m": args.cpp_range,
            "ratio": ours_ms / cpp_ms,
        }
        args.json.write_text(json.dumps(doc, indent=1) + "\n")


if __name__ == "__main__":
    main()
