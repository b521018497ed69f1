"""One step of the exact free flow of ``(M, R)`` as a numba kernel, and the heavy top's
exact-free-flow + gravity-kick composition built on it.

:class:`dirac.rigidbody.exact.ExactRigidBodyFlow` sets a flow up once (in Python) and then
evaluates it at many times. A splitting of the heavy top needs the opposite: a new free
flow after every kick, each evaluated at one time. :func:`free_flow_step` does the whole
set-up and the one evaluation inside numba, with the same formulas, branches and
evaluation order as :mod:`dirac.rigidbody.exact` (its module docstring has the closed
forms: ``M`` in Jacobi ``sn, cn, dn`` (Landau & Lifshitz, Mechanics §37), ``R = Q Z(psi)
A(M)`` with ``psi`` from an elliptic integral of the third kind (Celledoni, Fassò,
Säfström & Zanna, SIAM J. Sci. Comput. 30 (2008)); the paper's (250)–(251)), and reuses
its compiled parts (:func:`dirac.rigidbody.exact._phase_excess`). Three evaluation
changes, all exact identities (with them a heavy-top step costs about 0.6x that of a
plain textbook kernel, the anchor of ``dirac bench``'s heavy-top figures):

- ``K = pi / (2 agm(1, sqrt(1 - m)))`` from the AGM that ``sn, cn, dn`` need anyway
  (Gauss; DLMF 19.8.5) instead of ``R_F(0, 1 - m, 1)``;
- the quarter-period anchor ``q0`` of ``u0`` is read off ``sn, cn, dn (u0)`` (which come
  from ``M(0)``), so ``u0`` and the angle term ``B(u0)`` share one Carlson duplication
  (:func:`_initial_anchor`) and no Jacobi function is evaluated at ``u0``;
- the complete integral ``D = Pi(n|m) - K/(1 - n)`` enters ``psi`` as ``(q_1 - q_0) D``
  (``B(q K) = q D``, see :func:`dirac.rigidbody.exact._phase_excess`), so it is computed
  only when the step crosses a quarter-period anchor ``q``.

:func:`exact_kick_advance` composes it with the gravity kick of
:func:`dirac.rigidbody.heavy_top.kick`: ``prod_i K(g_i h/2) F(g_i h) K(g_i h/2)``, adjacent
kicks merged, exactly as :func:`dirac.rigidbody.heavy_top.heavy_top_advance` does with a
splitting free step.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from dirac.rigidbody.elliptic import carlson_rf, carlson_rf_rj, complete_pi
from dirac.rigidbody.exact import _phase_excess
from dirac.rigidbody.heavy_top import kick

__all__ = ["FreeFlowWork", "free_flow_step", "exact_kick_advance"]

_LEVELS = 40  # AGM levels of agm_sequence at most
_AGM_TOL = 1e-8  # as dirac.rigidbody.elliptic.agm_sequence


class FreeFlowWork:
    """Scratch arrays of :func:`free_flow_step` (allocated once per stepper, not per step).

    ``p`` holds the 21 flow parameters in the layout of
    :class:`dirac.rigidbody.exact.ExactRigidBodyFlow` (read by ``_phase_excess``), ``em``
    and ``en`` the AGM sequence.
    """

    def __init__(self) -> None:
        self.p = np.zeros(21)
        self.em = np.zeros(_LEVELS)
        self.en = np.zeros(_LEVELS)

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(p, em, en)`` for the kernels."""
        return self.p, self.em, self.en


@njit(cache=True, inline="always")
def _agm_fill(mc, em, en):
    """:func:`dirac.rigidbody.elliptic.agm_sequence` into preallocated arrays: the number of
    levels and the limit ``pi / (2 K)``."""
    if mc <= 0.0:
        return 0, 0.0
    a = 1.0
    emc = mc
    c = 1.0
    levels = 0
    for _ in range(_LEVELS):
        em[levels] = a
        emc = math.sqrt(emc)
        en[levels] = emc
        levels += 1
        c = 0.5 * (a + emc)
        if abs(a - emc) <= _AGM_TOL * a:
            break
        emc *= a
        a = c
    return levels, c


