"""Jacobi elliptic functions and Carlson's symmetric integrals (numba kernels).

Everything takes the *complementary* parameter ``mc = 1 - m`` where it matters, so the
near-separatrix regime ``m -> 1`` of the rigid body loses no accuracy (``scipy.special``'s
``ellipj`` receives ``m`` and switches to a first-order approximation for
``m > 1 - 1e-9``).

- Jacobi ``sn, cn, dn`` by Bulirsch's descending Gauss transformation (no arcsine, so
  no loss near ``m = 1``, unlike the A&S 16.4 amplitude recursion), after reduction of the
  argument to ``|u| <= K`` with a half-period shift near ``+-K``.
- Carlson's ``R_F``, ``R_J``, ``R_C`` by the duplication theorem (Carlson 1995, Numer.
  Algorithms 10, 13; as in Numerical Recipes 3rd ed., Sect. 6.12).
- Legendre's incomplete integrals of the first and third kind through them
  (DLMF 19.25.5, 19.25.14), extended to any real amplitude by quasi-periodicity.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = [
    "agm_sequence",
    "sncndn",
    "reduced_sncndn",
    "carlson_rf",
    "carlson_rj",
    "carlson_rf_rj",
    "carlson_rc",
    "elliptic_f",
    "elliptic_pi",
    "complete_pi",
    "jacobi_sncndn",
]

_AGM_TOL = 1e-8  # quadratic convergence: the next AGM step is exact to ~1e-16


def agm_sequence(mc: float) -> tuple[np.ndarray, np.ndarray, float]:
    """AGM of ``(1, sqrt(mc))`` for :func:`sncndn` (Bulirsch 1965; Numerical Recipes 3rd
    ed., ``sncndn``).

    Parameters
    ----------
    mc : float
        Complementary parameter ``1 - m``, in ``(0, 1]``.

    Returns
    -------
    em, en : numpy.ndarray
        The ``a_i`` and ``b_i = sqrt(a_{i-1} b_{i-1})`` of the AGM.
    agm : float
        Its limit ``(a + b)/2 = pi / (2 K(m))``.
    """
    if mc <= 0.0:
        return np.zeros(0), np.zeros(0), 0.0
    em: list[float] = []
    en: list[float] = []
    a = 1.0
    emc = mc
    c = 1.0
    for _ in range(40):
        em.append(a)
        emc = math.sqrt(emc)
        en.append(emc)
        c = 0.5 * (a + emc)
        if abs(a - emc) <= _AGM_TOL * a:
            break
        emc *= a
        a = c
    return np.array(em), np.array(en), c


@njit(cache=True)
def sncndn(u, em, en, agm):
    """Jacobi ``sn, cn, dn (u | m)`` by Bulirsch's descending Gauss transformation.

    Takes the AGM data of :func:`agm_sequence` (so ``mc = 1 - m`` is used directly). No
    arcsine is taken, so it stays accurate as ``m -> 1``; ``dn`` is formed from positive
    terms only. Empty ``em`` means ``m = 1``: ``sn = tanh u``, ``cn = dn = sech u``.
    Reduce ``|u| <= K`` first for relative accuracy of ``cn`` near its zeros.
    """
    levels = em.shape[0]
    if levels == 0:
        sech = 1.0 / math.cosh(u)
        return math.tanh(u), sech, sech
    if abs(u) < 1e-150:
        # sn = u - (1 + m) u^3 / 6 + ..., cn = 1 - u^2 / 2, dn = 1 - m u^2 / 2: exact in double
        # here, and cn / sn below would overflow for a subnormal u
        return u, 1.0, 1.0
    x = u * agm
    sn = math.sin(x)
    cn = math.cos(x)
    dn = 1.0
    if sn == 0.0:
        return sn, cn, dn
    a = cn / sn
    c = agm * a
    for ii in range(levels - 1, -1, -1):
        b = em[ii]
        a *= c
        c *= dn
        dn = (en[ii] + a) / (b + a)
        a = c / b
    a = 1.0 / math.sqrt(c * c + 1.0)
    sn = a if sn >= 0.0 else -a
    cn = c * sn
    return sn, cn, dn


@njit(cache=True)
def carlson_rc(x, y):
    """Carlson's degenerate integral ``R_C(x, y)``, ``x > 0``, ``y > 0`` (DLMF 19.2.17, 19.2.18).

    With ``e = (y - x) / x``: ``atan(sqrt((y - x)/x)) / sqrt(y - x)`` for ``e > 0``,
    ``ln((sqrt x + sqrt(x - y)) / sqrt y) / sqrt(x - y)`` for ``e < 0``, and for
    ``|e| < 1e-3`` the series ``sum_k (-e)^k / (2k + 1) / sqrt(x)`` (truncation < 1e-18).
    """
    e = (y - x) / x
    if abs(e) < 1e-3:
        g = 1.0 - e * (1.0 / 3.0 - e * (0.2 - e * (1.0 / 7.0 - e * (1.0 / 9.0 - e / 11.0))))
        return g / math.sqrt(x)
    if e > 0.0:
        return math.atan(math.sqrt(e)) / math.sqrt(y - x)
    d = math.sqrt(x - y)
    return math.log((math.sqrt(x) + d) / math.sqrt(y)) / d


@njit(cache=True)
def carlson_rf(x, y, z):
    """Carlson's ``R_F(x, y, z)`` for ``x, y, z >= 0``, at most one zero (DLMF 19.16.1)."""
    xt = x
    yt = y
    zt = z
    for _ in range(100):
        sx = math.sqrt(xt)
        sy = math.sqrt(yt)
        sz = math.sqrt(zt)
        lam = sx * (sy + sz) + sy * sz
        xt = 0.25 * (xt + lam)
        yt = 0.25 * (yt + lam)
        zt = 0.25 * (zt + lam)
        ave = (xt + yt + zt) / 3.0
        dx = (ave - xt) / ave
        dy = (ave - yt) / ave
        dz = (ave - zt) / ave
        if max(abs(dx), abs(dy), abs(dz)) <= 0.0025:
            break
    e2 = dx * dy - dz * dz
    e3 = dx * dy * dz
    return (1.0 + (e2 / 24.0 - 0.1 - 3.0 / 44.0 * e3) * e2 + e3 / 14.0) / math.sqrt(ave)


