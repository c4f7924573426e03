"""The ``rgbd-eval`` command line (typer); one module per command."""

import os

# One BLAS and one OpenCV thread per process: the pipeline's matrices and image crops
# are small; multi-threaded BLAS stalls small calls for tens of milliseconds on a busy
# machine, and OpenCV's pool spent ~15% more CPU for no wall-clock gain on the demo.
# Sweeps parallelise with processes instead. Must be set before numpy/cv2 are imported.
for _var in (
    "OPENBLAS_NUM_THREADS",
    "OMP_NUM_THREADS",
    "MKL_NUM_THREADS",
    "OPENCV_FOR_THREADS_NUM",
):
    os.environ.setdefault(_var, "1")
