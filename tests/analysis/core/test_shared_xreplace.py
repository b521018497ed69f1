"""``shared_xreplace`` gives sympy's ``xreplace``: the same expression, shared sub-trees rebuilt once."""

from __future__ import annotations

import random

import sympy

from dirac.analysis.core.algebra import shared_xreplace

x, y, m, g = sympy.symbols("x y m g")


def test_the_same_expression_as_xreplace():
    rnd = random.Random(7)
    pieces = [x, y, x * y, x + y, 1 / m, 1 / (m + g), g / (m - 1) ** 2, sympy.sin(x / m), sympy.sqrt(m + x), 1 / x]
    replaced = 0
    for _ in range(300):
        shared = sympy.Add(*rnd.sample(pieces, 3)) * rnd.choice(pieces)
        expr = sympy.Add(*[rnd.choice(pieces) * shared ** rnd.randint(1, 3) + rnd.choice(pieces) for _ in range(rnd.randint(1, 4))])
        rule = {rnd.choice(pieces): sympy.Symbol("r"), 1 / m: sympy.Symbol("d0"), m + g: 2 * g}
        expected = expr.xreplace(rule)
        assert shared_xreplace(expr, rule) == expected
        replaced += expected != expr
    assert replaced > 250
    assert shared_xreplace(x + y, {}) == x + y


def test_classes_with_their_own_xreplace_keep_it():
    # Derivative and Subs rebuild their variables themselves (sympy's own _xreplace)
    f = sympy.Function("f")
    for expr in (sympy.Derivative(f(x), x) * (1 / m) + 1 / m, sympy.Subs(f(x) / m, x, y) + x / m):
        rule = {1 / m: sympy.Symbol("d0")}
        assert shared_xreplace(expr, rule) == expr.xreplace(rule)
