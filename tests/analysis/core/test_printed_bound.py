"""The printed-length bound of :func:`dirac.analysis.core.algebra.printed_at_most` against sympy's printer.

The bound must never be below ``len(str(expr))`` nor below the length printed with the
terms in stored order (``sympy.sstr(expr, order="none")``): :func:`~dirac.analysis.core.algebra.prints_shorter`
answers ``True`` from it without printing, and the report picks its ordering from it.
Checked on random trees of sums, products and powers with the cases the printer treats
apart: negative and fractional coefficients, powers ``-1``, ``-2``, ``1/2``, ``-1/2``, ``1/3``,
negative bases, sums inside products and powers (the analysis' expressions have rational coefficients).
"""

import random

import sympy

from dirac.analysis.core.algebra import printed_at_most, prints_shorter

SYMBOLS = sympy.symbols("x y_long p_R_11 lambda_3 I_1")
NUMBERS = [sympy.Integer(2), sympy.Integer(-1), sympy.Integer(-3), sympy.Rational(1, 2), sympy.Rational(-3, 7)]
EXPONENTS = [2, 3, -1, -2, sympy.Rational(1, 2), sympy.Rational(-1, 2), sympy.Rational(1, 3), sympy.Rational(-2, 3)]


def _tree(rng: random.Random, depth: int) -> sympy.Expr:
    if depth == 0 or rng.random() < 0.25:
        return rng.choice(SYMBOLS) if rng.random() < 0.8 else rng.choice(NUMBERS)
    kind = rng.random()
    if kind < 0.4:
        return sympy.Add(*[_tree(rng, depth - 1) for _ in range(rng.randint(2, 4))])
    if kind < 0.8:
        factors = [_tree(rng, depth - 1) for _ in range(rng.randint(2, 4))]
        if rng.random() < 0.5:
            factors.append(rng.choice(NUMBERS))
        return sympy.Mul(*factors)
    return sympy.Pow(_tree(rng, depth - 1), rng.choice(EXPONENTS))


def test_the_bound_is_never_below_the_printed_length():
    """2000 random trees: bound >= both printed lengths (a bound of None is allowed only for other nodes)."""
    rng = random.Random(20261128)
    checked = 0
    for _ in range(2000):
        expr = _tree(rng, rng.randint(1, 5))
        bound = printed_at_most(expr, 10**9)
        if bound is None:
            assert expr.atoms(sympy.Function) or any(not (a.is_Symbol or a.is_Number) for a in expr.atoms())
            continue
        assert bound >= len(str(expr)), expr
        assert bound >= len(sympy.sstr(expr, order="none")), expr
        checked += 1
    assert checked > 1500


def test_prints_shorter_agrees_with_the_printer():
    """``prints_shorter`` is exactly ``len(str(expr)) < limit``, for limits around the printed length."""
    rng = random.Random(7)
    for _ in range(300):
        expr = _tree(rng, rng.randint(1, 4))
        n = len(str(expr))
        for limit in (n - 1, n, n + 1, 2 * n):
            assert prints_shorter(expr, limit) == (n < limit)
