"""Hand-written numba kernels of general systems: the anchors of the general-systems tables.

Each kernel runs exactly the algorithm the generated kernel of
:mod:`dirac.codegen.kernel_source` runs for that system -- the same iteration, the same
convergence test, the same order of operations where it matters -- but written by hand
for the one system: closed-form constraint, Jacobian, force and mass, scalar unknowns,
closed-form small solves, nothing allocated inside a step. ``dirac bench`` times both in
the same run; their ratio is what the generator costs over hand-written code, and the two
final states must agree to round-off (checked in the run).

* :func:`pendulum_rattle`: RATTLE (Andersen 1983; Hairer, Lubich & Wanner VII.1.4) for
  the planar pendulum in Cartesian coordinates, ``chi = x^2 + y^2 - l^2``, Newton on the
  one multiplier.
* :func:`double_pendulum_rattle`: the same for the double pendulum, two rod constraints,
  Newton on two multipliers with Cramer's rule.
* :func:`polar_pendulum_rattle`: RATTLE for a configuration-dependent mass (Jay 1996),
  the pendulum in polar coordinates ``(r, th)``, ``M = diag(m, m r^2)``, ``chi = r - l``;
  simplified Newton on ``(p_half, q1, lam)`` with a finite-difference Jacobian.
* :func:`first_order_midpoint`: the implicit midpoint rule on the Dirac field (240) of
  ``L = x y_dot - (x^2 + y^2)/2 + z_dot^2/2 - z^2/2`` (second-class ``p_x = 0``,
  ``p_y - x = 0``), written in closed form: ``(x, y, z, p_x, p_y, p_z)_dot =
  (-y, x, p_z, 0, -y, -z)``; then the projection onto the (linear) constraints.

Each returns the number of steps done (``n_steps`` unless a Newton iteration failed).
"""

from __future__ import annotations

import numba
import numpy as np

__all__ = ["pendulum_rattle", "double_pendulum_rattle", "polar_pendulum_rattle", "first_order_midpoint"]


@numba.njit(cache=True)
def pendulum_rattle(q, p, mass, g, length, dt, n_steps, tol, max_iter):
    """RATTLE for ``H = |p|^2/(2m) + m g y``, ``chi = x^2 + y^2 - l^2``, in place."""
    x, y = q[0], q[1]
    px, py = p[0], p[1]
    h = dt
    inv = 1.0 / mass
    ll = length * length
    for step in range(n_steps):
        phx = px
        phy = py - 0.5 * h * mass * g
        qpx = x + h * (inv * phx)
        qpy = y + h * (inv * phy)
        ax = inv * (2.0 * x)
        ay = inv * (2.0 * y)
        lam = 0.0
        x1, y1 = qpx, qpy
        converged = False
        for _it in range(max_iter):
            chi = x1 * x1 + y1 * y1 - ll
            if abs(chi) <= tol * (1.0 + x1 * x1 + y1 * y1):
                converged = True
                break
            jac = -0.5 * h * h * (2.0 * x1 * ax + 2.0 * y1 * ay)
            lam -= chi / jac
            x1 = qpx - 0.5 * h * h * (ax * lam)
            y1 = qpy - 0.5 * h * h * (ay * lam)
        if not converged:
            q[0], q[1], p[0], p[1] = x, y, px, py
            return step
        phx -= 0.5 * h * (2.0 * x * lam)
        phy -= 0.5 * h * (2.0 * y * lam)
        x, y = x1, y1
        px = phx
        py = phy - 0.5 * h * mass * g
        gx, gy = 2.0 * x, 2.0 * y
        rhs = gx * (inv * px) + gy * (inv * py)
        s = 0.5 * h * (gx * (inv * gx) + gy * (inv * gy))
        mu = rhs / s
        px -= 0.5 * h * (gx * mu)
        py -= 0.5 * h * (gy * mu)
    q[0], q[1], p[0], p[1] = x, y, px, py
    return n_steps


