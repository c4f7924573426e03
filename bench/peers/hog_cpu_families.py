"""How much the authors' C++ HOG depends on the CPU's SSE reciprocals, measured.

PCL's ``PersonClassifier`` takes ``1/sqrt`` and ``1/x`` from ``rsqrtps``/``rcpps``, 12-bit
approximations whose exact results are the CPU maker's own: AMD and Intel differ, and
qemu computes them exactly. ``src/rgbd_eval/data/pcl_people/sse_reciprocal.npz`` holds
the results measured on this project's AMD EPYC (Zen 3) machines, so our classifier
gives the C++'s confidences on those, on any CPU. This script runs the C++ oracle on the
27 windows of ``tests/detect/data/authors_hog/`` natively and under ``qemu-x86_64 -cpu
Haswell`` (exact reciprocals, as no real CPU has them), and prints the spread::

    .venv/bin/python -m bench.peers.hog_cpu_families /tmp/pcl_people_oracle

(build the oracle as bench/peers/README.md says; qemu from Debian's ``qemu-user``).
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from rgbd_eval.detect.authors_hog import PersonWindow, person_confidences
from rgbd_eval.machine import machine_info

DATA = Path("tests/detect/data/authors_hog")
MODEL = Path("src/rgbd_eval/data/pcl_people/trainedLinearSVMForPeopleDetectionWithHOG.yaml")


def _image(name: str) -> NDArray[np.uint8]:
    import cv2
    from tests.detect.scenes import ring_texture

    if name == "rings":
        return ring_texture()
    bgr = cv2.imread(str(DATA / name), cv2.IMREAD_COLOR)
    return np.asarray(cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB), dtype=np.uint8)


def _cpp(
    oracle: str, rgb: NDArray[np.uint8], windows: list[PersonWindow], qemu: str | None
) -> list[float]:
    with tempfile.TemporaryDirectory() as tmp:
        ppm, listing = Path(tmp) / "image.ppm", Path(tmp) / "windows.txt"
        h, w = rgb.shape[:2]
        ppm.write_bytes(f"P6\n{w} {h}\n255\n".encode() + rgb.tobytes())
        listing.write_text("".join(f"{p.height!r} {p.xc!r} {p.yc!r}\n" for p in windows))
        cmd = [oracle, "classify", str(MODEL), str(ppm), str(listing)]
        if qemu is not None:
            cmd = ["qemu-x86_64", "-cpu", qemu, *cmd]
        out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout.split()
    return [float(v) for v in out]


def main(oracle: str) -> int:
    cases = json.loads((DATA / "oracle.json").read_text())["cases"]
    stored, native, emulated, ours_tables, ours_exact = [], [], [], [], []
    qemu = "Haswell" if shutil.which("qemu-x86_64") else None
    for name in sorted({c["image"] for c in cases}):
        mine = [c for c in cases if c["image"] == name]
        windows = [PersonWindow(float(c["height"]), float(c["xc"]), float(c["yc"])) for c in mine]
        rgb = _image(name)
        stored += [float(c["confidence"]) for c in mine]
        native += _cpp(oracle, rgb, windows, None)
        if qemu is not None:
            emulated += _cpp(oracle, rgb, windows, qemu)
        ours_tables += list(person_confidences(rgb, windows, approximate=True))
        ours_exact += list(person_confidences(rgb, windows, approximate=False))
    s = np.array(stored)

    def spread(a: list[float], b: NDArray[np.float64]) -> str:
        d = np.abs(np.array(a) - b)
        return f"max {d.max():.2e}, median {np.median(d):.2e}"

    print(f"machine: {machine_info()['cpu']} ({machine_info()['flags']}); {len(s)} windows")
    print(f"C++ here            vs stored C++ (AMD EPYC): {spread(native, s)}")
    print(f"ours, AMD tables    vs stored C++ (AMD EPYC): {spread(ours_tables, s)}")
    if emulated:
        e = np.array(emulated)
        print(f"C++ under qemu {qemu} (exact 1/x) vs stored C++: {spread(emulated, s)}")
        print(f"ours, exact 1/x     vs C++ under qemu:        {spread(ours_exact, e)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1]))
