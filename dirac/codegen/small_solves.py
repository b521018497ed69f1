"""Source of the small dense linear solves that generated step kernels inline.

A step of RATTLE or of the midpoint rule solves a few small systems (``m x m`` for the
multipliers, ``n x n`` for the mass matrix, ``(2n + m)`` for a Newton step). Calling
LAPACK from numba costs more than these solves themselves and allocates, so each
generated module carries its own solves as source, specialised to the sizes that occur:

* size 1 and 2: closed forms (Cramer's rule);
* any size: Gaussian elimination with partial pivoting in place (Golub & Van Loan,
  Algorithm 3.4.1), factor once and solve many right-hand sides (the simplified Newton
  iterations keep their matrix over a step).

None of them allocates. A zero pivot or a zero determinant divides by zero, which numba
raises as ``ZeroDivisionError`` (the steppers turn it into a step failure that names
the singular Newton matrix).
"""

from __future__ import annotations

__all__ = ["solve_source", "lu_source"]


_CLOSED_FORMS = {
    1: '''
@numba.njit(cache=True, inline="always")
def solve_1(A, b, x, piv):
    """x = A^{-1} b for a 1 x 1 matrix."""
    x[0] = b[0] / A[0, 0]
''',
    2: '''
@numba.njit(cache=True, inline="always")
def solve_2(A, b, x, piv):
    """x = A^{-1} b for a 2 x 2 matrix (Cramer's rule)."""
    det = A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]
    inv = 1.0 / det
    x0 = (A[1, 1] * b[0] - A[0, 1] * b[1]) * inv
    x1 = (A[0, 0] * b[1] - A[1, 0] * b[0]) * inv
    x[0] = x0
    x[1] = x1
''',
}

_LU = '''
@numba.njit(cache=True, inline="always")
def lu_factor(A, piv):
    """A <- its LU factors with partial pivoting (row exchanges in piv), in place."""
    k = A.shape[0]
    for c in range(k):
        best = abs(A[c, c])
        r_best = c
        for r in range(c + 1, k):
            if abs(A[r, c]) > best:
                best = abs(A[r, c])
                r_best = r
        piv[c] = r_best
        if r_best != c:  # columns from c on: the multipliers left of c stay with their step
            for j in range(c, k):
                tmp = A[c, j]
                A[c, j] = A[r_best, j]
                A[r_best, j] = tmp
        d = A[c, c]
        for r in range(c + 1, k):
            f = A[r, c] / d
            A[r, c] = f
            if f != 0.0:
                for j in range(c + 1, k):
                    A[r, j] -= f * A[c, j]


@numba.njit(cache=True, inline="always")
def lu_solve(A, piv, b):
    """b <- A^{-1} b with the factors of lu_factor, in place (the row exchanges and the
    eliminations applied to b in the order lu_factor made them)."""
    k = A.shape[0]
    for c in range(k):
        r = piv[c]
        if r != c:
            tmp = b[c]
            b[c] = b[r]
            b[r] = tmp
        for r in range(c + 1, k):
            b[r] -= A[r, c] * b[c]
    for c in range(k - 1, -1, -1):
        acc = b[c]
        for r in range(c + 1, k):
            acc -= A[c, r] * b[r]
        b[c] = acc / A[c, c]
'''

_BY_ELIMINATION = '''
@numba.njit(cache=True, inline="always")
def solve_{k}(A, b, x, piv):
    """x = A^{{-1}} b for a {k} x {k} matrix by elimination with partial pivoting; A is overwritten."""
    lu_factor(A, piv)
    for i in range({k}):
        x[i] = b[i]
    lu_solve(A, piv, x)
'''


def lu_source() -> str:
    """Source of ``lu_factor(A, piv)`` and ``lu_solve(A, piv, b)`` (in place)."""
    return _LU


def solve_source(size: int) -> str:
    """Source of ``solve_<size>(A, b, x, piv)``: ``x = A^{-1} b`` (``A`` may be overwritten;
    ``piv`` is an int64 work array of ``size`` entries).

    Closed forms for sizes 1 and 2; elimination with partial pivoting (needs
    :func:`lu_source` in the same module) otherwise. Size 0 gives a function that does
    nothing.
    """
    if size == 0:
        return '''
@numba.njit(cache=True, inline="always")
def solve_0(A, b, x, piv):
    """Nothing to solve (no constraints)."""
    return
'''
    if size in _CLOSED_FORMS:
        return _CLOSED_FORMS[size]
    return _BY_ELIMINATION.format(k=size)
