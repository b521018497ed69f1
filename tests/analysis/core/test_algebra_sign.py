"""The sign chosen for a constraint by ``tidy(..., sign=True)`` is sympy's ``could_extract_minus_sign``.

The shortcut reads sympy's tie-break (``expr.sort_key() < (-expr).sort_key()``, taken
when a sum has as many negative as positive terms) off the first ordered term; checked
against sympy's own answer on sums with parameters in the coefficients, tied and untied.
"""

from __future__ import annotations

import random

import sympy

from dirac.analysis.core.algebra import _minus_sign_first, tidy

x, y, z, m, g = sympy.symbols("x y z m g")


def test_sign_choice_equals_could_extract_minus_sign():
    rnd = random.Random(11)
    tied = 0
    for _ in range(1500):
        terms = [
            sympy.Rational(rnd.choice([-3, -2, -1, 1, 2, 3]), rnd.randint(1, 3))
            * rnd.choice([1, m, 1 / m, g / m, sympy.sqrt(g), m + g])
            * x ** rnd.randint(0, 2) * y ** rnd.randint(0, 2) * z ** rnd.randint(0, 1)
            for _ in range(rnd.randint(1, 6))
        ]
        e = sympy.Add(*terms)
        if e.is_Add:
            tied += sum(a.could_extract_minus_sign() for a in e.args) * 2 == len(e.args)
        assert _minus_sign_first(e) == e.could_extract_minus_sign(), e
    assert tied > 100  # the tie-break itself was exercised


def test_tidy_with_sign_makes_the_leading_term_positive_on_a_tie():
    # x - y and y - x: one negative and one positive term; sympy prefers x - y
    assert tidy(y - x, [x, y], sign=True) == x - y
    assert tidy(x - y, [x, y], sign=True) == x - y


def test_negated_is_sympy_negation():
    from dirac.analysis.core.algebra import negated

    rnd = random.Random(5)
    for _ in range(800):
        e = sympy.Add(*[
            sympy.Rational(rnd.randint(-4, 4), rnd.randint(1, 3))
            * rnd.choice([1, m, 1 / m, g / m, sympy.sqrt(g), sympy.Float(1.5), m + g])
            * x ** rnd.randint(0, 2) * y ** rnd.randint(0, 2) * z ** rnd.randint(0, 1)
            for _ in range(rnd.randint(1, 6))
        ])
        assert sympy.srepr(negated(e)) == sympy.srepr(-e)


def test_the_sign_of_a_term_is_sympys():
    from dirac.analysis.core.algebra import _negative_term

    rnd = random.Random(5)
    special = [sympy.oo, -sympy.oo, sympy.zoo, sympy.nan, sympy.Float(-2.5), sympy.Float(0.5), sympy.S.NegativeOne]
    terms = [-x, x, -x * y, 2 * x, -sympy.Rational(1, 3) * x * y**2, -(m + g) * x, (m - g) * x, sympy.sqrt(2) * x,
             -sympy.sqrt(2) * x, -x / m, sympy.I * x, -sympy.I * x, -sympy.sin(x), x**2, sympy.Integer(-3), *[s * x for s in special], *special]
    for _ in range(500):
        terms.append(sympy.Mul(
            rnd.choice([-3, -1, 1, 2, sympy.Rational(-1, 2), sympy.Float(-0.25), sympy.sqrt(3), -sympy.sqrt(3)]),
            rnd.choice([1, m, 1 / m, g - m, sympy.sin(y)]), x ** rnd.randint(0, 2), z ** rnd.randint(0, 1),
        ))
    for t in terms:
        assert _negative_term(t) == bool(t.could_extract_minus_sign()), t
