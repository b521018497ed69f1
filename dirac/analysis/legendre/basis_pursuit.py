"""Least-``l1`` solutions of an under-determined linear system (basis pursuit), certified.

Basis pursuit (Chen, Donoho & Saunders, SIAM J. Sci. Comput. 20, 33 (1998)) solves

    min ||x||_1   subject to   A x = b,

a linear program. :func:`least_l1` first tries a road that needs no LP solver: the
solutions are ``x = x0 + N t`` (``N`` a basis of the null space of ``A``, ``f`` columns;
for the right inverses of (228) ``f = 3`` for 272 unknowns), so the problem is a least
absolute deviations fit in the ``f`` free coordinates ``t``. Iteratively reweighted least
squares in ``t`` approaches the minimiser; its entries below :data:`GAP` of the largest
form the zero set ``Z``, ``t`` is solved from ``N_Z t = -x0_Z``, and the entries of ``Z``
(below :data:`ZERO` of the largest then: the data are values at sample points, so the
exact sparse combination satisfies ``A x = b`` to rounding, as the LP solver's answer
does) are set to zero. The result is *certified*: with ``S`` the support and ``s`` a vector on ``Z`` with

    N_Z^T s = -N_S^T sign(x_S),   |s_i| < 1,   rank N_Z = f,

``x`` is the unique minimiser (the subgradient condition with strict inequality; Fuchs,
IEEE Trans. Inf. Theory 50, 1341 (2004), Theorem 4), to the accuracy of the data. Only a
certified answer, with a clean gap (:data:`GAP`) between its zeros and the rest, is
returned from this road, so its support is the one an LP solver finds; when no certificate is
found (a minimiser that is not unique, a near tie, more free directions than
:data:`MAX_FREE`) the LP is solved by scipy's HiGHS as before. That saves the import of
``scipy.optimize`` (about 0.3 s) and the solve (about 0.2 s) on (228).
"""

from __future__ import annotations

import numpy as np

__all__ = ["least_l1", "MAX_FREE"]

#: more free directions than this go straight to the LP solver
MAX_FREE = 12
#: certificate entries must stay this far inside [-1, 1]
MARGIN = 1e-6
#: entries below this fraction of the largest are zeros of the minimiser (the data are values
#: at sample points, accurate to about 1e-9: the LP solver's answer carries such entries too)
ZERO = 1e-6
#: and every other entry must be above this fraction of the largest (a clean split)
GAP = 1e-3
#: ``A x = b`` to this accuracy once the zeros are set (HiGHS' primal feasibility tolerance)
FEASIBLE = 1e-7


def least_l1(A: np.ndarray, b: np.ndarray) -> np.ndarray | None:
    """``argmin ||x||_1`` subject to ``A x = b`` (``A`` of full row rank), or ``None`` if the LP fails.

    The certified road of the module text first, else ``linprog`` (HiGHS) on
    ``min 1^T (u + v)``, ``A (u - v) = b``, ``u, v >= 0``.
    """
    x = _certified(A, b)
    if x is not None:
        return x
    from scipy.optimize import linprog  # scipy.optimize costs ~0.3 s to import: only when needed

    m = A.shape[1]
    lp = linprog(np.ones(2 * m), A_eq=np.hstack([A, -A]), b_eq=b, bounds=(0, None), method="highs")
    if lp.status != 0:
        return None
    return lp.x[:m] - lp.x[m:]


def _certified(A: np.ndarray, b: np.ndarray) -> np.ndarray | None:
    """The unique least-``l1`` solution with its certificate (module text), or ``None``."""
    if A.ndim != 2 or A.shape[0] == 0 or not np.all(np.isfinite(A)) or not np.all(np.isfinite(b)):
        return None
    U, S, Vt = np.linalg.svd(A, full_matrices=True)
    if S[0] == 0:
        return None
    r = int(np.sum(S > 1e-12 * S[0]))
    x0 = Vt[:r].T @ ((U[:, :r].T @ b) / S[:r])
    if np.max(np.abs(A @ x0 - b)) > 1e-9 * max(1.0, float(np.max(np.abs(b)))):
        return None
    N = Vt[r:].T
    f = N.shape[1]
    if f == 0:
        return x0  # a single solution
    if f > MAX_FREE:
        return None
    size = max(float(np.max(np.abs(x0))), 1e-300)
    # iteratively reweighted least squares in t, smoothing |.| by eps, eps shrinking
    t = np.linalg.lstsq(N, -x0, rcond=None)[0]
    eps = size
    for _ in range(80):
        res = x0 + N @ t
        w = 1.0 / np.sqrt(res * res + eps * eps)
        try:
            t = np.linalg.solve((N.T * w) @ N, -(N.T * w) @ x0)
        except np.linalg.LinAlgError:
            return None
        eps = max(eps * 0.5, 1e-13 * size)
    x = x0 + N @ t
    big = float(np.max(np.abs(x)))
    if big == 0:
        return None
    # the small entries (reweighting may leave them small but not zero) are made zero:
    # t from N_Z t = -x0_Z, which must then leave them below ZERO and the rest above GAP
    Z = np.abs(x) < GAP * big
    if not Z.any() or np.linalg.matrix_rank(N[Z]) < f:
        return None
    x = x0 + N @ np.linalg.lstsq(N[Z], -x0[Z], rcond=None)[0]
    big = float(np.max(np.abs(x)))
    if big == 0 or np.max(np.abs(x[Z])) > ZERO * big or np.min(np.abs(x[~Z]), initial=big) < GAP * big:
        return None  # no clean split into zeros and non-zeros: a near tie, the LP decides
    x[Z] = 0.0
    if np.max(np.abs(A @ x - b)) > FEASIBLE * max(1.0, float(np.max(np.abs(b)))):
        return None
    g = N[~Z].T @ np.sign(x[~Z])
    s = np.linalg.lstsq(N[Z].T, -g, rcond=None)[0]
    if np.max(np.abs(N[Z].T @ s + g)) > 1e-9 * max(1.0, float(np.max(np.abs(g)))) or np.max(np.abs(s), initial=0.0) >= 1 - MARGIN:
        return None  # no certificate of this form: the LP decides
    return x
