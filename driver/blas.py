"""One BLAS thread for the localizer's linear algebra.

The filters' matrices are small (tens of basis columns by at most tens of thousands of starts), and
OpenBLAS's threads cost more than they give there: on a 2-core machine one marginalisation over
12 647 starts took 7.3 ms with its threads and 0.54 ms with one, a reactive run on the kidney 4.1 s of
CPU and 2.6 s (docs/speed.md). Beside another process (a study's workers, two test workers) the threads
only compete for the same cores. The command line and each trial of a study run with one thread; a
script that runs the filters in a loop can do the same with :func:`one_blas_thread`.
"""

from __future__ import annotations

from threadpoolctl import threadpool_limits

__all__ = ["one_blas_thread"]


def one_blas_thread() -> threadpool_limits:
    """A context in which every BLAS library loaded by then uses one thread (as before, after it).

    Examples
    --------
    >>> import numpy as np
    >>> with one_blas_thread():
    ...     float((np.eye(3) @ np.ones(3)).sum())
    3.0
    """
    return threadpool_limits(limits=1, user_api="blas")
