"""The benchmarks run as the command line does, with one BLAS thread (:mod:`driver.blas`), set before
numpy loads OpenBLAS."""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
