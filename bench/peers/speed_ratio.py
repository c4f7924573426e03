"""Our basso2012 detector against the authors' C++ on the same organised cloud, one core.

Run from the repository root (README.md here says how to build the oracle)::

    .venv/bin/python -m bench.peers.speed_ratio [/tmp/pcl_people_oracle] [--pcd CLOUD.pcd]
        [--ground A B C D] [--intrinsics FX FY CX CY] [--rounds 5] [--repeat 10]

By default one ray-cast frame (depth and RGB at 640x480, five people 1.8-5.5 m, camera
1.1 m high, the true ground plane) is written as an organised PCD (``PointXYZRGBA``,
depth optical frame). ``--pcd`` takes any organised PCD instead (``x y z`` and ``rgb``
or ``rgba``; ``ascii``, ``binary`` or ``binary_compressed``), for example PCL's real
``five_people.pcd``: its depth is the cloud's ``z``, its colour the packed ``rgb``, its
intrinsics fitted to the points (``--intrinsics`` to give them), and its ground plane
``--ground`` or else the one our automatic ground search finds on it (printed).

PCL's ``GroundBasedPeopleDetectionApp`` gets that file (voxel 0.06 m, the plane,
heights 1.4-2.3 m, 6.5 m range; its ``compute()`` timed). Ours gets the same frame and
plane (``ground_mode: plane``) and is timed over ``detect()`` (which also builds the
cloud from depth: the C++ gets the cloud ready-made). Both are pinned to the same CPU
and measured in alternating rounds by thread CPU time, so machine load hits both alike.
Prints per-round medians, the overall medians and the ratio ours / C++.
``--cpp-range 50`` gives the C++ PCL's default depth range instead of ours (6.5 m).

When the oracle is missing it is built (``g++``, ``pkg-config``, ``libpcl-dev``); when
that fails the script says why and times ours alone.
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
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from tests.detect.scenes import Person, Scene, camera_pose, render

from rgbd_eval.bench import one_core
from rgbd_eval.detect.ground import GroundMode
from rgbd_eval.methods.basso2012.detector import STAGES, Basso2012Detector
from rgbd_eval.methods.basso2012.detector_config import Basso2012DetectorConfig as DetectorConfig
from rgbd_eval.types import CameraModel, Frame, Pose

MODEL = Path("src/rgbd_eval/data/pcl_people/trainedLinearSVMForPeopleDetectionWithHOG.yaml")
SOURCE = Path(__file__).with_name("pcl_people_oracle.cpp")
DEFAULT_ORACLE = "/tmp/pcl_people_oracle"


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


_PCD_TYPES = {("F", 4): "<f4", ("F", 8): "<f8", ("U", 1): "u1", ("U", 2): "<u2", ("U", 4): "<u4"}
_PCD_TYPES |= {("I", 1): "i1", ("I", 2): "<i2", ("I", 4): "<i4", ("U", 8): "<u8", ("I", 8): "<i8"}


class PcdError(ValueError):
    """A PCD this script cannot read (the message says what was expected)."""


def lzf_decompress(data: bytes, size: int) -> bytes:
    """liblzf's format, as PCL's ``binary_compressed`` stores it."""
    out = bytearray()
    i = 0
    while i < len(data):
        ctrl = data[i]
        i += 1
        if ctrl < 32:  # a literal run of ctrl + 1 bytes
            out += data[i : i + ctrl + 1]
            i += ctrl + 1
            continue
        length = ctrl >> 5
        if length == 7:
            length += data[i]
            i += 1
        ref = len(out) - ((ctrl & 0x1F) << 8) - data[i] - 1
        i += 1
        length += 2
        if ref < 0:
            raise PcdError("binary_compressed data refers before its start")
        if ref + length <= len(out):
            out += out[ref : ref + length]
        else:  # an overlapping back-reference repeats bytes it writes
            for k in range(length):
                out.append(out[ref + k])
    if len(out) != size:
        raise PcdError(f"binary_compressed data is {len(out)} bytes, header says {size}")
    return bytes(out)


def read_pcd(path: Path) -> tuple[NDArray[np.float32], NDArray[np.uint8]]:
    """An organised PCD's points ``(H, W, 3)`` and colour ``(H, W, 3)`` (RGB)."""
    raw = path.read_bytes()
    header: dict[str, list[str]] = {}
    pos = 0
    while "DATA" not in header:
        end = raw.find(b"\n", pos)
        if end < 0:
            raise PcdError(f"{path}: no DATA line in the header")
        words = raw[pos:end].decode("ascii", errors="replace").split()
        pos = end + 1
        if words and not words[0].startswith("#"):
            header[words[0].upper()] = words[1:]
    names = header.get("FIELDS", [])
    sizes = [int(x) for x in header.get("SIZE", [])]
    types = header.get("TYPE", [])
    counts = [int(x) for x in header.get("COUNT", ["1"] * len(names))]
    width, height = int(header["WIDTH"][0]), int(header["HEIGHT"][0])
    if not {"x", "y", "z"} <= set(names) or not {"rgb", "rgba"} & set(names):
        raise PcdError(f"{path}: fields {names}, expected x y z and rgb or rgba")
    if height <= 1:
        raise PcdError(f"{path}: HEIGHT {height}, expected an organised cloud (HEIGHT > 1)")
    fields = []
    for k, (name, size, kind, count) in enumerate(zip(names, sizes, types, counts, strict=True)):
        code = _PCD_TYPES[(kind, size)]
        fields.append((name if name != "_" else f"_pad{k}", code, (count,) if count > 1 else ()))
    dtype = np.dtype(fields)
    n = width * height
    mode = header["DATA"][0]
    if mode == "ascii":
        text = raw[pos:].decode("ascii").split()
        flat = np.array(text[: n * sum(counts)], dtype=np.float64).reshape(n, sum(counts))
        rec = np.empty(n, dtype=dtype)
        col = 0
        for name, count in zip(dtype.names or (), counts, strict=True):
            values = flat[:, col : col + count]
            if name in ("rgb", "rgba") and dtype[name] == np.dtype("<f4"):
                # PCL writes a float-typed packed colour as its integer bits.
                bits = values[:, 0]
                if np.all(bits == np.floor(bits)):
                    rec[name] = bits.astype("<u4").view("<f4")
                else:
                    rec[name] = bits.astype("<f4")
            else:
                rec[name] = values[:, 0] if count == 1 else values
            col += count
    elif mode == "binary":
        rec = np.frombuffer(raw, dtype=dtype, count=n, offset=pos)
    elif mode == "binary_compressed":
        packed, unpacked = np.frombuffer(raw, dtype="<u4", count=2, offset=pos)
        data = lzf_decompress(raw[pos + 8 : pos + 8 + int(packed)], int(unpacked))
        rec = np.empty(n, dtype=dtype)
        at = 0
        for name in dtype.names or ():  # one field after another (structure of arrays)
            sub = dtype[name]
            count = n * (sub.itemsize // sub.base.itemsize)
            chunk = np.frombuffer(data, dtype=sub.base, count=count, offset=at)
            rec[name] = chunk.reshape(rec[name].shape)
            at += n * sub.itemsize
    else:
        raise PcdError(f"{path}: DATA {mode}, expected ascii, binary or binary_compressed")
    xyz = np.stack([rec["x"], rec["y"], rec["z"]], axis=-1).astype(np.float32)
    colour = rec["rgb" if "rgb" in names else "rgba"]
    packed_rgb = np.ascontiguousarray(colour).view("<u4") if colour.dtype.kind == "f" else colour
    packed_rgb = packed_rgb.astype(np.uint32)
    rgb = np.stack([(packed_rgb >> s) & 0xFF for s in (16, 8, 0)], axis=-1).astype(np.uint8)
    return xyz.reshape(height, width, 3), rgb.reshape(height, width, 3)


def fit_intrinsics(xyz: NDArray[np.float32]) -> tuple[float, float, float, float, float]:
    """``fx fy cx cy`` of the pinhole that projects the cloud's points onto their pixels,
    by least squares, and the largest residual (pixels)."""
    h, w = xyz.shape[:2]
    v, u = np.mgrid[0:h, 0:w]
    z = xyz[..., 2]
    ok = np.isfinite(z) & (z > 0)
    if ok.sum() < 3:
        raise PcdError("fewer than 3 points with a positive depth: cannot fit intrinsics")
    out, worst = [], 0.0
    for coord, pix in ((xyz[..., 0], u), (xyz[..., 1], v)):
        a = np.stack([(coord / np.where(ok, z, 1.0))[ok], np.ones(int(ok.sum()))], axis=1)
        sol, *_ = np.linalg.lstsq(a, pix[ok].astype(np.float64), rcond=None)
        worst = max(worst, float(np.abs(a @ sol - pix[ok]).max()))
        out.append((float(sol[0]), float(sol[1])))
    (fx, cx), (fy, cy) = out
    return fx, fy, cx, cy, worst


def frame_of_pcd(path: Path, intrinsics: tuple[float, float, float, float] | None) -> Frame:
    """The PCD as a registered colour + depth frame (depth = ``z``, NaN where invalid)."""
    xyz, rgb = read_pcd(path)
    h, w = rgb.shape[:2]
    if intrinsics is None:
        fx, fy, cx, cy, worst = fit_intrinsics(xyz)
        print(
            f"intrinsics fitted to the cloud: fx {fx:.3f} fy {fy:.3f} cx {cx:.3f} cy {cy:.3f} "
            f"(largest residual {worst:.3f} px)"
        )
    else:
        fx, fy, cx, cy = intrinsics
    cam = CameraModel(width=w, height=h, fx=fx, fy=fy, cx=cx, cy=cy)
    depth = np.where(np.isfinite(xyz[..., 2]) & (xyz[..., 2] > 0), xyz[..., 2], np.nan)
    return Frame.rgbd(0, 0, rgb, depth.astype(np.float32), cam, cam)


def build_command(out: str) -> list[str]:
    """The oracle's build command (README.md here), as arguments."""
    flags = subprocess.run(
        ["pkg-config", "--cflags", "--libs", "pcl_people", "pcl_io", "pcl_common"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout.split()
    return [
        "g++",
        "-O2",
        "-std=c++17",
        "-I/usr/include/vtk-9.1",
        "-o",
        out,
        str(SOURCE),
        *flags,
        "-lvtkCommonCore-9.1",
    ]


def find_oracle(path: str) -> tuple[str | None, str]:
    """The oracle at ``path``, built there when missing; else None and why."""
    if os.access(path, os.X_OK):
        return path, ""
    for tool in ("g++", "pkg-config"):
        if shutil.which(tool) is None:
            return None, f"{tool} is not installed"
    try:
        cmd = build_command(path)
    except subprocess.CalledProcessError as err:
        return (
            None,
            f"pkg-config finds no PCL ({err.stderr.strip()}); apt-get install -y libpcl-dev",
        )
    print("building the C++ oracle:", " ".join(cmd))
    built = subprocess.run(cmd, capture_output=True, text=True)
    if built.returncode != 0:
        tail = built.stderr.strip().splitlines()[-3:]
        return None, "g++ failed: " + " | ".join(tail)
    return path, ""


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
    parser.add_argument(
        "oracle", nargs="?", default=DEFAULT_ORACLE, help="the built oracle (built here if missing)"
    )
    parser.add_argument("--pcd", type=Path, help="an organised PCD (default: the synthetic frame)")
    parser.add_argument("--ground", type=float, nargs=4, metavar=("A", "B", "C", "D"))
    parser.add_argument("--intrinsics", type=float, nargs=4, metavar=("FX", "FY", "CX", "CY"))
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
    oracle, why = find_oracle(args.oracle)
    if oracle is None:
        print(f"C++ oracle unavailable ({why}): timing ours only", file=sys.stderr)
    ours_all: list[float] = []
    cpp_all: list[float] = []
    with tempfile.TemporaryDirectory() as tmp:
        if args.pcd is None:
            pose = camera_pose(height=1.1, pitch_deg=5.0)
            frame = render(five_people(), pose, depth_size=(640, 480))
            plane = args.ground or floor_in_optical(pose)
            pcd = Path(tmp) / "frame.pcd"
            write_pcd(frame, pcd)
        else:
            pcd = args.pcd
            try:
                frame = frame_of_pcd(pcd, args.intrinsics)
            except (OSError, PcdError, KeyError) as err:
                sys.exit(f"error: {pcd}: {err}")
            plane = args.ground or auto_plane(frame)
        plane = tuple(float(x) for x in plane)
        print("ground plane (optical frame):", " ".join(f"{x:.6f}" for x in plane))
        cfg = DetectorConfig(ground_mode=GroundMode.PLANE, ground_plane=plane)
        if oracle is not None:
            lines = run_cpp(oracle, pcd, plane, frame, 1, args.cpp_range)
            print("C++ people:", *(x for x in lines if x.startswith("person")), sep="\n  ")
        dets = Basso2012Detector(cfg).detect(frame)
        print("our people:", *(f"{d.confidence:.3f} h={d.height:.2f}" for d in dets), sep="\n  ")
        stages: dict[str, float] = {}
        for r in range(args.rounds):
            cpp: list[float] = []
            if oracle is not None:
                lines = run_cpp(oracle, pcd, plane, frame, args.repeat, args.cpp_range)
                cpp = [float(x.split()[1]) for x in lines if x.startswith("cpu_ms")]
            ours, stages = ours_round(frame, cfg, args.repeat)
            cpp_all += cpp
            ours_all += ours
            cpp_text = f"C++ {statistics.median(cpp):.2f} ms" if cpp else "C++ -"
            print(
                f"round {r}: ours {statistics.median(ours):.2f} ms, {cpp_text} "
                "(median CPU per frame)"
            )
    ours_ms = statistics.median(ours_all)
    cpp_ms = statistics.median(cpp_all) if cpp_all else None
    ratio = ours_ms / cpp_ms if cpp_ms else None
    print("our stages (ms, last round): " + "  ".join(f"{k} {v:.2f}" for k, v in stages.items()))
    cpp_text = f"{cpp_ms:.2f} ms (range {args.cpp_range} m)" if cpp_ms else f"unavailable ({why})"
    ratio_text = f"{ratio:.3f}" if ratio else "-"
    print(f"cpus {cpus}: ours {ours_ms:.2f} ms, C++ {cpp_text}, ratio {ratio_text}")
    if args.json:
        doc = {
            "cpus": cpus,
            "pcd": str(args.pcd) if args.pcd else None,
            "ground_plane": plane,
            "ours_ms": ours_ms,
            "cpp_ms": cpp_ms,
            "cpp_range_m": args.cpp_range,
            "ratio": ratio,
            "cpp_unavailable": why or None,
        }
        args.json.write_text(json.dumps(doc, indent=1) + "\n")


def auto_plane(frame: Frame) -> tuple[float, ...]:
    """The floor our automatic ground search finds on ``frame`` (exits when none)."""
    det = Basso2012Detector(DetectorConfig(ground_mode=GroundMode.AUTO))
    det.detect(frame)
    if det.ground_plane is None:
        sys.exit("error: no ground plane found on the cloud: give one with --ground A B C D")
    return tuple(float(x) for x in det.ground_plane)


if __name__ == "__main__":
    main()
