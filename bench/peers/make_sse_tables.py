"""Measure this CPU's SSE ``rsqrtps``/``rcpps`` as look-up tables for ``authors_hog``.

The authors' C++ HOG (PCL, from Dollár's toolbox) takes ``1/sqrt`` and ``1/x`` from
these 12-bit hardware approximations, and its confidences depend on them (up to
0.07 on flat-coloured synthetic windows; see tests/detect/test_authors_hog.py). On
the AMD EPYC (Zen) machines of this project both results depend only on the
exponent (its parity, for ``rsqrt``) and the top 12 mantissa bits: this script
checks that on 2^22 random inputs and writes the 2 x 4096 + 4096 table entries::

    gcc -O2 -shared -fPIC -o /tmp/libsse_reciprocal.so bench/peers/sse_reciprocal.c
    .venv/bin/python -m bench.peers.make_sse_tables /tmp/libsse_reciprocal.so

Output: ``src/rgbd_eval/data/pcl_people/sse_reciprocal.npz`` (``rsqrt`` (2, 4096):
inputs ``m`` and ``2 m`` for the mantissas ``m`` in [1, 2); ``rcp`` (4096,)).
"""

from __future__ import annotations

import ctypes
import sys
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from rgbd_eval.detect.authors_hog import sse_rcp, sse_rsqrt

OUT = Path("src/rgbd_eval/data/pcl_people/sse_reciprocal.npz")


def hardware(lib: ctypes.CDLL, name: str, x: NDArray[np.float32]) -> NDArray[np.float32]:
    x = np.ascontiguousarray(x, dtype=np.float32)
    y = np.empty_like(x)
    fn = getattr(lib, name)
    fn(x.ctypes.data_as(ctypes.c_void_p), y.ctypes.data_as(ctypes.c_void_p), ctypes.c_long(x.size))
    return y


def cpu_model() -> str:
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("model name"):
            return line.split(":", 1)[1].strip()
    return "unknown CPU"


def main(library: str) -> None:
    lib = ctypes.CDLL(library)
    mantissas = (np.arange(4096, dtype=np.uint32) << np.uint32(11)) | np.uint32(127 << 23)
    ones = mantissas.view(np.float32)  # the 4096 mantissa prefixes in [1, 2)
    rsqrt = np.stack([hardware(lib, "sse_rsqrt", ones), hardware(lib, "sse_rsqrt", 2 * ones)])
    rcp = hardware(lib, "sse_rcp", ones)
    np.savez(OUT, rsqrt=rsqrt, rcp=rcp)
    # Check the model on random inputs over the exponents the descriptor meets.
    rng = np.random.default_rng(0)
    x = np.exp(rng.uniform(np.log(1e-12), np.log(1e12), 1 << 22)).astype(np.float32)
    bad_s = int(np.count_nonzero(sse_rsqrt(x) != hardware(lib, "sse_rsqrt", x)))
    bad_r = int(np.count_nonzero(sse_rcp(x) != hardware(lib, "sse_rcp", x)))
    print(
        f"{cpu_model()}: wrote {OUT}; "
        f"mismatches on {x.size} random inputs: rsqrt {bad_s}, rcp {bad_r}"
    )
    if bad_s or bad_r:
        sys.exit("this CPU's approximations are not a 12-bit table: the model does not hold")


if __name__ == "__main__":
    main(sys.argv[1])