@njit(cache=True)
def carlson_rf_rj(x, y, z, p):
    """``(R_F(x, y, z), R_J(x, y, z, p))`` from one shared duplication sequence.

    ``x, y, z >= 0`` (at most one zero), ``p > 0`` (DLMF 19.16.1, 19.16.2; Carlson 1995
    duplication with the Numerical Recipes series and tolerances: relative error about
    ``1e-16``). Both integrals duplicate ``x, y, z`` identically, so ``R_F`` comes almost
    for free with ``R_J``.
    """
    c1 = 3.0 / 14.0
    c2 = 1.0 / 3.0
    c3 = 3.0 / 22.0
    c4 = 3.0 / 26.0
    c5 = 0.75 * c3
    c6 = 1.5 * c4
    c7 = 0.5 * c2
    c8 = c3 + c3
    total = 0.0
    fac = 1.0
    xt = x
    yt = y
    zt = z
    pt = p
    for _ in range(100):
        sx = math.sqrt(xt)
        sy = math.sqrt(yt)
        sz = math.sqrt(zt)
        lam = sx * (sy + sz) + sy * sz
        alpha = pt * (sx + sy + sz) + sx * sy * sz
        alpha = alpha * alpha
        beta = pt * (pt + lam) * (pt + lam)
        total += fac * carlson_rc(alpha, beta)
        fac *= 0.25
        xt = 0.25 * (xt + lam)
        yt = 0.25 * (yt + lam)
        zt = 0.25 * (zt + lam)
        pt = 0.25 * (pt + lam)
        ave = 0.2 * (xt + yt + zt + pt + pt)
        dx = (ave - xt) / ave
        dy = (ave - yt) / ave
        dz = (ave - zt) / ave
        dp = (ave - pt) / ave
        if max(abs(dx), abs(dy), abs(dz), abs(dp)) <= 0.0015:
            break
    ea = dx * (dy + dz) + dy * dz
    eb = dx * dy * dz
    ec = dp * dp
    ed = ea - 3.0 * ec
    ee = eb + 2.0 * dp * (ea - ec)
    series = (
        1.0
        + ed * (-c1 + c5 * ed - c6 * ee)
        + eb * (c7 + dp * (-c8 + dp * c4))
        + dp * ea * (c2 - dp * c3)
        - c2 * dp * ec
    )
    rj = 3.0 * total + fac * series / (ave * math.sqrt(ave))
    # R_F from the same (xt, yt, zt): its deviations are below 0.0015 * 5/3 < 0.0025
    ave_f = (xt + yt + zt) / 3.0
    fx = (ave_f - xt) / ave_f
    fy = (ave_f - yt) / ave_f
    fz = (ave_f - zt) / ave_f
    e2 = fx * fy - fz * fz
    e3 = fx * fy * fz
    rf = (1.0 + (e2 / 24.0 - 0.1 - 3.0 / 44.0 * e3) * e2 + e3 / 14.0) / math.sqrt(ave_f)
    return rf, rj


@njit(cache=True)
def carlson_rj(x, y, z, p):
    """Carlson's ``R_J(x, y, z, p)`` for ``x, y, z >= 0`` (at most one zero), ``p > 0``
    (DLMF 19.16.2)."""
    return carlson_rf_rj(x, y, z, p)[1]


@njit(cache=True)
def _f_reduced(phi, mc):
    s = math.sin(phi)
    c = math.cos(phi)
    return s * carlson_rf(c * c, c * c + mc * s * s, 1.0)


