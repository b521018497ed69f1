"""The benchmark's independent references, checked against closed forms and the standard test case (docs/conventions.md)."""

from __future__ import annotations

import math
from fractions import Fraction

import mpmath
import numpy as np
import sympy

from dirac.bench.reference import (
    _double_pendulum_angles_rhs,
    pendulum_period,
    taylor_rigid_body,
)


def _standard_exact_inputs():
    with mpmath.workdps(45):
        M0 = [mpmath.nstr(mpmath.cos(mpmath.mpf("1.1")), 42), "0", mpmath.nstr(mpmath.sin(mpmath.mpf("1.1")), 42)]
    return [Fraction(2), Fraction(1), Fraction(2, 3)], M0


def test_taylor_reference_reproduces_the_40_digit_values_of_the_standard_test_case():
    inertia, M0 = _standard_exact_inputs()
    M, R = taylor_rigid_body(inertia, M0, np.eye(3), [10.0])
    expected = np.array([0.40706613658804081, 0.28300742681284408, 0.86844916766156164])  # standard test case, docs/conventions.md
    np.testing.assert_allclose(M[0], expected, rtol=2e-16, atol=0)
    energy = 0.5 * (M[0, 0] ** 2 / 2.0 + M[0, 1] ** 2 + M[0, 2] ** 2 * 1.5)
    assert abs(energy - 0.64712527931383642713) < 2e-16
    # R stays a rotation and the lab momentum m = R M = M(0) is conserved
    assert np.max(np.abs(R[0].T @ R[0] - np.eye(3))) < 1e-15
    np.testing.assert_allclose(R[0] @ M[0], [math.cos(1.1), 0.0, math.sin(1.1)], atol=1e-15)


def test_taylor_reference_returns_after_one_period_of_M():
    inertia, M0 = _standard_exact_inputs()
    period = "10.73146523488280383381"  # standard test case, docs/conventions.md
    t = float(period)
    M, _ = taylor_rigid_body(inertia, M0, np.eye(3), [t])
    # t misses the period by delta = t - T (the double rounding of T), so
    # M(t) = M(0) + delta dM/dt(0) + O(delta^2), dM/dt = M x Omega (250)
    delta = Fraction(t) - Fraction(period)
    m = [Fraction(v) for v in M0]
    w = [m[i] / inertia[i] for i in range(3)]
    velocity = [m[1] * w[2] - m[2] * w[1], m[2] * w[0] - m[0] * w[2], m[0] * w[1] - m[1] * w[0]]
    expected = np.array([float(m[i] + delta * velocity[i]) for i in range(3)])
    # correctly rounded doubles of the same number: at most one ulp apart
    assert np.all(np.abs(M[0] - expected) <= np.maximum(np.spacing(np.abs(expected)), 1e-20))


def test_taylor_reference_matches_the_uniform_rotation_closed_form():
    # m = (0, 0, m3) on the principal axis 3: R(t) = rotation about z by w t, w = m3 / I3
    # (paper (133)-(165)), M stays (0, 0, m3)
    inertia = [2.0, 1.0, 0.5]
    m3 = 0.7
    t = 7.5
    M, R = taylor_rigid_body(inertia, [0.0, 0.0, m3], np.eye(3), [t])
    angle = m3 / 0.5 * t
    c, s = math.cos(angle), math.sin(angle)
    np.testing.assert_allclose(R[0], [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]], atol=1e-15)
    np.testing.assert_allclose(M[0], [0.0, 0.0, m3], atol=1e-17)


def test_pendulum_period_limits():
    # small amplitude: 2 pi sqrt(l/g); release from the horizontal: 4 K(1/2) sqrt(l/g)
    assert abs(pendulum_period(9.81, 1.0, 1e-8) - 2 * math.pi / math.sqrt(9.81)) < 1e-15
    K_half = 1.8540746773013719184  # complete elliptic integral K(m = 1/2), A&S table 17.1
    assert abs(pendulum_period(4.0, 1.0, math.pi / 2) - 4 * K_half / 2.0) < 1e-14


def test_double_pendulum_angle_equations_follow_from_the_lagrangian():
    a1, a2, w1, w2 = sympy.symbols("a1 a2 w1 w2")
    m1, m2, l1, l2, g = 1.3, 0.7, 0.9, 1.1, 9.81
    x1, y1 = l1 * sympy.sin(a1), -l1 * sympy.cos(a1)
    x2, y2 = x1 + l2 * sympy.sin(a2), y1 - l2 * sympy.cos(a2)
    t = sympy.Symbol("t")
    A1, A2 = sympy.Function("A1")(t), sympy.Function("A2")(t)
    subs = {a1: A1, a2: A2}
    kinetic = sum(
        m / 2 * (sympy.diff(x.subs(subs), t) ** 2 + sympy.diff(y.subs(subs), t) ** 2)
        for m, x, y in ((m1, x1, y1), (m2, x2, y2))
    )
    lagrangian = kinetic - g * (m1 * y1 + m2 * y2).subs(subs)
    equations = [
        sympy.diff(sympy.diff(lagrangian, sympy.diff(A, t)), t) - sympy.diff(lagrangian, A) for A in (A1, A2)
    ]
    acc = sympy.symbols("acc1 acc2")
    replace = {
        sympy.diff(A1, t, 2): acc[0], sympy.diff(A2, t, 2): acc[1],
        sympy.diff(A1, t): w1, sympy.diff(A2, t): w2, A1: a1, A2: a2,
    }
    # the Euler-Lagrange equations are linear in the accelerations: A acc = b
    A, b = sympy.linear_eq_to_matrix([sympy.expand(e.subs(replace)) for e in equations], acc)
    numeric = sympy.lambdify((a1, a2, w1, w2), (A, b), "numpy")
    rng = np.random.default_rng(4)
    for _ in range(5):
        point = rng.uniform(-2, 2, size=4)
        A_value, b_value = numeric(*point)
        expected = np.linalg.solve(np.array(A_value, dtype=float), np.array(b_value, dtype=float).ravel())
        got = _double_pendulum_angles_rhs(0.0, point, m1, m2, l1, l2, g)
        np.testing.assert_allclose(got[:2], point[2:], rtol=0, atol=0)
        np.testing.assert_allclose(got[2:], expected, rtol=1e-12)


def test_taylor_reference_stays_accurate_when_the_series_underflows():
    # Regression (bench separatrix case): for a steady rotation about the middle axis the
    # high Taylor coefficients fall below the fixed-point grid; the step size must stay
    # bounded. M = (0, 1, 0), I = (1, 2, 3): Omega = (0, 1/2, 0), R(t) = rotation about y
    # by t/2 (paper (133)-(165) with the axes relabelled).
    M, R = taylor_rigid_body([1.0, 2.0, 3.0], [0.0, 1.0, 0.0], np.eye(3), [100.0])
    c, s = math.cos(50.0), math.sin(50.0)
    np.testing.assert_allclose(R[0], [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]], atol=1e-15)
    np.testing.assert_allclose(M[0], [0.0, 1.0, 0.0], atol=1e-30)
