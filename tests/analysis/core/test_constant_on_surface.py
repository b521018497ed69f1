"""Divisors that are constant on the constraint surface (:func:`dirac.analysis.core.divisors.constant_on_surface`)."""

import sympy

from dirac.analysis.core.divisors import constant_on_surface

R = sympy.symbols("R_11 R_12 R_13 R_21 R_22 R_23 R_31 R_32 R_33")
R11, R12, R13, R21, R22, R23, R31, R32, R33 = R
I1, I2, I3 = sympy.symbols("I_1:4", positive=True)
HALF = sympy.Rational(1, 2)
#: the first two columns of R of unit length and orthogonal, as Lagrangian (78) writes them
COLUMNS = [R11**2 / 2 + R21**2 / 2 + R31**2 / 2 - HALF, R11 * R12 + R21 * R22 + R31 * R32, R12**2 / 2 + R22**2 / 2 + R32**2 / 2 - HALF]


def test_a_squared_column_norm_is_one():
    """``R_11^2 + R_21^2 + R_31^2 = 1 + 2 phi_1``: the value 1 on the surface."""
    assert constant_on_surface(R11**2 + R21**2 + R31**2, COLUMNS, R) == 1


def test_a_combination_of_column_norms_with_moments():
    """By hand, with ``c_1``, ``c_2`` the squared norms of the first two columns:
    ``(I_2 + I_3 - I_1) c_1 + (I_1 - I_2 + I_3) c_2 = 2 I_3`` where both are 1."""
    c1 = R11**2 + R21**2 + R31**2
    c2 = R12**2 + R22**2 + R32**2
    divisor = sympy.expand((I2 + I3 - I1) * c1 + (I1 - I2 + I3) * c2)
    assert sympy.simplify(constant_on_surface(divisor, COLUMNS, R) - 2 * I3) == 0


def test_no_certificate_for_what_varies_on_the_surface():
    """``R_11`` takes every value in [-1, 1] on the surface, ``R_11^2`` too: neither is a constant there."""
    assert constant_on_surface(R11, COLUMNS, R) is None
    assert constant_on_surface(R11**2, COLUMNS, R) is None


def test_constraints_in_other_variables_are_not_used():
    """``x^2 + y^2`` on ``z = 1`` alone is not constant: the constraint says nothing of ``x`` and ``y``."""
    x, y, z = sympy.symbols("x y z")
    assert constant_on_surface(x**2 + y**2, [z - 1], [x, y, z]) is None
    assert constant_on_surface(z**2 + 2 * z, [z - 1], [x, y, z]) is None  # 3 on z = 1, but not a constant combination
