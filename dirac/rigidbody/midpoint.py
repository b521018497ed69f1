"""The implicit midpoint rule on the Euler–Poisson equations (250)–(251) (numba kernel).

``M`` first, by Newton on the 3 unknowns ``Mm = (M0 + M1)/2`` with the exact Jacobian;
then ``R1 = R0 cay(h Omega_m)`` with the Cayley transform
``cay(A) = (1 + A/2)(1 - A/2)^{-1}`` of ``hat(Omega_m)`` (the midpoint rule for
``dR/dt = R hat(Omega_m)``, orthogonal by construction). Every quadratic invariant --
``|M|^2``, ``H_0``, ``m = R M``, ``R^T R = 1`` -- is kept (Cooper 1987; Austin,
Krishnaprasad & Wang 1993; Hairer, Lubich & Wanner, Geometric Numerical Integration,
Sect. IV.2).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["midpoint_rigid_body"]


@njit(cache=True)
def _report(info, steps_done, failed, evals, increment):
    """Fill ``info = [steps_done, failed (0/1), evaluations, last_increment]``."""
    info[0] = steps_done
    info[1] = 1.0 if failed else 0.0
    info[2] = evals
    info[3] = increment


@njit(cache=True)
def _solve3(J, r):
    """Solve the 3 x 3 system J d = r by Cramer's rule."""
    c00 = J[1, 1] * J[2, 2] - J[1, 2] * J[2, 1]
    c01 = J[1, 2] * J[2, 0] - J[1, 0] * J[2, 2]
    c02 = J[1, 0] * J[2, 1] - J[1, 1] * J[2, 0]
    det = J[0, 0] * c00 + J[0, 1] * c01 + J[0, 2] * c02
    d0 = (r[0] * c00 + J[0, 1] * (r[2] * J[1, 2] - r[1] * J[2, 2]) + J[0, 2] * (r[1] * J[2, 1] - r[2] * J[1, 1])) / det
    d1 = (J[0, 0] * (r[1] * J[2, 2] - r[2] * J[1, 2]) + r[0] * c01 + J[0, 2] * (r[2] * J[1, 0] - r[1] * J[2, 0])) / det
    d2 = (J[0, 0] * (J[1, 1] * r[2] - J[2, 1] * r[1]) + J[0, 1] * (J[2, 0] * r[1] - J[1, 0] * r[2]) + r[0] * c02) / det
    return d0, d1, d2


@njit(cache=True)
def midpoint_rigid_body(M, R, inv_inertia, dt, n_steps, with_R, tol, max_iter, info):
    """Advance ``(M, R)`` in place by ``n_steps`` implicit-midpoint steps (Euler–Poisson).

    Newton on ``Mm = M0 + h/2 Mm x (I^{-1} Mm)``, Jacobian
    ``1 - h/2 (hat(Mm) I^{-1} - hat(Omega_m))``; then ``M1 = 2 Mm - M0`` and
    ``R1 = R0 (1 + h/2 hat(Omega_m)) (1 - h/2 hat(Omega_m))^{-1}``.
    ``info = [steps_done, failed, evaluations, last_increment]``.
    """
    a0 = inv_inertia[0]
    a1 = inv_inertia[1]
    a2 = inv_inertia[2]
    evals = 0.0
    size = 0.0
    J = np.empty((3, 3))
    r = np.empty(3)
    B = np.zeros((3, 3))  # hat(b): only the off-diagonal entries are set, per step
    C = np.empty((3, 3))
    for step in range(n_steps):
        x0 = M[0]
        x1 = M[1]
        x2 = M[2]
        m0 = x0
        m1 = x1
        m2 = x2
        hh = 0.5 * dt
        converged = False
        for _ in range(max_iter):
            w0 = a0 * m0
            w1 = a1 * m1
            w2 = a2 * m2
            r[0] = m0 - x0 - hh * (m1 * w2 - m2 * w1)
            r[1] = m1 - x1 - hh * (m2 * w0 - m0 * w2)
            r[2] = m2 - x2 - hh * (m0 * w1 - m1 * w0)
            evals += 1.0
            # d(M x (A M))/dM = hat(M) A - hat(A M)
            J[0, 0] = 1.0 - hh * (0.0)
            J[0, 1] = -hh * (-m2 * a1 + w2)
            J[0, 2] = -hh * (m1 * a2 - w1)
            J[1, 0] = -hh * (m2 * a0 - w2)
            J[1, 1] = 1.0
            J[1, 2] = -hh * (-m0 * a2 + w0)
            J[2, 0] = -hh * (-m1 * a0 + w1)
            J[2, 1] = -hh * (m0 * a1 - w0)
            J[2, 2] = 1.0
            d0, d1, d2 = _solve3(J, r)
            m0 -= d0
            m1 -= d1
            m2 -= d2
            size = max(abs(d0), abs(d1), abs(d2))
            scale = max(1e-300, math.sqrt(m0 * m0 + m1 * m1 + m2 * m2))
            if size <= tol * scale:
                converged = True
                break
            if size != size:
                break
        if not converged:
            _report(info, step, True, evals, size)
            return
        M[0] = 2.0 * m0 - x0
        M[1] = 2.0 * m1 - x1
        M[2] = 2.0 * m2 - x2
        if with_R:
            # C = (1 + B)(1 - B)^{-1}, B = hh hat(w)
            b0 = hh * a0 * m0
            b1 = hh * a1 * m1
            b2 = hh * a2 * m2
            # (1 - B)^{-1} = (1 + B + b b^T) / (1 + |b|^2)   for skew B = hat(b)
            nb = 1.0 + b0 * b0 + b1 * b1 + b2 * b2
            # Cayley: cay = 1 + 2 (B + B^2) / (1 + |b|^2)
            B[0, 1] = -b2
            B[0, 2] = b1
            B[1, 0] = b2
            B[1, 2] = -b0
            B[2, 0] = -b1
            B[2, 1] = b0
            for i in range(3):
                for j in range(3):
                    acc = 0.0
                    for k in range(3):
                        acc += B[i, k] * B[k, j]
                    C[i, j] = (1.0 if i == j else 0.0) + 2.0 * (B[i, j] + acc) / nb
            for i in range(3):
                r0 = R[i, 0]
                r1 = R[i, 1]
                r2 = R[i, 2]
                for j in range(3):
                    R[i, j] = r0 * C[0, j] + r1 * C[1, j] + r2 * C[2, j]
    _report(info, n_steps, False, evals, size)
