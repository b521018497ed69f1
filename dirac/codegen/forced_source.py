"""Step kernels of forced systems: generalized forces ``Q(q, q_dot, t)`` not derived from a potential.

Appended to the kernel module of a mechanical system (:mod:`dirac.codegen.kernel_source`,
whose ``force`` then holds ``dH/dq - Q``), this module's source adds

* ``applied_force(q, v, t, c, out)``: ``Q(q, v, t)`` as straight-line code (the printer
  of :func:`dirac.codegen.kernel_source.emit_function`);
* ``forced_rattle_run``: RATTLE with forces from the discrete Lagrange–d'Alembert principle
  (Marsden & West, "Discrete mechanics and variational integrators", Acta Numerica 10
  (2001), Sect. 3.2), with the discrete forces ``f_d^-(q0, q1) = h/2 Q(q0, v_-, t0)`` and
  ``f_d^+(q0, q1) = h/2 Q(q1, v_+, t1)`` at the velocities ``v_- = M(q0)^{-1} p_half``,
  ``v_+ = M(q1)^{-1} p_half`` of the half-step momentum (for a constant mass both are
  ``(q1 - q0)/h``). Written out (``f = dH/dq`` at ``v``):

      p_half = p0 - h/2 (f(q0, v_-, t0) - Q(q0, v_-, t0) + G(q0)^T lam),
      q1 = q0 + h/2 (v_- + v_+),  chi(q1, t1) = 0,
      p1 = p_half - h/2 (f(q1, v_+, t1) - Q(q1, v_+, t1) + G(q1)^T mu),
      G(q1) M(q1)^{-1} p1 + d chi/dt = 0.

  The step is symmetric (exchanging ``(q0, p0, t0)`` with ``(q1, p1, t1)`` and ``h`` with
  ``-h`` gives the same equations), so its compositions with the coefficients of
  :data:`dirac.compositions.COMPOSITIONS` reach order 4, 6, 8. The work of the forces is
  carried along with the symmetric rule ``W1 = W0 + h/2 (Q(q0, v_-)·v_- + Q(q1, v_+)·v_+)``,
  which keeps the augmented step symmetric (so ``energy - work`` is conserved to the
  method's order);
* ``conformal_run``: for ``Q = -gamma M q_dot = -gamma p`` with a constant scalar ``gamma``
  (linear damping of a constant-mass system whose damping matrix is ``gamma M``), the
  splitting ``D_{h/2} o RATTLE_h o D_{h/2}`` with the exact damping flow
  ``D_s: p -> exp(-gamma s) p`` (McLachlan & Perlmutter, "Conformal Hamiltonian systems",
  J. Geom. Phys. 39 (2001) 276-300). ``D_s`` keeps the hidden constraint ``G M^{-1} p = 0``
  (it is linear in ``p``) and multiplies the symplectic form by ``exp(-gamma s)``; RATTLE
  keeps it; so each step contracts it by exactly ``exp(-gamma h)``. The work of a damping
  sub-step is exactly the change of the kinetic energy, ``T (exp(-2 gamma s) - 1)``.

``info`` is filled as in :mod:`dirac.codegen.kernel_templates`; ``work`` (float64, 1) is
the accumulated work ``W``, updated in place.
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy

from dirac.codegen.kernel_source import emit_function
from dirac.codegen.kernel_templates import RATTLE_NEWTON

__all__ = ["forced_kernel_source"]

_FORCED_RATTLE = '''

@numba.njit(cache=True)
def forced_rattle_run(q, p, t, c, fractions, dt, n_steps, tol, max_iter, info, work_done):
    """RATTLE with the discrete Lagrange-d'Alembert forces (see dirac.codegen.forced_source),
    composed with the sub-steps h = dt fractions[s]; work_done[0] += the work of Q.
    The module's force() is dH/dq - Q, so rattle_residual solves the forced first half."""
    q_save = np.empty(__N__)
    p_save = np.empty(__N__)
    x = np.empty(__NX__)
    xx = np.empty(__NX__)
    r = np.empty(__NX__)
    rr = np.empty(__NX__)
    J = np.empty((__NX__, __NX__))
    pivx = np.empty(__NX__, dtype=np.int64)
    v = np.empty(__N__)
    f = np.empty(__N__)
    ph = np.empty(__N__)
    q1 = np.empty(__N__)
    v0 = np.empty(__N__)
    f0 = np.empty(__N__)
    v1 = np.empty(__N__)
    col = np.empty(__N__)
    u = np.empty(__N__)
    qa = np.empty(__N__)
    Qa = np.empty(__N__)
    work = np.empty((__N__, __N__))
    pivn = np.empty(__N__, dtype=np.int64)
    work0 = np.empty((__N__, __N__))
    piv0 = np.empty(__N__, dtype=np.int64)
    chi = np.zeros(__M__)
    G0 = np.zeros((__M__, __N__))
    G1 = np.zeros((__M__, __N__))
    W = np.zeros((__N__, __M__))
    S = np.empty((__M__, __M__))
    rhs = np.empty(__M__)
    mu = np.empty(__M__)
    pivm = np.empty(__M__, dtype=np.int64)
    evals = 0.0
    residual = 0.0
    w_save = work_done[0]
    for step in range(n_steps):
        for i in range(__N__):
            q_save[i] = q[i]
            p_save[i] = p[i]
        w_save = work_done[0]
        tau = t + step * dt
        for s in range(fractions.shape[0]):
            h = dt * fractions[s]
            tau1 = tau + h
            velocity(q, p, tau, c, v, work0, piv0)  # M(q, tau) factored once per sub-step
            for i in range(__N__):
                x[i] = p[i]
                x[__N__ + i] = q[i] + h * v[i]
                qa[i] = q[i]
            for a in range(__M__):
                x[2 * __N__ + a] = 0.0
