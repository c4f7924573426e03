"""What machine a result was computed on: CPU model and the instruction sets that change code paths.

Reports and benchmarks carry this so that two results from different machines can be told
apart, and so that ``compare`` can say what differed when two recordings of the same
provenance are not the same bytes.
"""

from __future__ import annotations

import platform
from functools import cache
from pathlib import Path

#: CPU flags that select other code in the libraries we use (BLAS kernels, libm, numpy).
_FLAGS = ("sse4_2", "avx", "avx2", "fma", "avx512f")


@cache
def machine_info() -> dict[str, str]:
    """``{"cpu": model name, "arch": machine, "flags": "avx2 fma ..."}`` (empty strings if unknown)."""
    model, flags = "", ""
    try:
        text = Path("/proc/cpuinfo").read_text(encoding="utf-8", errors="replace")
    except OSError:
        text = ""
    for line in text.splitlines():
        key, _, value = line.partition(":")
        key = key.strip()
        if key == "model name" and not model:
            model = value.strip()
        elif key == "flags" and not flags:
            present = set(value.split())
            flags = " ".join(f for f in _FLAGS if f in present)
    return {"cpu": model or platform.processor(), "arch": platform.machine(), "flags": flags}
