"""The polynomial steps of the special-value search, against hand results.

The search frees the determinant of a block with radicals of its square roots by a
resultant, ``Res_r(N(r), r**2 - X)`` (the product of ``N`` over both branches ``r = +-sqrt(X)``),
and keeps the parameter-only factors as the gcd of two such numerators. By hand:
``Res_r(r - a, r**2 - b) = a**2 - b``; with ``r/2 - a`` the same up to the factor ``1/4``,
so ``4 a**2 - b`` once the rationals are cleared.
"""

from __future__ import annotations

import sympy

from dirac.analysis.chain.special_values import _fraction, _gcd, _radical_free_numerator, _resultant

a, b, c, r = sympy.symbols("a b c r")


def _proportional(f: sympy.Expr, g: sympy.Expr) -> bool:
    ratio = sympy.cancel(f / g)
    return ratio != 0 and not ratio.free_symbols


def test_the_resultant_of_a_linear_factor_and_the_square_root_relation():
    assert _proportional(_resultant(r - a, r**2 - b, r), a**2 - b)


def test_the_resultant_clears_its_rational_coefficients():
    result = _resultant(r / 2 - a, r**2 - b, r)
    assert _proportional(result, 4 * a**2 - b)
    assert all(coefficient.is_Integer for coefficient in sympy.Poly(result, a, b).coeffs())


def test_the_resultant_with_float_coefficients_keeps_its_zeros():
    """Floats leave the field of rationals: the expression road, with the same zero set ``b = a**2 / 4``."""
    result = _resultant(r - 0.5 * a, r**2 - b, r)
    assert abs(float(result.subs({a: 3, b: sympy.Rational(9, 4)}))) < 1e-12
    assert abs(float(result.subs({a: 3, b: 1}))) > 1e-3


def test_a_fraction_in_lowest_terms():
    """``a/b + 1/a = (a**2 + b) / (a b)``; ``(a**2 - 1)/(a - 1) = a + 1``."""
    numerator, denominator = _fraction(a / b + 1 / a)
    assert sympy.expand(numerator * a * b - denominator * (a**2 + b)) == 0
    assert sympy.gcd(numerator, denominator).is_number
    assert _fraction((a**2 - 1) / (a - 1)) == (a + 1, 1)


def test_the_gcd_of_two_numerators_is_their_common_parameter_factor():
    assert _proportional(_gcd(c**4 * (a + b), c**2 * (a - b)), c**2)


def test_a_nested_radical_is_removed_from_the_inside_out():
    """``sqrt(1 + sqrt(a)) - 2`` vanishes at ``sqrt(a) = 3``, ``a = 9``: the radical-free numerator has the factor ``a - 9``."""
    numerator = _radical_free_numerator(sympy.Matrix([[sympy.sqrt(1 + sympy.sqrt(a)) - 2]]))
    assert sympy.rem(sympy.Poly(numerator, a), sympy.Poly(a - 9, a)).is_zero


def test_an_antisymmetric_block_with_a_radical_goes_through_its_pfaffian():
    """``[[0, sqrt(a) - 1], [1 - sqrt(a), 0]]``: ``Pf = sqrt(a) - 1``, free of the root: ``1 - a`` up to a factor."""
    block = sympy.Matrix([[0, sympy.sqrt(a) - 1], [1 - sympy.sqrt(a), 0]])
    assert _proportional(_radical_free_numerator(block), a - 1)
