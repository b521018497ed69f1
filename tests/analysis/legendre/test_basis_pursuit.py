"""Least-l1 solutions of ``A x = b`` (basis pursuit), the certified road and the LP road.

Hand derivations:

* ``A = [[1, 0, 1, 1], [0, 1, 1, -1]]``, ``b = (1, 1)``. The solutions are
  ``x = (1 - s - t, 1 - s + t, s, t)``; at ``s = 1, t = 0`` that is ``x = e_3`` with
  ``||x||_1 = 1`` (no solution has less: checked at random solutions below). The subgradient
  condition at
  ``x = e_3``: support ``S = {3}`` with sign ``+1``, zeros ``Z = {1, 2, 4}``; the null space
  is spanned by ``(-1, -1, 1, 0)`` and ``(-1, 1, 0, 1)``; ``s = (1/2, 1/2, 0)`` on ``Z`` gives
  ``N_Z^T s = (-1, 0)`` = ``-N_S^T sign(x_S)``, with ``|s_i| < 1``: the unique minimiser.
* ``A = [[1, 1]]``, ``b = 1``: every ``x = (a, 1 - a)`` with ``0 <= a <= 1`` has
  ``||x||_1 = 1``, the minimum: not unique, so no certificate exists (it would need
  ``|s| < 1`` where ``s = -1`` is forced), and the LP decides; its answer must still be a
  minimiser (``||x||_1 = 1``, ``A x = b``).
* A square invertible ``A``: one solution, ``A^{-1} b``.
"""

from __future__ import annotations

import numpy as np

from dirac.analysis.legendre.basis_pursuit import _certified, least_l1


def test_sparse_minimiser_is_certified() -> None:
    A = np.array([[1.0, 0.0, 1.0, 1.0], [0.0, 1.0, 1.0, -1.0]])
    b = np.array([1.0, 1.0])
    x = _certified(A, b)
    assert x is not None
    np.testing.assert_allclose(x, [0.0, 0.0, 1.0, 0.0], atol=1e-12)
    assert np.count_nonzero(x) == 1  # the zeros are exact zeros
    rng = np.random.default_rng(1)
    for s, t in rng.normal(size=(50, 2)):
        other = np.array([1 - s - t, 1 - s + t, s, t])
        np.testing.assert_allclose(A @ other, b)
        assert np.abs(other).sum() >= 1.0 - 1e-12


def test_tie_goes_to_the_linear_program() -> None:
    A = np.array([[1.0, 1.0]])
    b = np.array([1.0])
    assert _certified(A, b) is None
    x = least_l1(A, b)
    assert x is not None
    np.testing.assert_allclose(A @ x, b, atol=1e-9)
    assert abs(np.abs(x).sum() - 1.0) < 1e-9


def test_single_solution() -> None:
    A = np.array([[2.0, 1.0], [1.0, 3.0]])
    b = np.array([3.0, 4.0])  # x = (1, 1)
    np.testing.assert_allclose(least_l1(A, b), [1.0, 1.0], atol=1e-12)


def test_certified_answer_is_the_linear_programs() -> None:
    """Random sparse combinations: the certified road and HiGHS find the same solution.

    ``b = A x*`` with ``x*`` of 4 non-zeros. For a random ``A`` with this few non-zeros the
    least-l1 solution is ``x*`` itself (Donoho, Comm. Pure Appl. Math. 59, 797 (2006)).
    With 3 free directions (``A`` 37 x 40, the shape of the right inverses of (228): 269 x
    272) the certificate is found; with 8 (``A`` 12 x 20) its minimum-norm form exceeds 1 and
    the LP decides: the answer is ``x*`` either way.
    """
    from scipy.optimize import linprog

    for shape, certified in (((37, 40), True), ((12, 20), False)):
        rng = np.random.default_rng(7)
        A = rng.normal(size=shape)
        truth = np.zeros(shape[1])
        truth[[2, 9, 17, 19]] = [1.5, -2.0, 0.5, 1.0]
        b = A @ truth
        assert (_certified(A, b) is not None) == certified
        x = least_l1(A, b)
        assert x is not None
        np.testing.assert_allclose(x, truth, atol=1e-7)
        m = shape[1]
        lp = linprog(np.ones(2 * m), A_eq=np.hstack([A, -A]), b_eq=b, bounds=(0, None), method="highs")
        np.testing.assert_allclose(lp.x[:m] - lp.x[m:], x, atol=1e-7)
