"""Polynomials in sines and cosines reduced with ``sin(u)^2 + cos(u)^2 = 1``, checked by hand and as functions."""

from __future__ import annotations

import numpy as np
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st

from dirac.analysis.core.pythagoras import circle_polynomial, pythagorean_form, trig_arguments

a, b, th, ps, m, M = sympy.symbols("a b th ps m M", real=True)
s, c = sympy.sin, sympy.cos


def _same_function(f: sympy.Expr, g: sympy.Expr, symbols: list[sympy.Symbol]) -> bool:
    """``f`` and ``g`` agree at random real points (the reduction must not change the function)."""
    rng = np.random.default_rng(7)
    first, second = (sympy.lambdify(symbols, e, "math") for e in (f, g))
    for _ in range(20):
        point = rng.uniform(0.5, 3.0, len(symbols)) * rng.choice([-1.0, 1.0], len(symbols))
        u, v = first(*point), second(*point)
        if abs(u - v) > 1e-9 * (1.0 + abs(u) + abs(v)):
            return False
    return True


def test_the_circle_identity_is_one():
    assert pythagorean_form(s(a) ** 2 + c(a) ** 2) == 1
    assert pythagorean_form(m * s(a) ** 2 + m * c(a) ** 2 + M) == m + M


def test_an_angle_with_only_its_cosine_is_written_with_its_sine_when_shorter():
    """By hand: ``M + m - m cos(th)^2 = M + m sin(th)^2`` (two terms, not three)."""
    reduced = circle_polynomial(M + m - m * c(th) ** 2)
    assert reduced is not None
    assert reduced.polynomial.xreplace(reduced.back) == M + m * s(th) ** 2


def test_each_angle_is_reduced_its_own_way():
    """The asymmetric top's cofactor ``I1 I2 sin(th)^2 (sin(ps)^2 + cos(ps)^2)^2 + ...``: the square of the
    circle in ``ps`` is 1 while ``th`` is best left alone: 4 terms, where reducing both angles the same
    way (all sines, or all cosines) leaves 5."""
    I1, I2, I3 = sympy.symbols("I1 I2 I3", positive=True)
    entry = (I1 * I2 * s(th) ** 2 * (s(ps) ** 2 + c(ps) ** 2) ** 2 + I1 * I3 * c(ps) ** 2 * c(th) ** 2
             + I2 * I3 * s(ps) ** 2 * c(th) ** 2)
    reduced = circle_polynomial(entry)
    assert reduced is not None
    written = reduced.polynomial.xreplace(reduced.back)
    assert len(sympy.Add.make_args(written)) == 4
    assert _same_function(written, entry, [th, ps, I1, I2, I3])
    uniform = circle_polynomial(entry, by_angle=False)
    assert uniform is not None and len(sympy.Add.make_args(uniform.polynomial)) == 5


def test_a_quotient_is_reduced_above_and_below():
    """By hand: ``(sin(a)^2 + cos(a)^2 + b)/(m cos(a)^2 + m sin(a)^2) = (1 + b)/m``."""
    assert sympy.simplify(pythagorean_form((s(a) ** 2 + c(a) ** 2 + b) / (m * c(a) ** 2 + m * s(a) ** 2)) - (1 + b) / m) == 0


def test_no_sines_or_no_polynomial_is_left_alone():
    assert circle_polynomial(a**2 + b) is None
    assert pythagorean_form(a**2 + b) == a**2 + b
    assert trig_arguments(s(a - b) * c(th)) == {a - b, th}
    assert pythagorean_form(sympy.sqrt(s(a) ** 2 + c(a) ** 2 + b)) == sympy.sqrt(s(a) ** 2 + c(a) ** 2 + b)


_ANGLES = (a, b, a - b)
_COEFFICIENTS = (1, -2, 3, m, M / 2, 1 / m)


@given(st.lists(st.tuples(st.sampled_from(_COEFFICIENTS), st.sampled_from(_ANGLES), st.integers(0, 3), st.integers(0, 3),
                          st.sampled_from(_ANGLES), st.integers(0, 2)), min_size=1, max_size=5))
@settings(max_examples=40, deadline=None)
def test_the_reduction_is_the_same_function_of_the_angles(terms):
    """Random sums of ``k sin(u)^i cos(u)^j cos(v)^l`` (parameters in coefficients, one in a denominator): the
    reduced forms, written back in sines and cosines, take the same values at random angles and masses."""
    expr = sympy.Add(*(k * s(u) ** i * c(u) ** j * c(v) ** e for k, u, i, j, v, e in terms))
    symbols = [a, b, m, M]
    for by_angle in (True, False):
        reduced = circle_polynomial(expr, by_angle=by_angle)
        if reduced is not None:
            assert _same_function(reduced.polynomial.xreplace(reduced.back), expr, symbols)
    assert _same_function(pythagorean_form(expr), expr, symbols)
    assert _same_function(pythagorean_form(expr / (s(a) ** 2 + c(a) ** 2 + m**2)), expr / (1 + m**2), symbols)