@njit(cache=True)
def _pi_reduced(phi, n, mc):
    s = math.sin(phi)
    c = math.cos(phi)
    delta2 = c * c + mc * s * s
    if n == 0.0:
        return s * carlson_rf(c * c, delta2, 1.0)
    rf, rj = carlson_rf_rj(c * c, delta2, 1.0, 1.0 - n * s * s)
    return s * rf + n / 3.0 * s * s * s * rj


@njit(cache=True)
def complete_pi(n, mc):
    """Complete integral of the third kind ``Pi(n | m)``, ``n < 1``, ``mc > 0``
    (DLMF 19.25.2); ``n = 0`` gives ``K(m)``."""
    if n == 0.0:
        return carlson_rf(0.0, mc, 1.0)
    rf, rj = carlson_rf_rj(0.0, mc, 1.0, 1.0 - n)
    return rf + n / 3.0 * rj


@njit(cache=True)
def elliptic_pi(phi, n, mc, pi_complete):
    """Incomplete ``Pi(n; phi | m) = int_0^phi dt / ((1 - n sin^2 t) sqrt(1 - m sin^2 t))``
    for any real ``phi`` (``n < 1``; DLMF 19.25.14 and 19.2.10's quasi-periodicity
    ``Pi(phi + j pi) = Pi(phi) + 2 j Pi(n | m)``); ``pi_complete = complete_pi(n, mc)``
    (ignored, may be anything, when ``|phi| <= pi/2``)."""
    j = math.floor(phi / math.pi + 0.5)
    if j == 0.0:
        return _pi_reduced(phi, n, mc)
    return 2.0 * j * pi_complete + _pi_reduced(phi - j * math.pi, n, mc)


@njit(cache=True)
def elliptic_f(phi, mc):
    """Incomplete integral of the first kind ``F(phi | m)`` for any real ``phi``
    (DLMF 19.25.5 with quasi-periodicity); ``mc = 1 - m``."""
    j = math.floor(phi / math.pi + 0.5)
    if j == 0.0:
        return _f_reduced(phi, mc)
    return 2.0 * j * carlson_rf(0.0, mc, 1.0) + _f_reduced(phi - j * math.pi, mc)


def jacobi_sncndn(u: np.ndarray | float, m: float, mc: float | None = None) -> tuple:
    """Jacobi ``sn, cn, dn (u | m)``, vectorised over ``u``.

    The argument is first reduced to ``u = 2 j K + w``, ``|w| <= K``, and near ``w = +-K``
    shifted by the half period (``sn(K + v) = cd v``, ``cn(K + v) = -k' sd v``,
    ``dn(K + v) = k' nd v``), so ``cn`` and ``dn`` keep their relative accuracy near
    ``u = K`` for ``m -> 1``.

    Parameters
    ----------
    u : array_like
        Arguments.
    m : float
        Parameter ``m = k^2`` in ``[0, 1]``.
    mc : float, optional
        ``1 - m``, given directly for accuracy near ``m = 1`` (default ``1 - m``).

    Returns
    -------
    sn, cn, dn : numpy.ndarray
    """
    mc = 1.0 - m if mc is None else float(mc)
    em, en, agm = agm_sequence(mc)
    K = carlson_rf(0.0, mc, 1.0) if mc > 0.0 else math.inf
    u_arr = np.atleast_1d(np.asarray(u, dtype=float))
    flat = u_arr.ravel()
    out = np.empty((3, flat.shape[0]))
    for i in range(flat.shape[0]):
        j, sn, cn, dn = reduced_sncndn(flat[i], em, en, agm, K, math.sqrt(mc))
        parity = 1.0 - 2.0 * (j % 2.0)
        out[0, i] = parity * sn
        out[1, i] = parity * cn
        out[2, i] = dn
    return tuple(row.reshape(u_arr.shape) for row in out)


@njit(cache=True)
def reduced_sncndn(u, em, en, agm, K, kp):
    """``u = 2 j K + w`` with ``|w| <= K``; returns ``j`` and ``sn, cn, dn (w)`` (``cn >= 0``).

    Near ``w = +-K`` the half-period shift keeps ``cn`` and ``dn`` *relatively* accurate
    where both are small (the near-separatrix turning points of the rigid body).
    ``kp = sqrt(1 - m)``; ``em`` empty (``m = 1``) means no period.
    """
    if em.shape[0] == 0:
        sn, cn, dn = sncndn(u, em, en, agm)
        return 0.0, sn, cn, dn
    j = math.floor(u / (2.0 * K) + 0.5)
    w = u - 2.0 * j * K
    if abs(w) <= 0.5 * K:
        sn, cn, dn = sncndn(w, em, en, agm)
        return j, sn, cn, dn
    sign = 1.0 if w > 0.0 else -1.0
    snv, cnv, dnv = sncndn(w - sign * K, em, en, agm)
    return j, sign * cnv / dnv, -sign * kp * snv / dnv, kp / dnv