@njit(cache=True)
def _uniform_rotation_step(M, R, a, tau):
    """``R <- R exp(tau hat(Omega))``, ``Omega = a M`` constant (a relative equilibrium;
    Rodrigues' formula)."""
    w0 = a[0] * M[0]
    w1 = a[1] * M[1]
    w2 = a[2] * M[2]
    speed = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
    if speed == 0.0:
        return
    n0 = w0 / speed
    n1 = w1 / speed
    n2 = w2 / speed
    angle = speed * tau
    s = math.sin(angle)
    c1 = 1.0 - math.cos(angle)
    # E = 1 + s hat(n) + (1 - cos) hat(n)^2, hat(n)^2 = n n^T - 1
    E00 = 1.0 + c1 * (n0 * n0 - 1.0)
    E11 = 1.0 + c1 * (n1 * n1 - 1.0)
    E22 = 1.0 + c1 * (n2 * n2 - 1.0)
    E01 = -s * n2 + c1 * n0 * n1
    E10 = s * n2 + c1 * n0 * n1
    E02 = s * n1 + c1 * n0 * n2
    E20 = -s * n1 + c1 * n0 * n2
    E12 = -s * n0 + c1 * n1 * n2
    E21 = s * n0 + c1 * n1 * n2
    for row in range(3):
        x = R[row, 0]
        y = R[row, 1]
        z = R[row, 2]
        R[row, 0] = x * E00 + y * E10 + z * E20
        R[row, 1] = x * E01 + y * E11 + z * E21
        R[row, 2] = x * E02 + y * E12 + z * E22


@njit(cache=True, inline="always")
def _frame_row1(mu0, mu1, mu2, b):
    """First row ``r1 = e_b x mu / |e_b x mu|`` of the frame ``A(M)`` of
    :mod:`dirac.rigidbody.exact`."""
    r0 = 0.0
    r1 = 0.0
    r2 = 0.0
    if b == 0:  # (0, 1, 2): r1[1] = -mu[2], r1[2] = mu[1]
        r1 = -mu2
        r2 = mu1
        rho = math.hypot(r1, r2)
    elif b == 1:  # (1, 2, 0): r1[2] = -mu[0], r1[0] = mu[2]
        r2 = -mu0
        r0 = mu2
        rho = math.hypot(r2, r0)
    else:  # (2, 0, 1): r1[0] = -mu[1], r1[1] = mu[0]
        r0 = -mu1
        r1 = mu0
        rho = math.hypot(r0, r1)
    return r0 / rho, r1 / rho, r2 / rho


@njit(cache=True, inline="always")
def _unpermute(x1, x2, x3, p1, p2):
    """The vector with components ``x1, x2, x3`` at indices ``p1, p2`` and the third."""
    v0 = x3
    v1 = x3
    v2 = x3
    if p1 == 0:
        v0 = x1
    elif p1 == 1:
        v1 = x1
    else:
        v2 = x1
    if p2 == 0:
        v0 = x2
    elif p2 == 1:
        v1 = x2
    else:
        v2 = x2
    return v0, v1, v2


