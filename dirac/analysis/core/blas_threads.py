"""One BLAS thread for the dense linear algebra of the symbolic analysis.

The analysis is single-threaded Python; its few large dense solves (the basis pursuit of
:mod:`dirac.analysis.legendre.polynomial_kernel`, a ``1120 x 272`` SVD for (228)) are small for
a threaded BLAS: the library splits them over all cores and its threads spin while they
wait. On a machine whose cores are busy with other jobs that SVD took 0.9-1.6 s of CPU
time (4-8 s wall) with the default threads and 0.035 s with one thread (OpenBLAS
0.3.31, 2 cores). :func:`one_blas_thread` limits every BLAS library loaded in the process
to one thread for a block and restores the previous counts, through ``threadpoolctl``
(which knows the thread controls of OpenBLAS, MKL and BLIS builds; the results are the
same either way, only the time differs).
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

__all__ = ["one_blas_thread"]


@contextlib.contextmanager
def one_blas_thread() -> Iterator[None]:
    """Run the block with one BLAS thread (threadpoolctl's ``threadpool_limits``)."""
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):
        yield
