"""The one-pass numerical decisions for large systems against dense references.

Independent checks: the greedy choice of rows is compared with the SVD-based choice of
:func:`dirac.analysis.core.numeric.independent_rows` (its definition: a row is kept when it
raises the rank at a majority of points) on random matrices of known rank; the
minimum-norm step with ``numpy.linalg.lstsq``; the regularity test with the smallest
singular value of the dense row-normalised matrix.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from dirac.analysis.core.numeric import independent_rows
from dirac.analysis.core.sparse_numeric import (
    full_row_rank,
    independent_rows_eliminated,
    independent_rows_one_pass,
    minimum_norm_step,
)


def test_one_pass_choice_equals_the_svd_choice_on_matrices_of_known_rank():
    rng = np.random.default_rng(7)
    for trial in range(40):
        m, n = int(rng.integers(2, 25)), int(rng.integers(2, 25))
        r = int(rng.integers(1, min(m, n) + 1))
        left = rng.normal(size=(m, r))
        matrices = [left @ rng.normal(size=(r, n)) for _ in range(4)]
        order = [int(i) for i in rng.permutation(m)]
        base = [rng.normal(size=(2, n)) for _ in range(4)] if trial % 2 else None
        chosen = independent_rows_one_pass(matrices, order, base)
        assert chosen == independent_rows(matrices, order, base)
        if base is None:
            assert len(chosen) == r  # the rank of every point's matrix


def test_a_repeated_row_and_a_zero_row_are_dependent():
    a = np.array([[1.0, 2.0, 0.0], [2.0, 4.0, 0.0], [0.0, 0.0, 0.0], [0.0, 1.0, 1.0]])
    assert independent_rows_one_pass([a, 3 * a, -a], [0, 1, 2, 3]) == [0, 3]


def test_the_majority_decides_where_points_disagree():
    a = np.array([[1.0, 0.0], [0.0, 1.0]])
    b = np.array([[1.0, 0.0], [1.0, 0.0]])  # row 1 dependent at this point only
    assert independent_rows_one_pass([a, a, b], [0, 1]) == [0, 1]
    assert independent_rows_one_pass([a, b, b], [0, 1]) == [0]


def test_minimum_norm_step_equals_lstsq_also_when_rank_deficient():
    rng = np.random.default_rng(3)
    J = sp.random(60, 90, density=0.05, random_state=4) + sp.eye(60, 90)
    J = sp.vstack([J, J.getrow(0) + J.getrow(1)]).tocsr()  # a dependent row: rank 60 of 61
    r = rng.normal(size=61)
    r[60] = r[0] + r[1]  # consistent, as for a reducible constraint on the surface
    step = minimum_norm_step(J, r)
    assert np.allclose(step, np.linalg.lstsq(J.toarray(), -r, rcond=None)[0], atol=1e-10)


def test_full_row_rank_agrees_with_the_dense_singular_values():
    rng = np.random.default_rng(5)
    for _ in range(20):
        blocks = [rng.normal(size=(3, 4)) for _ in range(5)]
        if rng.random() < 0.5:
            k = int(rng.integers(5))
            blocks[k][2] = blocks[k][0] - 2 * blocks[k][1]
        J = sp.block_diag(blocks).tocsr()
        dense = J.toarray()
        normed = dense / np.linalg.norm(dense, axis=1)[:, None]
        expected = np.linalg.svd(normed, compute_uv=False)[-1] > 1e-6
        assert full_row_rank(J, 1e-6) == expected


def _incidence(n: int, rows: int) -> sp.csr_matrix:
    """Rows ``e_i - e_{i-1}`` (periodic): the gradients of the ring's Gauss laws in ``p_A1``."""
    r = [i for i in range(rows) for _ in range(2)]
    c = [col for i in range(rows) for col in (i, (i - 1) % n)]
    return sp.csr_matrix(([1.0, -1.0] * rows, (r, c)), shape=(rows, n))


def test_elimination_choice_equals_the_svd_choice_on_sparse_matrices_of_known_rank():
    rng = np.random.default_rng(11)
    for trial in range(40):
        m, n = int(rng.integers(2, 30)), int(rng.integers(2, 30))
        r = int(rng.integers(1, min(m, n) + 1))
        left = sp.random(m, r, density=0.3, random_state=trial) + sp.eye(m, r)
        matrices = [(left @ (sp.random(r, n, density=0.3, random_state=100 + trial + k) + sp.eye(r, n))).tocsr() for k in range(4)]
        order = [int(i) for i in rng.permutation(m)]
        base = [sp.random(2, n, density=0.5, random_state=200 + trial + k).tocsr() for k in range(4)] if trial % 2 else None
        chosen = independent_rows_eliminated(matrices, order, base)
        dense_base = [b.toarray() for b in base] if base is not None else None
        assert chosen is not None
        assert chosen == independent_rows([m.toarray() for m in matrices], order, dense_base)


def test_the_sum_of_the_ring_gauss_laws_vanishes_so_the_last_one_in_order_is_dependent():
    # hand count: sum_i (e_i - e_{i-1}) = 0 and any n - 1 of the n rows are independent
    n = 500
    J = _incidence(n, n)
    assert independent_rows_eliminated([J, 2.0 * J, -J], list(range(n))) == list(range(n - 1))
    reverse = list(range(n))[::-1]
    assert independent_rows_eliminated([J, 2.0 * J, -J], reverse) == reverse[:-1]
    # with the rows already chosen as a base, none is new
    assert independent_rows_eliminated([J], list(range(n)), base=[J[: n - 1]]) == []


def test_a_row_close_to_dependent_is_left_to_the_dense_pass_with_a_note():
    a = sp.csr_matrix(np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 3e-7]]))
    assert independent_rows_eliminated([a, a, a], [0, 1, 2]) is None  # 3e-7: neither below 1e-8 nor above 1e-6
    notes: list[str] = []
    chosen = independent_rows([a, a, a], [0, 1, 2], notes=notes)
    assert chosen == independent_rows([a.toarray()] * 3, [0, 1, 2]) == [0, 1, 2]
    assert len(notes) == 1 and "dense path" in notes[0]


def test_full_row_rank_of_large_blocks_by_factorisation_agrees_with_the_dense_singular_values():
    # the ring's n - 1 Gauss laws are independent (smallest singular value ~ pi/n), all n are not
    assert full_row_rank(_incidence(600, 599), 1e-6)
    assert not full_row_rank(_incidence(600, 600), 1e-6)
    rng = np.random.default_rng(9)
    for trial in range(4):
        m = int(rng.integers(205, 240))
        J = (sp.random(m, m + 10, density=0.01, random_state=trial) + sp.eye(m, m + 10)).tocsr()
        J = sp.vstack([J, sp.csr_matrix(np.ones((1, m + 10)))]).tocsr()  # one block larger than the dense limit
        if trial % 3 == 0:
            J = sp.vstack([J, J.getrow(1) - 0.5 * J.getrow(m)]).tocsr()  # a dependent row
        dense = J.toarray()
        normed = dense / np.linalg.norm(dense, axis=1)[:, None]
        expected = np.linalg.svd(normed, compute_uv=False)[-1] > 1e-6 if J.shape[0] <= J.shape[1] else False
        assert full_row_rank(J, 1e-6) == expected