''' + RATTLE_NEWTON + '''            if not converged:
                for i in range(__N__):
                    q[i] = q_save[i]
                    p[i] = p_save[i]
                work_done[0] = w_save
                report(info, step, True, evals, residual)
                return
            for i in range(__N__):
                ph[i] = x[i]
                q[i] = x[__N__ + i]
            # the work of Q over the sub-step: h/2 (Q(q0, v_-)·v_- + Q(q1, v_+)·v_+)
            velocity(qa, ph, tau, c, v0, work, pivn)
            applied_force(qa, v0, tau, c, Qa)
            acc = 0.0
            for i in range(__N__):
                acc += Qa[i] * v0[i]
            velocity(q, ph, tau1, c, v, work, pivn)
            applied_force(q, v, tau1, c, Qa)
            for i in range(__N__):
                acc += Qa[i] * v[i]
            work_done[0] += 0.5 * h * acc
            force(q, v, tau1, c, f)
            evals += 1.0
            for i in range(__N__):
                p[i] = ph[i] - 0.5 * h * f[i]
            if __M__ > 0:
                jacobian(q, tau1, c, G1)
                velocity(q, p, tau1, c, u, work, pivn)
                for a in range(__M__):
                    for i in range(__N__):
                        col[i] = G1[a, i]
                    velocity(q, col, tau1, c, v, work, pivn)
                    for i in range(__N__):
                        W[i, a] = v[i]
                constraints_dt(q, tau1, c, chi)
                project_momentum(G1, W, u, chi, p, h, S, rhs, mu, pivm)
            tau = tau1
    report(info, n_steps, False, evals, residual)
'''

_CONFORMAL = '''

@numba.njit(cache=True, inline="always")
def damp(q, p, t, c, gamma, s, v, work, pivn, work_done):
    """The exact damping flow p -> exp(-gamma s) p; its work is T (exp(-2 gamma s) - 1)."""
    velocity(q, p, t, c, v, work, pivn)
    kinetic = 0.0
    for i in range(__N__):
        kinetic += 0.5 * p[i] * v[i]
    factor = math.exp(-gamma * s)
    for i in range(__N__):
        p[i] *= factor
    work_done[0] += kinetic * (factor * factor - 1.0)


@numba.njit(cache=True)
def conformal_run(q, p, t, c, gamma, fractions, dt, n_steps, tol, max_iter, info, work_done):
    """The conformal-symplectic splitting D_{h/2} o RATTLE_h o D_{h/2} for p_dot = ... - gamma p
    (McLachlan & Perlmutter 2001), composed with the sub-steps h = dt fractions[s]."""
    one = np.ones(1)
    v = np.empty(__N__)
    work = np.empty((__N__, __N__))
    pivn = np.empty(__N__, dtype=np.int64)
    q_save = np.empty(__N__)
    p_save = np.empty(__N__)
    evals = 0.0
    residual = 0.0
    for step in range(n_steps):
        for i in range(__N__):
            q_save[i] = q[i]
            p_save[i] = p[i]
        w_save = work_done[0]
        tau = t + step * dt
        for s in range(fractions.shape[0]):
            h = dt * fractions[s]
            damp(q, p, tau, c, gamma, 0.5 * h, v, work, pivn, work_done)
            rattle_constant_mass(q, p, tau, c, one, h, 1, tol, max_iter, info)
            evals += info[2]
            residual = info[3]
            if info[1] != 0.0:
                for i in range(__N__):
                    q[i] = q_save[i]
                    p[i] = p_save[i]
                work_done[0] = w_save
                report(info, step, True, evals, residual)
                return
            tau = tau + h
            damp(q, p, tau, c, gamma, 0.5 * h, v, work, pivn, work_done)
    report(info, n_steps, False, evals, residual)
'''


def forced_kernel_source(
    coordinates: Sequence[sympy.Symbol],
    velocities: Sequence[sympy.Symbol],
    parameters: Sequence[sympy.Symbol],
    forces: Sequence[sympy.Expr],
    time: sympy.Symbol | None,
    n_constraints: int,
    constant_mass: bool,
) -> str:
    """Source appended to a mechanical kernel module whose ``force`` includes ``-Q``
    (:func:`dirac.codegen.kernel_source.mechanical_kernel_source` with ``forces``):
    ``applied_force``, ``forced_rattle_run`` and, for a constant mass, ``conformal_run``.

    Parameters
    ----------
    coordinates, velocities
        The symbols of ``q`` and ``q_dot`` the forces are written in (read from ``q`` and ``v``).
    parameters
        The symbols read from ``c``.
    forces
        ``Q_r(q, q_dot, t)``, one per coordinate.
    time
        The time symbol, or None.
    n_constraints
        ``m``, the number of holonomic constraints.
    constant_mass
        Whether the module has ``rattle_constant_mass`` (then ``conformal_run`` is added).
    """
    n = len(coordinates)
    source = "\n\n" + emit_function("applied_force", "Q(q, v, t): the generalized forces, (n,)",
                                    [("q", list(coordinates)), ("v", list(velocities))], [("t", time)],
                                    list(forces), (n,), parameters)
    loops = _FORCED_RATTLE + (_CONFORMAL if constant_mass else "")
    return source + (loops.replace("__NX__", str(2 * n + n_constraints)).replace("__N__", str(n))
                     .replace("__M__", str(n_constraints)))
