"""Compiled kernels of :mod:`rgbd_eval.exact` for large arrays (imported on first use).

Each does the same IEEE operations in the same order as its numpy form in ``exact``, so
the two agree to the last bit: numba compiles without fast-math, so no multiply and add
are fused into one instruction and nothing is reordered.
"""

from __future__ import annotations

from collections.abc import Callable

import numba
import numpy as np
from numpy.typing import NDArray

F64 = NDArray[np.float64]


def _matmul_rows(a: F64, b: F64, out: F64) -> None:
    """``out[i, m] = ((a[i, 0] b[0, m] + a[i, 1] b[1, m]) + ...)``, k in order."""
    n, k_dim = a.shape
    m_dim = b.shape[1]
    for i in range(n):
        for m in range(m_dim):
            acc = a[i, 0] * b[0, m]
            for k in range(1, k_dim):
                acc = acc + a[i, k] * b[k, m]
            out[i, m] = acc


matmul_rows: Callable[[F64, F64, F64], None] = numba.njit(cache=True)(_matmul_rows)