@numba.njit(cache=True)
def double_pendulum_rattle(q, p, m1, m2, g, l1, l2, dt, n_steps, tol, max_iter):
    """RATTLE for the double pendulum in Cartesian coordinates ``(x1, y1, x2, y2)``,
    ``chi_1 = x1^2 + y1^2 - l1^2``, ``chi_2 = (x2 - x1)^2 + (y2 - y1)^2 - l2^2``, in place."""
    inv = np.array([1.0 / m1, 1.0 / m1, 1.0 / m2, 1.0 / m2])
    grad_v = np.array([0.0, m1 * g, 0.0, m2 * g])
    ph = np.empty(4)
    qp = np.empty(4)
    q1 = np.empty(4)
    G0 = np.zeros((2, 4))
    G1 = np.zeros((2, 4))
    A = np.zeros((4, 2))
    h = dt
    for step in range(n_steps):
        for i in range(4):
            ph[i] = p[i] - 0.5 * h * grad_v[i]
            qp[i] = q[i] + h * (inv[i] * ph[i])
        G0[0, 0], G0[0, 1] = 2.0 * q[0], 2.0 * q[1]
        dx, dy = q[2] - q[0], q[3] - q[1]
        G0[1, 0], G0[1, 1], G0[1, 2], G0[1, 3] = -2.0 * dx, -2.0 * dy, 2.0 * dx, 2.0 * dy
        for i in range(4):
            A[i, 0] = inv[i] * G0[0, i]
            A[i, 1] = inv[i] * G0[1, i]
            q1[i] = qp[i]
        lam0 = 0.0
        lam1 = 0.0
        converged = False
        for _it in range(max_iter):
            c0 = q1[0] * q1[0] + q1[1] * q1[1] - l1 * l1
            ex, ey = q1[2] - q1[0], q1[3] - q1[1]
            c1 = ex * ex + ey * ey - l2 * l2
            size = 1.0
            for i in range(4):
                size += q1[i] * q1[i]
            if max(abs(c0), abs(c1)) <= tol * size:
                converged = True
                break
            G1[0, 0], G1[0, 1] = 2.0 * q1[0], 2.0 * q1[1]
            G1[1, 0], G1[1, 1], G1[1, 2], G1[1, 3] = -2.0 * ex, -2.0 * ey, 2.0 * ex, 2.0 * ey
            j00 = j01 = j10 = j11 = 0.0
            for i in range(4):
                j00 += G1[0, i] * A[i, 0]
                j01 += G1[0, i] * A[i, 1]
                j10 += G1[1, i] * A[i, 0]
                j11 += G1[1, i] * A[i, 1]
            f = -0.5 * h * h
            j00, j01, j10, j11 = f * j00, f * j01, f * j10, f * j11
            det = 1.0 / (j00 * j11 - j01 * j10)
            d0 = (j11 * c0 - j01 * c1) * det
            d1 = (j00 * c1 - j10 * c0) * det
            lam0 -= d0
            lam1 -= d1
            for i in range(4):
                q1[i] = qp[i] - 0.5 * h * h * (A[i, 0] * lam0 + A[i, 1] * lam1)
        if not converged:
            return step
        for i in range(4):
            ph[i] -= 0.5 * h * (G0[0, i] * lam0 + G0[1, i] * lam1)
            q[i] = q1[i]
            p[i] = ph[i] - 0.5 * h * grad_v[i]
        G1[0, 0], G1[0, 1] = 2.0 * q[0], 2.0 * q[1]
        ex, ey = q[2] - q[0], q[3] - q[1]
        G1[1, 0], G1[1, 1], G1[1, 2], G1[1, 3] = -2.0 * ex, -2.0 * ey, 2.0 * ex, 2.0 * ey
        r0 = r1 = s00 = s01 = s10 = s11 = 0.0
        for i in range(4):
            u = inv[i] * p[i]
            r0 += G1[0, i] * u
            r1 += G1[1, i] * u
            s00 += G1[0, i] * inv[i] * G1[0, i]
            s01 += G1[0, i] * inv[i] * G1[1, i]
            s10 += G1[1, i] * inv[i] * G1[0, i]
            s11 += G1[1, i] * inv[i] * G1[1, i]
        f = 0.5 * h
        s00, s01, s10, s11 = f * s00, f * s01, f * s10, f * s11
        det = 1.0 / (s00 * s11 - s01 * s10)
        mu0 = (s11 * r0 - s01 * r1) * det
        mu1 = (s00 * r1 - s10 * r0) * det
        for i in range(4):
            p[i] -= 0.5 * h * (G1[0, i] * mu0 + G1[1, i] * mu1)
    return n_steps


