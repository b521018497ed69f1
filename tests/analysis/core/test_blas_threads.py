"""``one_blas_thread``: one BLAS thread inside the block, the previous counts after it."""

from __future__ import annotations

import numpy as np
from threadpoolctl import threadpool_info

from dirac.analysis.core.blas_threads import one_blas_thread


def _blas_threads() -> list[int]:
    return [entry["num_threads"] for entry in threadpool_info() if entry["user_api"] == "blas"]


def test_one_thread_inside_and_restored_after() -> None:
    a = np.random.default_rng(1).normal(size=(300, 120))
    outside = np.linalg.svd(a, compute_uv=False)
    before = _blas_threads()
    assert before, "numpy's BLAS is not seen by threadpoolctl"
    with one_blas_thread():
        inside = np.linalg.svd(a, compute_uv=False)
        assert _blas_threads() == [1] * len(before)
    assert _blas_threads() == before
    # the same singular values to round-off, whatever the thread count
    assert np.allclose(inside, outside, rtol=1e-12, atol=0.0)