@njit(cache=True)
def _initial_anchor(sn0, cn0, dn0, p, em, en):
    """``u0 = q0 K + x0`` (``|x0| <= K/2`` up to rounding) and ``B(u0)`` of
    :func:`dirac.rigidbody.exact._phase_excess`, without its ``q0 D`` term, from
    ``sn, cn, dn (u0)`` as read off ``M(0)``.

    The anchor follows from ``sn(K/2)^2 = 1/(1 + k')``: ``|u0 - 2jK| <= K/2`` iff
    ``sn0^2 (1 + k') <= 1``. Then ``s, c, d = sn, cn, dn (x0)`` by the half- and quarter-period
    shifts (inverting ``sn(K + x) = cd x``, ``cn(K + x) = -k' sd x``, ``dn(K + x) = k' nd x``),
    and ``x0 = F(am x0) = s R_F(c^2, d^2, 1)`` (DLMF 19.25.5) and the ``R_J`` of ``B`` share one
    duplication sequence (:func:`dirac.rigidbody.elliptic.carlson_rf_rj`). Where that does
    not apply (separatrix, ``n = 0``, ``dn0 = 0`` from rounding) it is
    :class:`dirac.rigidbody.exact.ExactRigidBodyFlow`'s own route.
    """
    mc = p[5]
    n = p[6]
    K = p[12]
    kp = p[13]
    if mc == 0.0:  # separatrix: F(phi | 1) = asinh(tan phi), no period
        u0 = math.asinh(sn0 / max(cn0, dn0))
        return 0.0, u0, _phase_excess(u0, p, em, en)[3]
    if n == 0.0 or dn0 <= 0.0:
        f_red = sn0 * carlson_rf(cn0 * cn0, dn0 * dn0, 1.0)
        u0 = f_red if cn0 >= 0.0 else math.copysign(2.0, sn0) * K - f_red
        q0 = float(math.floor(u0 / K + 0.5))
        x0 = u0 - q0 * K
        p[7] = q0
        return q0, x0, _phase_excess(x0, p, em, en)[3]  # D = p[19] = 0 here
    if sn0 * sn0 * (1.0 + kp) <= 1.0:  # even anchor: q0 = 0, or +-2 beyond am = pi/2
        if cn0 >= 0.0:
            q0 = 0.0
            s = sn0
            c = cn0
        else:
            q0 = math.copysign(2.0, sn0)
            s = -sn0
            c = -cn0
        d = dn0
        rf, rj = carlson_rf_rj(c * c, d * d, 1.0, 1.0 - n * s * s)
        x0 = s * rf
        return q0, x0, n / 3.0 * s * s * s * rj - n / p[18] * x0
    d = kp / dn0
    if sn0 > 0.0:  # q0 = 1: sn u0 = c/d, cn u0 = -k' s/d
        q0 = 1.0
        c = sn0 * d
        s = -cn0 / dn0
    else:  # q0 = -1 (3 mod 4): sn u0 = -c/d, cn u0 = k' s/d
        q0 = -1.0
        c = -sn0 * d
        s = cn0 / dn0
    c2 = c * c
    rf, rj = carlson_rf_rj(c2, d * d, 1.0, p[16] + p[15] * c2)
    x0 = s * rf
    excess = p[17] / 3.0 * s * s * s * rj / p[18] if mc >= 1e-40 else 0.0
    return q0, x0, excess


@njit(cache=True, inline="always")
def _restore_orthogonality(R):
    """One Björck–Bowie step ``R <- R (3 - R^T R) / 2`` (SIAM J. Numer. Anal. 8 (1971) 358).

    The frames ``A(M)`` are normalised to ``|mu| = 1``, where the rounding of a square root
    is biased (doubles are twice as dense just below 1 as just above), so without this
    ``R^T R - 1`` would grow by about 4e-16 per step; with it, it stays at round-off. The
    change of ``R`` is of the size of that rounding.
    """
    s00 = R[0, 0] * R[0, 0] + R[1, 0] * R[1, 0] + R[2, 0] * R[2, 0]
    s11 = R[0, 1] * R[0, 1] + R[1, 1] * R[1, 1] + R[2, 1] * R[2, 1]
    s22 = R[0, 2] * R[0, 2] + R[1, 2] * R[1, 2] + R[2, 2] * R[2, 2]
    s01 = R[0, 0] * R[0, 1] + R[1, 0] * R[1, 1] + R[2, 0] * R[2, 1]
    s02 = R[0, 0] * R[0, 2] + R[1, 0] * R[1, 2] + R[2, 0] * R[2, 2]
    s12 = R[0, 1] * R[0, 2] + R[1, 1] * R[1, 2] + R[2, 1] * R[2, 2]
    # C = (3 - S)/2 = 1 + D with D = (1 - S)/2, applied as R + R D (D is of size 1e-16)
    d00 = 0.5 * (1.0 - s00)
    d11 = 0.5 * (1.0 - s11)
    d22 = 0.5 * (1.0 - s22)
    d01 = -0.5 * s01
    d02 = -0.5 * s02
    d12 = -0.5 * s12
    for row in range(3):
        x = R[row, 0]
        y = R[row, 1]
        z = R[row, 2]
        R[row, 0] = x + (x * d00 + y * d01 + z * d02)
        R[row, 1] = y + (x * d01 + y * d11 + z * d12)
        R[row, 2] = z + (x * d02 + y * d12 + z * d22)