@numba.njit(cache=True)
def _polar_residual(x, r0, th0, pr, pth, mass, g, length, h, out):
    """RATTLE's implicit stage of the polar pendulum at ``x = (p_half, q1, lam)``."""
    phr, phth, r1, th1, lam = x[0], x[1], x[2], x[3], x[4]
    v0r, v0th = phr / mass, phth / (mass * r0 * r0)
    f0r = -mass * g * np.cos(th0) - mass * r0 * v0th * v0th
    f0th = mass * g * r0 * np.sin(th0)
    out[0] = phr - pr + 0.5 * h * (f0r + lam)
    out[1] = phth - pth + 0.5 * h * f0th
    v1r, v1th = phr / mass, phth / (mass * r1 * r1)
    out[2] = r1 - r0 - 0.5 * h * (v0r + v1r)
    out[3] = th1 - th0 - 0.5 * h * (v0th + v1th)
    out[4] = r1 - length


@numba.njit(cache=True)
def polar_pendulum_rattle(q, p, mass, g, length, dt, n_steps, tol, max_iter):
    """RATTLE (Jay 1996) for ``H = p_r^2/(2m) + p_th^2/(2 m r^2) - m g r cos th``,
    ``chi = r - l``, in place: simplified Newton on ``(p_half, q1, lam)`` (5 unknowns)
    with a finite-difference Jacobian factored once per step."""
    h = dt
    x = np.empty(5)
    xx = np.empty(5)
    r = np.empty(5)
    rr = np.empty(5)
    J = np.empty((5, 5))
    piv = np.empty(5, dtype=np.int64)
    for step in range(n_steps):
        r0, th0, pr, pth = q[0], q[1], p[0], p[1]
        x[0], x[1] = pr, pth
        x[2] = r0 + h * (pr / mass)
        x[3] = th0 + h * (pth / (mass * r0 * r0))
        x[4] = 0.0
        _polar_residual(x, r0, th0, pr, pth, mass, g, length, h, r)
        for j in range(5):
            for i in range(5):
                xx[i] = x[i]
            d = 1e-7 * (1.0 + abs(x[j]))
            xx[j] += d
            _polar_residual(xx, r0, th0, pr, pth, mass, g, length, h, rr)
            for i in range(5):
                J[i, j] = (rr[i] - r[i]) / d
        # LU with partial pivoting, once
        for c in range(5):
            best, rb = abs(J[c, c]), c
            for k in range(c + 1, 5):
                if abs(J[k, c]) > best:
                    best, rb = abs(J[k, c]), k
            piv[c] = rb
            if rb != c:
                for k in range(c, 5):
                    J[c, k], J[rb, k] = J[rb, k], J[c, k]
            for k in range(c + 1, 5):
                f = J[k, c] / J[c, c]
                J[k, c] = f
                if f != 0.0:
                    for jj in range(c + 1, 5):
                        J[k, jj] -= f * J[c, jj]
        converged = False
        for _it in range(max_iter):
            for c in range(5):
                if piv[c] != c:
                    r[c], r[piv[c]] = r[piv[c]], r[c]
                for k in range(c + 1, 5):
                    r[k] -= J[k, c] * r[c]
            for c in range(4, -1, -1):
                acc = r[c]
                for k in range(c + 1, 5):
                    acc -= J[c, k] * r[k]
                r[c] = acc / J[c, c]
            for i in range(5):
                x[i] -= r[i]
            _polar_residual(x, r0, th0, pr, pth, mass, g, length, h, r)
            size = 0.0
            for i in range(5):
                size = max(size, abs(r[i]))
            if size <= tol * (1.0 + x[0] * x[0] + x[1] * x[1] + x[2] * x[2] + x[3] * x[3]):
                converged = True
                break
        if not converged:
            return step
        r1, th1 = x[2], x[3]
        vth = x[1] / (mass * r1 * r1)
        p_r = x[0] - 0.5 * h * (-mass * g * np.cos(th1) - mass * r1 * vth * vth)
        p_th = x[1] - 0.5 * h * (mass * g * r1 * np.sin(th1))
        # projection onto G M^{-1} p = p_r / m = 0: mu = (p_r/m) / (h/2 /m)
        mu = (p_r / mass) / (0.5 * h * (1.0 / mass))
        q[0], q[1] = r1, th1
        p[0] = p_r - 0.5 * h * mu
        p[1] = p_th
    return n_steps


