"""``one_blas_thread``: one OpenBLAS thread inside the block, the previous count after it."""

from __future__ import annotations

import numpy as np

from dirac.analysis.core import blas_threads
from dirac.analysis.core.blas_threads import one_blas_thread


def test_one_thread_inside_and_restored_after() -> None:
    a = np.random.default_rng(1).normal(size=(300, 120))
    outside = np.linalg.svd(a, compute_uv=False)
    with one_blas_thread():
        inside = np.linalg.svd(a, compute_uv=False)
        controls = blas_threads._CONTROLS
        if isinstance(controls, tuple):  # OpenBLAS found (numpy's wheels): one thread here
            assert controls[0]() == 1
    if isinstance(controls, tuple):
        before = controls[0]()
        with one_blas_thread():
            pass
        assert controls[0]() == before
    # the same singular values to round-off, whatever the thread count
    assert np.allclose(inside, outside, rtol=1e-12, atol=0.0)
