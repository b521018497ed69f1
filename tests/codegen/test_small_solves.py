"""The unrolled LU of dirac.codegen.small_solves (the interpreted tier's solves of fixed
size) against hand-worked factors and solutions, numpy's dense solve, and the looped
elimination it replaces, which it must reproduce bit for bit (the two tiers of a
generated module give the same numbers only then)."""

from __future__ import annotations

import numpy as np
import pytest

from dirac.codegen.numba_backend import interpret_source
from dirac.codegen.small_solves import UNROLLED_MAX_SIZE, lu_source, offset_lu_source, unrolled_lu_source

_HEADER = "import math\nimport numpy as np\nimport numba\n"


@pytest.fixture(scope="module")
def solves():
    """The looped lu_factor / lu_solve and the unrolled ones of every size, in the interpreter."""
    sizes = range(1, UNROLLED_MAX_SIZE + 1)
    return interpret_source(_HEADER + lu_source() + "".join(unrolled_lu_source(k) for k in sizes))


def _unrolled(solves, matrix, b):
    k = matrix.shape[0]
    A, piv, x = matrix.copy(), np.empty(k, dtype=np.int64), b.copy()
    getattr(solves, f"lu_factor_{k}")(A, piv)
    getattr(solves, f"lu_solve_{k}")(A, piv, x)
    return A, piv, x


def _looped(solves, matrix, b):
    k = matrix.shape[0]
    A, piv, x = matrix.copy(), np.empty(k, dtype=np.int64), b.copy()
    solves.lu_factor(A, piv)
    solves.lu_solve(A, piv, x)
    return A, piv, x


def test_a_hand_worked_two_by_two(solves) -> None:
    """A = [[2, 1], [4, 3]], b = (3, 7): the pivot of column 0 is row 1 (|4| > |2|), the
    multiplier 2/4 = 0.5 and U = [[4, 3], [0, 1 - 0.5 * 3]] = [[4, 3], [0, -0.5]]; the
    solution of 2x + y = 3, 4x + 3y = 7 is x = y = 1 (by hand)."""
    A, piv, x = _unrolled(solves, np.array([[2.0, 1.0], [4.0, 3.0]]), np.array([3.0, 7.0]))
    assert piv.tolist() == [1, 1]
    assert A.tolist() == [[4.0, 3.0], [0.5, -0.5]]
    assert x.tolist() == [1.0, 1.0]


def test_a_hand_worked_three_by_three(solves) -> None:
    """A = [[1, 2, 3], [2, 5, 3], [1, 0, 8]] has the integer inverse
    [[-40, 16, 9], [13, -5, -3], [5, -2, -1]] (det A = -1, by cofactors), so A x = e_1 is
    solved by its first column (-40, 13, 5) and A x = (1, 1, 1) by the row sums (-15, 5, 2)."""
    A = np.array([[1.0, 2.0, 3.0], [2.0, 5.0, 3.0], [1.0, 0.0, 8.0]])
    for b, expected in (([1.0, 0.0, 0.0], [-40.0, 13.0, 5.0]), ([1.0, 1.0, 1.0], [-15.0, 5.0, 2.0])):
        _, _, x = _unrolled(solves, A, np.array(b))
        np.testing.assert_allclose(x, expected, rtol=0, atol=1e-12)


@pytest.mark.parametrize("size", range(1, UNROLLED_MAX_SIZE + 1))
def test_random_well_conditioned_systems_against_numpy(solves, size) -> None:
    """Diagonally weighted random matrices (condition numbers of a few units): the unrolled
    solve agrees with numpy.linalg.solve (LAPACK gesv) to round-off."""
    rng = np.random.default_rng(100 + size)
    for _ in range(20):
        matrix = rng.normal(size=(size, size)) + size * np.eye(size)
        b = rng.normal(size=size)
        _, _, x = _unrolled(solves, matrix, b)
        reference = np.linalg.solve(matrix, b)
        assert np.max(np.abs(x - reference)) <= 1e-13 * (1.0 + np.max(np.abs(reference)))


@pytest.mark.parametrize("size", range(1, UNROLLED_MAX_SIZE + 1))
def test_the_unrolled_elimination_is_the_looped_one_bit_for_bit(solves, size) -> None:
    """Same pivots, same factors, same solution to the last bit as the loops, on matrices
    that exercise every branch: random ones, row permutations (a zero first pivot, so every
    exchange), ties of |pivot| (the first row wins in both), exact zero multipliers, and
    entries of very different magnitudes."""
    rng = np.random.default_rng(size)
    matrices = [rng.normal(size=(size, size)) for _ in range(10)]
    matrices += [rng.permutation(np.eye(size)) + 1e-3 * rng.normal(size=(size, size)) for _ in range(10)]
    matrices += [np.round(rng.normal(size=(size, size)) * 2) + 3 * np.eye(size) for _ in range(10)]  # ties, zeros
    matrices += [rng.normal(size=(size, size)) * 10.0 ** rng.integers(-8, 8, size=(size, size)) for _ in range(10)]
    for matrix in matrices:
        b = rng.normal(size=size)
        if abs(np.linalg.det(matrix)) < 1e-300:
            continue
        A1, piv1, x1 = _unrolled(solves, matrix, b)
        A2, piv2, x2 = _looped(solves, matrix, b)
        assert piv1.tolist() == piv2.tolist()
        assert A1.tobytes() == A2.tobytes() and x1.tobytes() == x2.tobytes()


