"""Jacobi functions and Carlson integrals (dirac.rigidbody.elliptic) against mpmath at
30 digits, including the near-separatrix regime m -> 1 where scipy's ellipj degrades."""

from __future__ import annotations

import mpmath as mp
import numpy as np
import pytest

from dirac.rigidbody.elliptic import (
    carlson_rc,
    carlson_rf,
    carlson_rf_rj,
    carlson_rj,
    complete_pi,
    elliptic_f,
    elliptic_pi,
    jacobi_sncndn,
)

mp.mp.dps = 30


@pytest.mark.parametrize("mc", [1.0, 0.7, 0.3, 1e-3, 1e-8, 1e-12, 1e-15, 0.0])
def test_sncndn_against_mpmath_relative_in_cn_dn(mc):
    m_exact = 1 - mp.mpf(mc)
    us = [0.0, 0.1, -1.3, 5.0, 17.0, 33.3, -48.0, 90.0]
    sn, cn, dn = jacobi_sncndn(us, float(m_exact), mc)
    for i, u in enumerate(us):
        ref = [mp.ellipfun(k, mp.mpf(u), m=m_exact) for k in ("sn", "cn", "dn")]
        # absolute accuracy ~ eps * |u| (the argument itself carries that error)
        tol = 4e-16 * (1.0 + abs(u))
        assert abs(sn[i] - float(ref[0])) < tol
        assert abs(cn[i] - float(ref[1])) < tol
        assert abs(dn[i] - float(ref[2])) < tol
        # dn is formed from positive terms: relative accuracy even when tiny
        assert abs(dn[i] / float(ref[2]) - 1.0) < 1e-14 * (1.0 + abs(u))


def test_sncndn_keeps_relative_accuracy_at_near_separatrix_turning_point():
    # u close to K with m = 1 - 1e-12: cn and dn are ~1e-6, both must be relatively exact.
    mc = 1e-12
    m_exact = 1 - mp.mpf(mc)
    K = mp.ellipk(m_exact)
    for offset in [0.0, 0.5, -2.0, 4.0]:
        u = float(K + offset)
        sn, cn, dn = jacobi_sncndn([u], float(m_exact), mc)
        ref_cn = mp.ellipfun("cn", mp.mpf(u), m=m_exact)
        ref_dn = mp.ellipfun("dn", mp.mpf(u), m=m_exact)
        assert abs(dn[0] / float(ref_dn) - 1.0) < 1e-13
        if abs(ref_cn) > 1e-8:
            assert abs(cn[0] / float(ref_cn) - 1.0) < 1e-13


def test_carlson_integrals_against_mpmath():
    rng = np.random.default_rng(11)
    for _ in range(60):
        scale = rng.choice([1e-12, 1e-6, 1.0, 10.0])
        x, y = rng.random(2) * scale
        z = rng.random() * 3 + 0.01
        p = rng.random() * 40 + 0.01
        rf_ref = mp.elliprf(x, y, z)
        rj_ref = mp.elliprj(x, y, z, p)
        assert abs(carlson_rf(x, y, z) / rf_ref - 1) < 1e-15
        assert abs(carlson_rj(x, y, z, p) / rj_ref - 1) < 2e-15
        rf, rj = carlson_rf_rj(x, y, z, p)
        assert abs(rf / rf_ref - 1) < 1e-15
        assert abs(rj / rj_ref - 1) < 2e-15
        assert abs(carlson_rc(x + 1e-3, p) / mp.elliprc(x + 1e-3, p) - 1) < 2e-15
    for x, y in [(1.0, 1.0004), (1.0, 0.9996), (2.0, 1e-9), (1e-9, 5.0)]:  # series / log / atan
        assert abs(carlson_rc(x, y) / mp.elliprc(x, y) - 1) < 2e-15


def _pi_condition(n, phi, m_exact):
    """Cancellation factor of Pi = F + n/3 s^3 R_J (DLMF 19.25.14) for n < 0:
    (F + |n| J) / Pi with J = int sin^2 / ((1 - n sin^2) Delta)."""
    f = mp.ellipf(phi, m_exact)
    pi = mp.ellippi(n, phi, m_exact)
    return float((abs(f) + abs(f - pi)) / abs(pi))


@pytest.mark.parametrize("mc", [0.5, 1e-6, 1e-12])
@pytest.mark.parametrize("n", [0.0, -0.5, -30.0])
def test_legendre_integrals_any_amplitude(mc, n):
    m_exact = 1 - mp.mpf(mc)
    cond = _pi_condition(n, mp.pi / 2, m_exact)
    assert abs(complete_pi(n, mc) / mp.ellippi(n, m_exact) - 1) < 1e-15 * cond
    pi_c = complete_pi(n, mc)
    for phi in [0.3, 1.5, 2.9, 7.0, -4.0, 31.0]:
        ref_pi = mp.ellippi(n, mp.mpf(phi), m_exact)
        ref_f = mp.ellipf(mp.mpf(phi), m_exact)
        cond = _pi_condition(n, mp.mpf(phi), m_exact)
        assert abs(elliptic_pi(phi, n, mc, pi_c) / ref_pi - 1) < 2e-15 * cond
        assert abs(elliptic_f(phi, mc) / ref_f - 1) < 2e-15