@njit(cache=True)
def free_flow_step(M, R, a, tau, p, em_buf, en_buf):
    """Advance ``(M, R)`` in place along the exact free flow (250)–(251) for a time ``tau``.

    Parameters
    ----------
    M : numpy.ndarray, shape (3,)
        Body angular momentum.
    R : numpy.ndarray, shape (3, 3)
        Attitude (body to lab).
    a : numpy.ndarray, shape (3,)
        Inverse principal moments ``1 / I_i``.
    tau : float
        Time (any sign).
    p, em_buf, en_buf : numpy.ndarray
        Scratch of :class:`FreeFlowWork`.

    Notes
    -----
    The set-up of :meth:`dirac.rigidbody.exact.ExactRigidBodyFlow.__init__` (homogeneity
    scaling, axis ordering, amplitudes, ``m`` and ``1 - m`` without cancellation, ``u0``,
    the anchored phase) followed by one evaluation of its ``_eval_state``.
    """
    if tau == 0.0:
        return
    # relative equilibrium: M = 0, or all nonzero components on axes of one moment
    lo_a = math.inf
    hi_a = -math.inf
    for i in range(3):
        if M[i] != 0.0:
            lo_a = min(lo_a, a[i])
            hi_a = max(hi_a, a[i])
    if lo_a == math.inf or hi_a - lo_a == 0.0:
        _uniform_rotation_step(M, R, a, tau)
        return
    # homogeneity: work with |M| = 1 and max a = 1, time in units of 1 / (|M| max a)
    largest = max(abs(M[0]), abs(M[1]), abs(M[2]))
    v0 = M[0] / largest
    v1 = M[1] / largest
    v2 = M[2] / largest
    size = largest * math.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
    alpha = max(a[0], a[1], a[2])
    t = tau * (size * alpha)
    s0 = a[0] / alpha
    s1_ = a[1] / alpha
    s2_ = a[2] / alpha
    m0 = M[0] / size
    m1 = M[1] / size
    m2 = M[2] / size
    aa = (s0, s1_, s2_)
    mm = (m0, m1, m2)
    # stable argsort of three values
    lo, mid, hi = 0, 1, 2
    if aa[mid] < aa[lo]:
        lo, mid = mid, lo
    if aa[hi] < aa[mid]:
        mid, hi = hi, mid
        if aa[mid] < aa[lo]:
            lo, mid = mid, lo
    p2 = mid
    d2 = mm[hi] ** 2 * (aa[hi] - aa[mid]) - mm[lo] ** 2 * (aa[mid] - aa[lo])
    if aa[hi] == aa[mid]:
        p3, p1 = lo, hi
    elif aa[mid] == aa[lo]:
        p3, p1 = hi, lo
    elif d2 >= 0.0:
        p3, p1 = hi, lo
    else:
        p3, p1 = lo, hi
    a1 = aa[p1]
    a2 = aa[p2]
    a3 = aa[p3]
    M1 = mm[p1]
    M2 = mm[p2]
    M3 = mm[p3]
    e_a2 = M1 ** 2 * (a1 - a2) + M3 ** 2 * (a3 - a2)
    if a1 == a2:
        A1 = math.hypot(M1, M2)
        A2 = A1
        A3 = abs(M3)
        m = 0.0
        mc = 1.0
        lam = abs(a3 - a2) * A3
    else:
        A1 = math.hypot(M1, M2 * math.sqrt((a2 - a3) / (a1 - a3)))
        A2 = math.hypot(M1 * math.sqrt((a1 - a3) / (a2 - a3)), M2)
        A3 = math.hypot(M2 * math.sqrt((a2 - a1) / (a3 - a1)), M3)
        m = (A2 / A3) ** 2 * ((a2 - a1) / (a3 - a1))
        mc = (a1 - a3) / (a2 - a3) * (e_a2 / (A3 * A3 * (a3 - a1)))
        m = min(max(m, 0.0), 1.0)
        mc = min(max(mc, 0.0), 1.0)
        lam = abs((a3 - a2) * A3 * (A2 / A1))
    s3 = 1.0 if M3 >= 0.0 else -1.0
    s1 = 1.0
    cn0 = M1 / A1
    if mc == 0.0:
        s1 = 1.0 if M1 >= 0.0 else -1.0
        cn0 = abs(cn0)
    eps = 1.0 if p2 == (p1 + 1) % 3 else -1.0  # sign of the permutation (p1, p2, p3)
    s2 = -s1 * s3 * eps * math.copysign(1.0, a3 - a2)
    sn0 = M2 / (s2 * A2)
    dn0 = abs(M3) / A3
    scale = math.hypot(sn0, cn0)
    sn0 = sn0 / scale
    cn0 = cn0 / scale
    levels, agm = _agm_fill(mc, em_buf, en_buf)
    em = em_buf[:levels]
    en = en_buf[:levels]
    n_p3 = (a2 - a1) / (a2 - a3)
    n_p1 = -(A1 * A1) / (A3 * A3) if n_p3 != 0.0 else -math.inf
    if abs(n_p3) <= abs(n_p1):
        b = p3
        a_b = a3
        a_o = a1
        n_char = n_p3
    else:
        b = p1
        a_b = a1
        a_o = a3
        n_char = n_p1
    K = 0.5 * math.pi / agm if mc > 0.0 else math.inf
    G = math.sqrt(m0 * m0 + m1 * m1 + m2 * m2)
    one_n = 1.0 - n_char
    p[0] = s1 * A1
    p[1] = s2 * A2
    p[2] = s3 * A3
    p[3] = lam
    p[5] = mc
    p[6] = n_char
    p[9] = G * a_b + G * (a_o - a_b) / one_n if n_char != 0.0 else G * a_o
    p[10] = G * (a_o - a_b) / lam if n_char != 0.0 else 0.0
    p[11] = G
    p[12] = K
    p[13] = math.sqrt(mc)
    p[14] = agm
    p[15] = (m - n_char) / one_n
    p[16] = mc / one_n
    p[17] = -n_char * mc / one_n
    p[18] = one_n
    p[19] = 0.0  # D, added below only when the anchor changes
    p[20] = math.sqrt(-n_char)
    q0, x0, excess0 = _initial_anchor(sn0, cn0, dn0, p, em, en)
    p[4] = x0
    p[7] = q0
    # attitude frame at the start: Q = R A(M(0))^T
    mu0 = m0 / G
    mu1 = m1 / G
    mu2 = m2 / G
    r10, r11, r12 = _frame_row1(mu0, mu1, mu2, b)
    r20 = mu1 * r12 - mu2 * r11
    r21 = mu2 * r10 - mu0 * r12
    r22 = mu0 * r11 - mu1 * r10
    Q00 = R[0, 0] * r10 + R[0, 1] * r11 + R[0, 2] * r12
    Q01 = R[0, 0] * r20 + R[0, 1] * r21 + R[0, 2] * r22
    Q02 = R[0, 0] * mu0 + R[0, 1] * mu1 + R[0, 2] * mu2
    Q10 = R[1, 0] * r10 + R[1, 1] * r11 + R[1, 2] * r12
    Q11 = R[1, 0] * r20 + R[1, 1] * r21 + R[1, 2] * r22
    Q12 = R[1, 0] * mu0 + R[1, 1] * mu1 + R[1, 2] * mu2
    Q20 = R[2, 0] * r10 + R[2, 1] * r11 + R[2, 2] * r12
    Q21 = R[2, 0] * r20 + R[2, 1] * r21 + R[2, 2] * r22
    Q22 = R[2, 0] * mu0 + R[2, 1] * mu1 + R[2, 2] * mu2
    # evaluation at t (the loop body of exact._eval_state)
    y = lam * t + x0
    sn, cn, dn, excess = _phase_excess(y, p, em, en)
    if mc > 0.0 and n_char != 0.0:
        dq = math.floor(y / K + 0.5)  # anchor of y minus that of x0 (q0, by construction)
        if dq != 0.0:
            D = complete_pi(n_char, mc) - K / one_n
            excess += dq * D
    n0, n1, n2 = _unpermute(p[0] * cn, p[1] * sn, p[2] * dn, p1, p2)
    psi = p[9] * t + p[10] * (excess - excess0)
    mu0 = n0 / G
    mu1 = n1 / G
    mu2 = n2 / G
    r10, r11, r12 = _frame_row1(mu0, mu1, mu2, b)
    r20 = mu1 * r12 - mu2 * r11
    r21 = mu2 * r10 - mu0 * r12
    r22 = mu0 * r11 - mu1 * r10
    c = math.cos(psi)
    s = math.sin(psi)
    # Z(psi) A: rows (c r1 - s r2, s r1 + c r2, r3); R = Q Z A
    z00 = c * r10 - s * r20
    z01 = c * r11 - s * r21
    z02 = c * r12 - s * r22
    z10 = s * r10 + c * r20
    z11 = s * r11 + c * r21
    z12 = s * r12 + c * r22
    R[0, 0] = Q00 * z00 + Q01 * z10 + Q02 * mu0
    R[0, 1] = Q00 * z01 + Q01 * z11 + Q02 * mu1
    R[0, 2] = Q00 * z02 + Q01 * z12 + Q02 * mu2
    R[1, 0] = Q10 * z00 + Q11 * z10 + Q12 * mu0
    R[1, 1] = Q10 * z01 + Q11 * z11 + Q12 * mu1
    R[1, 2] = Q10 * z02 + Q11 * z12 + Q12 * mu2
    R[2, 0] = Q20 * z00 + Q21 * z10 + Q22 * mu0
    R[2, 1] = Q20 * z01 + Q21 * z11 + Q22 * mu1
    R[2, 2] = Q20 * z02 + Q21 * z12 + Q22 * mu2
    M[0] = n0 * size
    M[1] = n1 * size
    M[2] = n2 * size
    _restore_orthogonality(R)


@njit(cache=True)
def exact_kick_advance(M, R, a, w, gammas, dt, n_steps, p, em, en):
    """``n_steps`` composed steps ``prod_i K(g_i dt/2) F(g_i dt) K(g_i dt/2)`` in place.

    ``F`` is :func:`free_flow_step` (the exact free flow, ``a = 1/I``), ``K`` the gravity
    kick ``M += tau gamma x w`` (``w = m g chi``, ``gamma`` the third row of ``R``) of
    :func:`dirac.rigidbody.heavy_top.kick`; adjacent kicks are merged, as in
    :func:`dirac.rigidbody.heavy_top.heavy_top_advance`.
    """
    s = gammas.shape[0]
    if n_steps <= 0:
        return
    kick(M, R, w, 0.5 * gammas[0] * dt)
    for step in range(n_steps):
        for i in range(s):
            free_flow_step(M, R, a, gammas[i] * dt, p, em, en)
            if i < s - 1:
                kick(M, R, w, 0.5 * (gammas[i] + gammas[i + 1]) * dt)
            elif step < n_steps - 1:
                kick(M, R, w, 0.5 * (gammas[i] + gammas[0]) * dt)
            else:
                kick(M, R, w, 0.5 * gammas[i] * dt)