def test_a_singular_matrix_divides_by_zero(solves) -> None:
    """All ones (rank 1): the second pivot is exactly zero, and the division by it raises as
    numba's compiled division does (the steppers report a singular Newton matrix)."""
    with pytest.raises(ZeroDivisionError):
        _unrolled(solves, np.ones((3, 3)), np.ones(3))


def test_a_size_below_one_is_refused() -> None:
    with pytest.raises(ValueError, match="at least 1"):
        unrolled_lu_source(0)


def _offset(size: int, matrices: list[np.ndarray], rhs: list[np.ndarray]):
    """Factor the matrices stacked in the rows of one array with lu_factor_n at offsets
    0, size, 2 size, ... (as the unconstrained RATTLE loop keeps its two Newton matrices) and
    solve each with lu_solve_n; returns (stacked factors, piv, solutions)."""
    module = interpret_source(_HEADER + offset_lu_source(size))
    J = np.vstack(matrices)
    piv = np.full(J.shape[0], -1, dtype=np.int64)
    dinv = np.full(J.shape[0], np.nan)
    solutions = []
    for block in range(len(rhs)):
        module.lu_factor_n(J, piv, dinv, block * size)
    for block, b in enumerate(rhs):
        x = b.copy()
        module.lu_solve_n(J, piv, dinv, x, block * size)
        solutions.append(x)
    return J, piv, dinv, solutions


def test_the_offset_lu_by_hand() -> None:
    """The hand-worked A = [[2, 1], [4, 3]] of the unrolled LU, stacked below the identity:
    the identity's block keeps piv (0, 1) and reciprocal pivots (1, 1); A's block exchanges its
    rows (|4| > |2|), multiplier 2/4 = 0.5, U = [[4, 3], [0, -0.5]], reciprocal pivots
    (1/4, -2); A x = (3, 7) gives x = (1, 1), I x = b gives b."""
    J, piv, dinv, (y, x) = _offset(2, [np.eye(2), np.array([[2.0, 1.0], [4.0, 3.0]])],
                                   [np.array([5.0, -6.0]), np.array([3.0, 7.0])])
    assert piv.tolist() == [0, 1, 1, 1]
    assert dinv.tolist() == [1.0, 1.0, 0.25, -2.0]
    assert J[2:].tolist() == [[4.0, 3.0], [0.5, -0.5]]
    assert x.tolist() == [1.0, 1.0] and y.tolist() == [5.0, -6.0]


@pytest.mark.parametrize("size", [1, 2, 3, 5])
def test_the_offset_lu_against_numpy_and_the_loops_pivots(solves, size) -> None:
    """Two blocks, random and row-permuted (every exchange taken): each block's solution agrees
    with numpy.linalg.solve (LAPACK gesv) to round-off, the row exchanges are the looped
    lu_factor's own (same pivot choices), and the other block is left as it was."""
    rng = np.random.default_rng(40 + size)
    for trial in range(20):
        first = rng.normal(size=(size, size)) + (0.0 if trial % 2 else size * np.eye(size))
        second = rng.permutation(np.eye(size)) + 1e-3 * rng.normal(size=(size, size))
        b1, b2 = rng.normal(size=size), rng.normal(size=size)
        J, piv, _, (x1, x2) = _offset(size, [first, second], [b1, b2])
        for matrix, b, x, block in ((first, b1, x1, 0), (second, b2, x2, 1)):
            reference = np.linalg.solve(matrix, b)
            scale = np.linalg.cond(matrix) * (1.0 + np.max(np.abs(reference)))
            assert np.max(np.abs(x - reference)) <= 1e-14 * scale
            _, looped_piv, _ = _looped(solves, matrix, b)
            assert piv[block * size:(block + 1) * size].tolist() == looped_piv.tolist()


def test_the_offset_lu_of_a_singular_block_divides_by_zero() -> None:
    """All ones (rank 1) in the second block: its second pivot is exactly zero and forming its
    reciprocal raises, as numba's compiled division does (a singular Newton matrix)."""
    with pytest.raises(ZeroDivisionError):
        _offset(3, [np.eye(3), np.ones((3, 3))], [np.ones(3), np.ones(3)])


def test_an_offset_lu_out_of_range_is_refused() -> None:
    for size in (0, UNROLLED_MAX_SIZE + 1):
        with pytest.raises(ValueError, match="unrolled offset LU"):
            offset_lu_source(size)
