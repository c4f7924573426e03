"""Do rendered recordings depend on the CPU? Render a few scenarios under other CPUs and compare.

Each variant renders the first frames of each scenario in a fresh process and prints the
sha256 of the recording. The variants change what the libraries pick at run time:

- ``native``: this machine;
- ``blas:<core>``: OpenBLAS forced to another CPU's kernels (``OPENBLAS_CORETYPE``);
- ``numpy:baseline``: numpy's SIMD dispatch off (``NPY_DISABLE_CPU_FEATURES``);
- ``jpeg:nosimd``: libjpeg-turbo without SIMD (``JSIMD_FORCENONE``);
- ``qemu:<model>``: the whole process under ``qemu-x86_64 -cpu <model>`` (Debian's
  ``qemu-user``): another CPU's instruction sets (Haswell: AVX2 and FMA; SandyBridge: AVX
  without FMA), and software versions of the approximate instructions (``rcpps``) that
  differ between vendors. Slow (10-15 minutes for a few frames, numba compiles under
  emulation).

Usage::

    .venv/bin/python tools/cpu_independence.py [--frames 6] [--qemu Haswell,SandyBridge]
        [SCENARIO ...]

All variants of a scenario must print the same digest. No AVX-512 CPU can be emulated here
(qemu's TCG lacks AVX-512); the variants cover every other code path selection.

With ``--method KEY`` the recording is rendered once (natively) and the method is run on it
under each variant instead (``rgbd-eval run REC --method KEY``); the digest is that of its
tracks and detections files (``<name>.tracks.csv``, ``<name>.detections.csv``)::

    .venv/bin/python tools/cpu_independence.py --method cielniak2010 --frames 60 \
        configs/scenarios/cielniak2010/thermal_crossings.yaml
"""

from __future__ import annotations

import argparse
import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

DEFAULT_SCENARIOS = (
    "configs/scenarios/demo.yaml",  # Kinect RGB-D, JPEG colour, a static robot
    "configs/scenarios/moving_complex.yaml",  # a moving robot: the static scene re-cast
    "configs/scenarios/satake2009_crossing.yaml",  # the stereo pair
    "configs/scenarios/cielniak2010/thermal_crossings.yaml",  # the thermal camera (blur)
    "configs/scenarios/dmtbs/scene1.yaml",  # static time-of-flight depth cameras
)
VARIANTS: dict[str, dict[str, str]] = {
    "native": {},
    "blas:Sandybridge": {"OPENBLAS_CORETYPE": "Sandybridge"},
    "blas:Prescott": {"OPENBLAS_CORETYPE": "Prescott"},
    "numpy:baseline": {"NPY_DISABLE_CPU_FEATURES": "X86_V3"},
    "jpeg:nosimd": {"JSIMD_FORCENONE": "1"},
}


def _cli(args: list[str], env: dict[str, str], qemu: str | None) -> None:
    """``rgbd-eval ARGS`` in a fresh process, under ``qemu-x86_64 -cpu QEMU`` if given."""
    cmd = [sys.executable, "-m", "rgbd_eval", *args]
    if qemu is not None:
        cmd = ["qemu-x86_64", "-cpu", qemu, *cmd]
    subprocess.run(
        cmd,
        env={**os.environ, **env},
        check=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
    )


def render(scenario: str, frames: int, out: Path, env: dict[str, str], qemu: str | None) -> str:
    """sha256 of the recording ``synth`` writes in a fresh process."""
    _cli(["synth", scenario, "--frames", str(frames), "-o", str(out)], env, qemu)
    return hashlib.sha256(out.read_bytes()).hexdigest()


def run_method(
    recording: Path, method: str, out: Path, env: dict[str, str], qemu: str | None
) -> str:
    """sha256 of the tracks and detections ``rgbd-eval run`` writes in a fresh process."""
    _cli(["run", str(recording), "--method", method, "--out", str(out)], env, qemu)
    digest = hashlib.sha256()
    for suffix in (".tracks.csv", ".detections.csv"):
        for path in sorted(out.glob(f"*{suffix}")):
            digest.update(path.read_bytes())
    return digest.hexdigest()


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("scenarios", nargs="*", default=list(DEFAULT_SCENARIOS))
    ap.add_argument("--frames", type=int, default=6)
    ap.add_argument("--qemu", default="", help="comma-separated qemu CPU models, e.g. Haswell")
    ap.add_argument("--method", default="", help="run this method on the recordings instead")
    args = ap.parse_args()
    variants: list[tuple[str, dict[str, str], str | None]] = [
        (name, env, None) for name, env in VARIANTS.items()
    ]
    models = [m for m in args.qemu.split(",") if m]
    if models and shutil.which("qemu-x86_64") is None:
        print("error: qemu-x86_64 not found (apt-get install qemu-user)", file=sys.stderr)
        return 2
    variants += [(f"qemu:{m}", {}, m) for m in models]
    failed = 0
    with tempfile.TemporaryDirectory() as tmp:
        for scenario in args.scenarios:
            digests = {}
            recording = Path(tmp) / f"{Path(scenario).stem}.mcap"
            if args.method:
                render(scenario, args.frames, recording, {}, None)
            for name, env, qemu in variants:
                tag = f"{Path(scenario).stem}-{name.replace(':', '_')}"
                if args.method:
                    out = Path(tmp) / tag
                    digests[name] = run_method(recording, args.method, out, env, qemu)
                else:
                    out = Path(tmp) / f"{tag}.mcap"
                    digests[name] = render(scenario, args.frames, out, env, qemu)
                print(f"{Path(scenario).stem:28s} {name:18s} {digests[name][:16]}", flush=True)
            same = len(set(digests.values())) == 1
            failed += not same
            print(f"{Path(scenario).stem:28s} {'same' if same else 'DIFFERENT'}", flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
