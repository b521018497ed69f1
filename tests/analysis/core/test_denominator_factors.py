"""The factors of the denominators an expression divides by, and the rational form that decides them.

A denominator is factored as a polynomial: a base with parameters in its own denominators
(``x**2/m - y**2/m``, as the Dirac bracket of a pendulum on a cart divides by) is factored
through its numerator, and a base whose reduced denominator holds the variables (the pivot
``x - y**2/x`` of an elimination) is no polynomial and is kept whole, without expanding it.
"""

from __future__ import annotations

import sympy

import dirac
from dirac.analysis.core.algebra import rational_parts
from dirac.analysis.core.divisors import constant_on_surface, denominator_factors
from dirac_systems.report_models import pendulum_on_a_cart, slider_crank

x, y, m, M = sympy.symbols("x y m M", real=True)


def test_rational_parts_is_the_reduced_fraction():
    """By hand: ``(x**2 - 1)/(x - 1) = x + 1``; ``x/2 + y/2 = (x + y)/2``; ``x - y**2/x = (x**2 - y**2)/x``;
    ``sin(x)`` is a generator of its own (``1/m - sin(x)/m = (1 - sin(x))/m``); a float or a square root
    is no rational function over the rationals."""
    assert rational_parts((x**2 - 1) / (x - 1)) == (x + 1, 1)
    assert rational_parts(x / 2 + y / 2) == (x + y, 2)
    numerator, denominator = rational_parts(x - y**2 / x)
    assert sympy.expand(numerator - (x**2 - y**2)) == 0 and denominator == x
    assert rational_parts(1 / m - sympy.sin(x) / m) == (1 - sympy.sin(x), m)
    assert rational_parts(0.5 * x + y) is None
    assert rational_parts(sympy.sqrt(x) + y) is None


def test_a_base_with_parameter_denominators_is_factored_through_its_numerator():
    """By hand: ``1/(x**2/m - y**2/m) = m/((x - y)(x + y))``: the divisors are ``x - y`` and ``x + y``
    (``m`` is a parameter, no divisor of the phase space)."""
    factors = denominator_factors(1 / (x**2 / m - y**2 / m), {x, y})
    assert set(factors) == {x - y, x + y}


def test_a_base_with_the_variables_in_its_reduced_denominator_is_kept_whole():
    """By hand: ``x - y**2/x = (x**2 - y**2)/x`` is no polynomial in ``x, y``: the divisor is the base as written."""
    base = x - y**2 / x
    assert base in denominator_factors(1 / base, {x, y})


def test_a_trigonometric_factor_is_reduced_with_pythagoras():
    """By hand: ``1/(m sin(x)**2 + m cos(x)**2 + m y**2) = 1/(m (1 + y**2))``: no divisor that can vanish;
    ``1/(sin(x)**2 + cos(x)**2 - y**2)`` divides by ``1 - y**2 = (1 - y)(1 + y)``."""
    s, c = sympy.sin(x), sympy.cos(x)
    assert denominator_factors(1 / (m * s**2 + m * c**2 + m * y**2), {x, y}) == []
    found = denominator_factors(1 / (s**2 + c**2 - y**2), {x, y})
    assert {sympy.expand(f) for f in found} <= {y - 1, y + 1, 1 - y, -y - 1} and len(found) == 2


def test_no_constant_on_the_surface_for_a_quotient_in_the_variables():
    """``x - y**2/x`` is not ``c + a (x**2 + y**2 - 1)`` for numbers ``a, c``: no identity, and none is sought."""
    assert constant_on_surface(x - y**2 / x, [x**2 + y**2 - 1], [x, y]) is None
    assert constant_on_surface(2 * x**2 + 2 * y**2 + 3, [x**2 + y**2 - 1], [x, y]) == 5


def test_the_dirac_bracket_of_a_pendulum_on_a_cart_divides_by_the_gram_determinant():
    """A cart ``X`` of mass ``M`` and a bob ``(x, y)`` of mass ``m`` on a rod ``l``: the Gram
    determinant of the rod, ``J W^-1 J^T = 4 ((X - x)^2 + y^2)/m + 4 (X - x)^2/M``, divides the
    multipliers, and ``det C`` of the four second-class constraints is ``256 G^4 / (M^4 m^4)`` with
    ``G = M (X - x)^2 + M y^2 + m (X - x)^2`` (the square of its Pfaffian ``16 G^2 / (M^2 m^2)``): its
    only divisor is ``G`` again, so the report names one divisor, not a second one too long to print."""
    text = dirac.analyze(pendulum_on_a_cart()).to_text()
    lines = [line for line in text.splitlines() if line.startswith("singular loci")]
    assert len(lines) == 1, lines
    assert "M*X**2 - 2*M*X*x + M*x**2 + M*y**2 + X**2*m - 2*X*m*x + m*x**2" in lines[0]
    assert "not printed" not in text


def test_the_report_of_a_slider_crank_names_its_divisor():
    """A crank ``th`` (inertia ``I``, radius ``r``) and a slider ``s`` (mass ``m``) on a rod ``L``:
    ``(s - r cos th)^2 + r^2 sin^2 th = L^2``. The multipliers divide by the Gram determinant
    ``J W^-1 J^T``, with ``J = (2 r s sin th, 2 (s - r cos th))`` and ``W = diag(I, m)``: ``4 (m r^2 s^2
    sin^2 th + I (s - r cos th)^2) / (I m)``, by hand. Its factor with the angle was put to ``trigsimp``,
    which did not end in five minutes; reduced with Pythagoras it is named in the report."""
    lines = [line for line in dirac.analyze(slider_crank()).to_text().splitlines() if line.startswith("singular loci")]
    assert len(lines) == 1, lines
    assert "I*r**2*cos(th)**2 - 2*I*r*s*cos(th) + I*s**2 + m*r**2*s**2*sin(th)**2" in lines[0]
