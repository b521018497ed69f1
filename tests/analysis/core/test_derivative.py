"""The tree derivative of the phase space (``dirac.analysis.core.phase_space.derivative``).

It replaces ``sympy.diff`` in the gradients and Poisson brackets of the analysis, so it
must give the same expression: checked against derivatives worked out by hand and
against ``sympy.diff`` (an independent implementation) on nested products, powers,
roots, quotients and functions, and on a shared sub-tree that occurs many times.
"""

from __future__ import annotations

import sympy

from dirac.analysis.core.phase_space import PhaseSpace, derivative

x, y, z, a = sympy.symbols("x y z a", real=True)


def test_hand_derivatives() -> None:
    # d/dx x^2 y = 2 x y; d/dx sqrt(x^2 + y^2) = x / sqrt(x^2 + y^2); d/dx 1/(x y) = -1/(x^2 y)
    assert derivative(x**2 * y, x) == 2 * x * y
    assert sympy.simplify(derivative(sympy.sqrt(x**2 + y**2), x) - x / sympy.sqrt(x**2 + y**2)) == 0
    assert derivative(1 / (x * y), x) == -1 / (x**2 * y)
    # d/dy of something free of y is exactly zero; d/dx x = 1
    assert derivative(sympy.sin(x) * (x + 1) ** 3, y) == 0
    assert derivative(x, x) == 1
    # chain rule through a function: d/dx sin(x y) = y cos(x y)
    assert derivative(sympy.sin(x * y), x) == y * sympy.cos(x * y)


def test_same_expression_as_sympy_diff() -> None:
    shared = x * y - z * a + 2 * x * z
    expressions = [
        (x * (y + z * (x - a) ** 2) + a) * (shared**2 - x / (y + 1)),
        sympy.Rational(1, 2) * x * shared * (y * shared - 3) / (x**2 + a) ** 3,
        -a * sympy.sqrt(x**2 - y**2 - z**2) + x * sympy.exp(y * z),
        (shared + (shared * x + 1) * (shared * y - 1)) ** 2 - shared ** (-2),
        x**a * y,  # a symbolic exponent: the chain rule hands the power to sympy
    ]
    for expr in expressions:
        for s in (x, y, z, a):
            assert derivative(expr, s) == sympy.diff(expr, s), (expr, s)


def test_partials_and_bracket() -> None:
    q, p = sympy.symbols("q p", real=True)
    space = PhaseSpace((q,), (p,))
    # {q^2 p, p^2/2} = d(q^2 p)/dq * d(p^2/2)/dp = 2 q p * p
    assert space.poisson_bracket(q**2 * p, p**2 / 2) == 2 * q * p**2
    dq, dp = space.partials(q * (q + p) ** 2)
    # d/dq q (q + p)^2 = (q + p)^2 + 2 q (q + p); d/dp = 2 q (q + p)
    assert sympy.expand(dq[q] - (q + p) ** 2 - 2 * q * (q + p)) == 0
    assert sympy.expand(dp[q] - 2 * q * (q + p)) == 0


def test_prints_shorter_is_len_of_str() -> None:
    """``prints_shorter(e, n)`` answers ``len(str(e)) < n`` exactly (it only avoids printing)."""
    from dirac.analysis.core.algebra import prints_shorter

    shared = (x * y - z / 3) ** 2
    expressions = [
        x / 2, x * y**-1, sympy.sqrt(x) - 1, -x / 3, x ** sympy.Rational(-1, 2), 1 / (x + y) ** 2,
        sympy.Float(0.5) * x, -sympy.Rational(3, 7) * x * y / (z - 1), sympy.sin(x) * shared,
        sum((shared * (x + k)) ** k for k in range(1, 30)),
    ]
    for e in expressions:
        for limit in (3, 5, 10, 40, 100, 400, 4000):
            assert prints_shorter(e, limit) == (len(str(e)) < limit), (e, limit)
