"""One BLAS thread for the dense linear algebra of the symbolic analysis.

The analysis is single-threaded Python; its few large dense solves (the basis pursuit of
:mod:`dirac.analysis.legendre.polynomial_kernel`, a ``1120 x 272`` SVD for (228)) are small for
a threaded BLAS: OpenBLAS splits them over all cores and its threads spin while they
wait. On a machine whose cores are busy with other jobs that SVD took 0.9-1.6 s of CPU
time (4-8 s wall) with the default threads and 0.035 s with one thread (OpenBLAS
0.3.31, 2 cores). :func:`one_blas_thread` sets OpenBLAS to one thread for a block and
restores the previous count; without an OpenBLAS found in the process it does nothing
(the results are the same either way, only the time differs).
"""

from __future__ import annotations

import contextlib
import ctypes
import glob
import os
from collections.abc import Callable, Iterator

__all__ = ["one_blas_thread"]

_CONTROLS: tuple[Callable[[], int], Callable[[int], None]] | None | bool = False  # False: not looked up yet


def _openblas_controls() -> tuple[Callable[[], int], Callable[[int], None]] | None:
    """``(get_num_threads, set_num_threads)`` of the OpenBLAS numpy uses, or ``None``."""
    import numpy

    folder = os.path.join(os.path.dirname(os.path.dirname(numpy.__file__)), "numpy.libs")
    for path in sorted(glob.glob(os.path.join(folder, "*openblas*"))):
        try:
            library = ctypes.CDLL(path)
        except OSError:
            continue
        for get_name, set_name in (
            ("scipy_openblas_get_num_threads64_", "scipy_openblas_set_num_threads64_"),
            ("openblas_get_num_threads64_", "openblas_set_num_threads64_"),
            ("openblas_get_num_threads", "openblas_set_num_threads"),
        ):
            getter = getattr(library, get_name, None)
            setter = getattr(library, set_name, None)
            if getter is not None and setter is not None:
                getter.restype = ctypes.c_int
                setter.argtypes = [ctypes.c_int]
                return getter, setter
    return None


@contextlib.contextmanager
def one_blas_thread() -> Iterator[None]:
    """Run the block with one OpenBLAS thread (a no-op without OpenBLAS)."""
    global _CONTROLS
    if _CONTROLS is False:
        _CONTROLS = _openblas_controls()
    controls = _CONTROLS
    if not controls or not isinstance(controls, tuple):
        yield
        return
    get_threads, set_threads = controls
    before = get_threads()
    set_threads(1)
    try:
        yield
    finally:
        set_threads(before)
