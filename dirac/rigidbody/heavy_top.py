"""The heavy top by splitting: gravity kicks composed with a free-body step (numba kernels).

``H = H_0(M) + V(R)``, ``V = m g <chi, gamma>``, ``gamma = R^T e_z`` (third row of ``R``).
With the bracket (248)–(249) the flow of ``V`` alone is a *kick*: ``R`` stays fixed and
``dM/dt = m g gamma x chi``, so ``M(t) = M(0) + t m g gamma x chi`` exactly. The base step
``K(h/2) F(h) K(h/2)`` with ``F`` a free-body Strang step of :mod:`dirac.rigidbody.splitting`
is symmetric, so a composition of :mod:`dirac.compositions` raises its order (Celledoni,
Fassò, Säfström & Zanna, SIAM J. Sci. Comput. 30 (2008); Touma & Wisdom 1994).
"""

from __future__ import annotations

from numba import njit

from dirac.rigidbody.splitting import advance_sequence

__all__ = ["kick", "heavy_top_advance"]


@njit(cache=True, inline="always")
def kick(M, R, w, tau):
    """``M += tau (gamma x w)`` in place, ``gamma`` the third row of ``R``: the exact flow of
    the potential for a time ``tau`` (``w = m g chi``)."""
    g0 = R[2, 0]
    g1 = R[2, 1]
    g2 = R[2, 2]
    M[0] += tau * (g1 * w[2] - g2 * w[1])
    M[1] += tau * (g2 * w[0] - g0 * w[2])
    M[2] += tau * (g0 * w[1] - g1 * w[0])


@njit(cache=True)
def heavy_top_advance(M, R, w, gammas, axes, rates, fractions, casimir_rate, dt, n_steps):
    """``n_steps`` composed steps ``prod_i K(g_i dt/2) F(g_i dt) K(g_i dt/2)`` in place.

    ``w = m g chi`` (body frame); ``F`` is the free-body Strang step given by the
    sub-step sequence ``(axes, rates, fractions, casimir_rate)`` of
    :func:`dirac.rigidbody.splitting.build_sequence`. Adjacent kicks are merged.
    """
    s = gammas.shape[0]
    if n_steps <= 0:
        return
    kick(M, R, w, 0.5 * gammas[0] * dt)
    for step in range(n_steps):
        for i in range(s):
            advance_sequence(M, R, axes, rates, fractions, casimir_rate, gammas[i] * dt, 1, True)
            if i < s - 1:
                kick(M, R, w, 0.5 * (gammas[i] + gammas[i + 1]) * dt)
            elif step < n_steps - 1:
                kick(M, R, w, 0.5 * (gammas[i] + gammas[0]) * dt)
            else:
                kick(M, R, w, 0.5 * gammas[i] * dt)
