"""The jump of the momenta at a generalized impulse, as plain loops shared by single runs and ensembles.

Integrating Lagrange's equations ``d/dt dL/dq_dot - dL/dq = Q + G^T lambda`` over a blow of
vanishing duration gives ``Delta p = J + G^T nu`` (``J`` the generalized impulse, Lamb's
``Q_r'``; ``G^T nu`` the constraints' own impulse), and the velocity stage
``G M^{-1} p + d chi/dt = 0`` must hold after it as before, so

    Delta p = J - G^T (G M^{-1} G^T)^{-1} G M^{-1} J,

the work of the blow being ``J . (q_dot_before + q_dot_after) / 2`` (the change of the
kinetic energy when the constraints do not move; Lamb, *Higher Mechanics*, Sect. 27).

:func:`impulse_kick` does this with its own Gaussian elimination (partial pivoting) in
plain loops of additions and products, so that the same text gives the same bits run by
Python (:meth:`dirac.flows.mechanics.MechanicalSystem.apply_impulse`, a single run) and
compiled by numba (the member loop of a general ensemble pastes :func:`kick_source` into its
module: numba keeps IEEE arithmetic, no fused or reordered operations without fastmath).
"""

from __future__ import annotations

import inspect

import numpy as np

__all__ = ["impulse_kick", "kick_source"]


def impulse_lu_factor(A, piv):
    """LU factors of the square ``A`` in place, rows exchanged by partial pivoting (``piv``)."""
    n = A.shape[0]
    for k in range(n):
        best = k
        for i in range(k + 1, n):
            if abs(A[i, k]) > abs(A[best, k]):
                best = i
        piv[k] = best
        if best != k:
            for j in range(n):
                swap = A[k, j]
                A[k, j] = A[best, j]
                A[best, j] = swap
        for i in range(k + 1, n):
            A[i, k] = A[i, k] / A[k, k]
            for j in range(k + 1, n):
                A[i, j] = A[i, j] - A[i, k] * A[k, j]


def impulse_lu_solve(A, piv, b):
    """``b <- A^{-1} b`` with the factors of :func:`impulse_lu_factor`."""
    n = A.shape[0]
    for k in range(n):
        if piv[k] != k:
            swap = b[k]
            b[k] = b[piv[k]]
            b[piv[k]] = swap
    for i in range(n):
        acc = b[i]
        for j in range(i):
            acc = acc - A[i, j] * b[j]
        b[i] = acc
    for i in range(n - 1, -1, -1):
        acc = b[i]
        for j in range(i + 1, n):
            acc = acc - A[i, j] * b[j]
        b[i] = acc / A[i, i]


def impulse_kick(M, G, p, J):
    """Apply the impulse ``J`` to the momenta ``p`` (in place) at a configuration with mass
    matrix ``M`` (n, n) and constraint Jacobian ``G`` (m, n) (module docstring); returns the
    work of the blow, ``J . (q_dot_before + q_dot_after) / 2``.

    Parameters
    ----------
    M : numpy.ndarray
        ``M(q, t)``, symmetric positive definite.
    G : numpy.ndarray
        ``d chi / dq`` at ``(q, t)``, shape ``(m, n)`` (``m = 0``: no constraints).
    p : numpy.ndarray
        The momenta before the blow; overwritten by those after it.
    J : numpy.ndarray
        The generalized impulse.
    """
    n = p.shape[0]
    m = G.shape[0]
    LU = M.copy()
    piv = np.zeros(n, dtype=np.int64)
    impulse_lu_factor(LU, piv)
    kick = J.copy()
    if m > 0:
        A = np.zeros((n, m))  # M^-1 G^T
        column = np.zeros(n)
        for a in range(m):
            for i in range(n):
                column[i] = G[a, i]
            impulse_lu_solve(LU, piv, column)
            for i in range(n):
                A[i, a] = column[i]
        S = np.zeros((m, m))  # G M^-1 G^T
        for a in range(m):
            for b in range(m):
                acc = 0.0
                for i in range(n):
                    acc = acc + G[a, i] * A[i, b]
                S[a, b] = acc
        y = J.copy()
        impulse_lu_solve(LU, piv, y)  # M^-1 J
        nu = np.zeros(m)
        for a in range(m):
            acc = 0.0
            for i in range(n):
                acc = acc + G[a, i] * y[i]
            nu[a] = acc
        pivm = np.zeros(m, dtype=np.int64)
        impulse_lu_factor(S, pivm)
        impulse_lu_solve(S, pivm, nu)
        for i in range(n):
            acc = 0.0
            for a in range(m):
                acc = acc + G[a, i] * nu[a]
            kick[i] = kick[i] - acc
    before = p.copy()
    impulse_lu_solve(LU, piv, before)
    for i in range(n):
        p[i] = p[i] + kick[i]
    after = p.copy()
    impulse_lu_solve(LU, piv, after)
    work = 0.0
    for i in range(n):
        work = work + J[i] * (before[i] + after[i])
    return work / 2.0


def kick_source() -> str:
    """The text of :func:`impulse_kick` and its two helpers, each under ``@numba.njit``, for a
    generated module that imports ``numba`` and ``numpy as np``."""
    parts = []
    for function in (impulse_lu_factor, impulse_lu_solve, impulse_kick):
        text = inspect.getsource(function)
        parts.append("@numba.njit(cache=True)\n" + text)
    return "\n\n".join(parts)
