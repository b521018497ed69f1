"""Partial derivatives in the sparse ring against sympy.diff (the definition)."""

from __future__ import annotations

import sympy

from dirac.analysis.core.fast_partials import PolynomialPartials, quadratic_parts

x, y, p, q = sympy.symbols("x y p q", real=True)
m, g, k = sympy.symbols("m g k", real=True)


def test_partials_equal_sympy_diff_with_parameters_in_denominators_and_roots():
    f = (x - y) ** 2 * p / (2 * m) + sympy.sqrt(g) * x * q**3 - k * y / (m + g) + sympy.Rational(3, 7)
    found = PolynomialPartials((x, y, p, q), (m, g, k)).partials(f, (x, y, p, q))
    assert set(found) == {x, y, p, q}
    for s, d in found.items():
        assert sympy.simplify(d - sympy.diff(f, s)) == 0


def test_absent_variables_and_zero_partials_are_left_out():
    found = PolynomialPartials((x, y, p), ()).partials(x**2 + 3, (x, y, p))
    assert found == {x: 2 * x}


def test_not_a_polynomial_is_left_to_the_caller():
    parts = PolynomialPartials((x, y), (m,))
    assert parts.partials(sympy.sin(x) + y, (x, y)) is None
    assert parts.partials(y / x, (x, y)) is None
    assert parts.partials(x * sympy.Symbol("z"), (x, y)) is None  # an unknown symbol


def test_quadratic_parts_of_a_singular_lagrangian():
    # L = (x_dot - (a1 - a0))^2/2 with a0, a1 without velocities: W = diag(0, 0, 1) ...
    a0, a1, v0, v1, xd = sympy.symbols("a0 a1 a0_dot a1_dot x_dot", real=True)
    L = (xd - (a1 - a0)) ** 2 / 2 - k * x**2 / 2
    W, a, V = quadratic_parts(L, (a0, a1, x), (v0, v1, xd), (k,))
    assert W == sympy.Matrix([[0, 0, 0], [0, 0, 0], [0, 0, 1]])
    assert a[0] == 0 and a[1] == 0 and sympy.expand(a[2] + (a1 - a0)) == 0
    assert sympy.expand(V - (k * x**2 / 2 - (a1 - a0) ** 2 / 2)) == 0


def test_quadratic_parts_refuses_what_is_not_quadratic():
    xd = sympy.Symbol("x_dot", real=True)
    assert quadratic_parts(xd**4 + x, (x,), (xd,), ()) is None
    assert quadratic_parts(sympy.sqrt(1 + xd**2), (x,), (xd,), ()) is None
