"""First-class combinations when C_ab is singular but no single constraint is first class."""

from __future__ import annotations

import numpy as np
import sympy

from dirac.analysis.classes.classification import classify
from dirac.analysis.core.numeric import Numerics
from dirac.analysis.core.phase_space import PhaseSpace


def test_first_class_combination_is_found():
    q1, q2, p1, p2 = sympy.symbols("q1 q2 p1 p2", real=True)
    space = PhaseSpace((q1, q2), (p1, p2))
    numerics = Numerics(space, {})
    # {q1, p1} = 1, {q1, p1 + q2} = 1, {p1, p1 + q2} = 0: rank 2, and
    # (p1 + q2) - p1 = q2 commutes with all three (hand).
    constraints = [q1, p1, p1 + q2]
    points = numerics.surface_points(constraints, 3)
    result = classify(space, numerics, constraints, points)
    assert result.rank == 2
    assert len(result.second_class) == 2 and len(result.first_class) == 1
    (combo,) = result.first_class
    for c in constraints:
        assert sympy.simplify(space.poisson_bracket(combo, c)) == 0
    # the combination is q2 up to the second-class constraints and a factor
    assert sympy.simplify(combo.subs({q1: 0, p1: 0})).free_symbols == {q2}


def test_poisson_bracket_convention():
    q, p = sympy.symbols("q p", real=True)
    space = PhaseSpace((q,), (p,))
    assert space.poisson_bracket(q, p) == 1
    assert space.poisson_bracket(p, q) == -1
    assert sympy.expand(space.poisson_bracket(q**2, p**2) - 4 * q * p) == 0


def test_surface_points_lie_on_the_surface():
    x, y, px, py = sympy.symbols("x y p_x p_y", real=True)
    space = PhaseSpace((x, y), (px, py))
    numerics = Numerics(space, {})
    points = numerics.surface_points([x**2 + y**2 - 1, x * px + y * py], 4)
    for z in points:
        assert abs(z[0] ** 2 + z[1] ** 2 - 1) < 1e-12
        assert abs(z[0] * z[2] + z[1] * z[3]) < 1e-12
    assert len({tuple(np.round(z, 6)) for z in points}) == 4


def test_rank_by_connected_blocks_equals_the_dense_rank():
    """Block-diagonal matrices (rows and columns permuted alike) of known rank: the blocks' ranks add up."""
    import numpy as np
    import scipy.sparse as sp

    from dirac.analysis.classes.classification import _rank_by_blocks
    from dirac.analysis.core.numeric import numeric_rank

    rng = np.random.default_rng(4)
    for trial in range(10):
        blocks, expected = [], 0
        for _ in range(int(rng.integers(3, 9))):
            size = int(rng.integers(1, 6))
            half = rng.normal(size=(size, size))
            block = half - half.T
            if size >= 3 and trial % 2:
                v = rng.normal(size=size)
                block = block - np.outer(block @ v, v) / (v @ v) - np.outer(v, v @ block) / (v @ v)
            expected += numeric_rank(block)
            blocks.append(block)
        dense = sp.block_diag(blocks).toarray()
        perm = rng.permutation(dense.shape[0])
        dense = dense[np.ix_(perm, perm)]
        rows, cols = np.nonzero(dense)
        assert _rank_by_blocks(dense.shape[0], rows, cols, dense[rows, cols]) == numeric_rank(dense) == expected
    assert _rank_by_blocks(5, np.zeros(0, dtype=int), np.zeros(0, dtype=int), np.zeros(0)) == 0


def test_rank_by_blocks_is_the_same_on_the_sparse_path():
    """From SPARSE_BRACKETS constraints the blocks are found on scipy.sparse matrices: the same rank as the dense SVD.

    A block-diagonal antisymmetric matrix of 40 blocks of size 2 (each of rank 2: a 2 x 2
    antisymmetric block with a non-zero entry is invertible), permuted: rank 80 of 80.
    """
    from dirac.analysis.classes.classification import SPARSE_BRACKETS, _rank_by_blocks
    from dirac.analysis.core.numeric import numeric_rank

    rng = np.random.default_rng(11)
    m = 80
    assert m >= SPARSE_BRACKETS
    dense = np.zeros((m, m))
    for k in range(0, m, 2):
        a = rng.uniform(0.5, 2.0)
        dense[k, k + 1], dense[k + 1, k] = a, -a
    dense[-2:, -2:] = 0.0  # the last block zero: rank 78
    perm = rng.permutation(m)
    dense = dense[np.ix_(perm, perm)]
    rows, cols = np.nonzero(dense)
    assert _rank_by_blocks(m, rows, cols, dense[rows, cols]) == numeric_rank(dense) == 78
