"""The ``rgbd-eval`` command line (typer); one module per command."""

import os

# One BLAS thread per process: the pipeline's matrices are tiny, and on a busy machine
# multi-threaded BLAS stalls small calls for tens of milliseconds. Sweeps parallelise
# with processes instead. Must be set before numpy is imported.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")
