"""The high-precision reference of the stress suite against the standard test case's 40-digit values.

The Taylor reference (:func:`dirac.bench.taylor_reference.taylor_reference`) judges every method on
the hard bodies, so it is itself checked against values computed elsewhere: the energy,
the period of ``M`` and ``M(10)`` of the standard body, to 40 digits (docs/conventions.md).
"""

from __future__ import annotations

from fractions import Fraction

import mpmath
import numpy as np

from dirac.bench.taylor_reference import taylor_reference

INERTIA = (Fraction(2), Fraction(1), Fraction(2, 3))  # exact: 2/3 is not a float here
M10 = np.array([0.40706613658804081, 0.28300742681284408, 0.86844916766156164])  # docs/conventions.md
PERIOD = 10.73146523488280383381  # docs/conventions.md


def _exact_initial_momentum() -> list[Fraction]:
    """``M(0) = (cos 1.1, 0, sin 1.1)`` to 60 digits (not rounded to doubles)."""
    with mpmath.workdps(60):
        x = mpmath.mpf(11) / 10
        return [_fraction(mpmath.cos(x)), Fraction(0), _fraction(mpmath.sin(x))]


def _fraction(value: mpmath.mpf) -> Fraction:
    """The exact binary value of an mpf as a fraction."""
    sign, mantissa, exponent, _ = value._mpf_
    magnitude = Fraction(int(mantissa)) * Fraction(2) ** int(exponent)
    return -magnitude if sign else magnitude


def test_reference_reproduces_the_40_digit_momentum_at_t_10():
    M, R = taylor_reference(INERTIA, _exact_initial_momentum(), None, [10.0], with_R=False)
    assert R is None
    # the printed values carry 17 digits; one rounding to double adds half an ulp
    assert np.max(np.abs(M[0] - M10)) <= 1.2e-16


def test_reference_returns_to_the_start_after_one_period_and_keeps_the_attitude_orthogonal():
    M0 = _exact_initial_momentum()
    M, R = taylor_reference(INERTIA, M0, None, [PERIOD / 2, PERIOD], with_R=True)
    start = np.array([float(c) for c in M0])
    assert np.max(np.abs(M[1] - start)) <= 1e-15
    assert np.max(np.abs(M[0] - start)) > 0.1  # half a period away it is elsewhere
    for rotation in R:
        assert np.max(np.abs(rotation.T @ rotation - np.eye(3))) <= 1e-15
    # m = R M is conserved (docs/conventions.md)
    assert np.max(np.abs(R[1] @ M[1] - start)) <= 1e-15