@numba.njit(cache=True)
def _first_order_field(z, out):
    out[0] = -z[1]
    out[1] = z[0]
    out[2] = z[5]
    out[3] = 0.0
    out[4] = -z[1]
    out[5] = -z[2]


@numba.njit(cache=True)
def first_order_midpoint(z, dt, n_steps, tol, max_iter):
    """Implicit midpoint on ``(x, y, z, p_x, p_y, p_z)_dot = (-y, x, p_z, 0, -y, -z)``
    with the simplified Newton iteration and finite-difference Jacobian of the generated
    kernel, then the projection onto ``p_x = 0``, ``p_y - x = 0``, in place."""
    N = 6
    f = np.empty(N)
    fz = np.empty(N)
    zz = np.empty(N)
    z1 = np.empty(N)
    zm = np.empty(N)
    r = np.empty(N)
    J = np.empty((N, N))
    piv = np.empty(N, dtype=np.int64)
    for step in range(n_steps):
        _first_order_field(z, f)
        for j in range(N):
            for i in range(N):
                zz[i] = z[i]
            d = 1e-7 * (1.0 + abs(z[j]))
            zz[j] += d
            _first_order_field(zz, fz)
            for i in range(N):
                J[i, j] = -0.5 * dt * (fz[i] - f[i]) / d
            J[j, j] += 1.0
        for c in range(N):
            best, rb = abs(J[c, c]), c
            for k in range(c + 1, N):
                if abs(J[k, c]) > best:
                    best, rb = abs(J[k, c]), k
            piv[c] = rb
            if rb != c:
                for k in range(c, N):
                    J[c, k], J[rb, k] = J[rb, k], J[c, k]
            for k in range(c + 1, N):
                fk = J[k, c] / J[c, c]
                J[k, c] = fk
                if fk != 0.0:
                    for jj in range(c + 1, N):
                        J[k, jj] -= fk * J[c, jj]
        for i in range(N):
            z1[i] = z[i] + dt * f[i]
        converged = False
        for _it in range(max_iter):
            for i in range(N):
                zm[i] = 0.5 * (z[i] + z1[i])
            _first_order_field(zm, fz)
            for i in range(N):
                r[i] = z1[i] - z[i] - dt * fz[i]
            for c in range(N):
                if piv[c] != c:
                    r[c], r[piv[c]] = r[piv[c]], r[c]
                for k in range(c + 1, N):
                    r[k] -= J[k, c] * r[c]
            for c in range(N - 1, -1, -1):
                acc = r[c]
                for k in range(c + 1, N):
                    acc -= J[c, k] * r[k]
                r[c] = acc / J[c, c]
            scl = 1.0
            size = 0.0
            for i in range(N):
                z1[i] -= r[i]
                scl = max(scl, abs(z1[i]))
                size = max(size, abs(r[i]))
            if size <= tol * scl:
                converged = True
                break
        if not converged:
            return step
        for i in range(N):
            z[i] = z1[i]
        # projection onto p_x = 0, p_y - x = 0: D = [[0,0,0,1,0,0], [-1,0,0,0,1,0]], D D^T = diag(1, 2)
        phi0, phi1 = z[3], z[4] - z[0]
        scl = 1.0
        for i in range(N):
            scl = max(scl, abs(z[i]))
        if max(abs(phi0), abs(phi1)) > tol * scl:
            y1 = phi1 / 2.0
            z[3] -= phi0
            z[0] += y1
            z[4] -= y1
    return n_steps
