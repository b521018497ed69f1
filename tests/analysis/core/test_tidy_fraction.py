"""``tidy`` of a product over polynomial denominators: one reduction at the end, the field's fraction.

Hand derivations:

* ``(x**2 - y**2) / (x - y) = x + y`` (the difference of squares), a polynomial again.
* ``(2 x) / (4 y) = x / (2 y)``: integer contents cancel too, the denominator keeps the
  positive leading coefficient.
* ``3 x / (2 y / 3) = 9 x / (2 y)``: a rational coefficient in the denominator moves up.
* ``(x + 1) / (-(x + 1) * y) = -1 / y``: the sign goes to the numerator.
* ``a x / ((b - a) (x**2 + y**2))`` with parameters ``a, b``: nothing cancels; the
  parameter factor ``1 / (b - a)`` stays a coefficient, as the field road gives it.

Each is also compared with the fraction-field road (``FracField``, which reduces after
every operation; its elements are the unique reduced fractions).
"""

from __future__ import annotations

import sympy
from sympy.polys.fields import FracField

from dirac.analysis.core.algebra import _reduced_product, ring_value, tidy

x, y, a, b = sympy.symbols("x y a b")


def _field_pair(expr: sympy.Expr, gens: list[sympy.Symbol]):
    field = FracField(gens, sympy.QQ)
    value = ring_value(expr, dict(zip(gens, field.gens)), field, invert=lambda base: field(1) / base)
    return value.numer, value.denom


def test_reduced_product_is_the_fields_fraction() -> None:
    from sympy.polys.rings import PolyRing

    gens = [x, y]
    ring = PolyRing(gens, sympy.QQ)
    cases = [
        (x**2 - y**2) / (x - y),
        2 * x / (4 * y),
        3 * x / (sympy.Rational(2, 3) * y),
        (x + 1) / (-(x + 1) * y),
        (x**3 + 2 * x * y) / (x**2 * (y + 1) ** 2),
    ]
    for expr in cases:
        mine = _reduced_product(expr, dict(zip(gens, ring.gens)), ring)
        assert mine is not None
        assert mine == _field_pair(expr, gens)


def test_tidy_by_hand() -> None:
    assert tidy((x**2 - y**2) / (x - y), [x, y]) == x + y
    assert tidy(2 * x / (4 * y), [x, y]) == x / (2 * y)
    assert tidy(3 * x / (sympy.Rational(2, 3) * y), [x, y]) == 9 * x / (2 * y)
    assert tidy((x + 1) / (-(x + 1) * y), [x, y]) == -1 / y
    expr = a * x / ((b - a) * (x**2 + y**2))
    out = tidy(expr, [x, y])
    assert sympy.simplify(out - expr) == 0
    assert str(out) == "a*x/((-a + b)*(x**2 + y**2))"


def test_a_sum_of_fractions_is_left_to_the_field() -> None:
    from sympy.polys.rings import PolyRing

    gens = [x, y]
    ring = PolyRing(gens, sympy.QQ)
    expr = x / y + y / x
    assert _reduced_product(expr, dict(zip(gens, ring.gens)), ring) is None
    assert tidy(expr, [x, y]) == (x**2 + y**2) / (x * y)


def test_cancelled_gives_the_pair_of_sympys_cancel():
    """``_cancelled`` returns the very pair of sympy's ``cancel`` on random fractions with common factors.

    The factors are polynomials in a few generators (those of the denominator), with
    integer and rational contents and both signs, times numerators in more generators.
    """
    import random

    from sympy.polys.rings import PolyRing

    from dirac.analysis.core.algebra import _cancelled

    rnd = random.Random(1)
    ring = PolyRing(sympy.symbols("g0:7"), sympy.QQ)

    def polynomial(terms, gens, degree=2):
        out = ring.zero
        for _ in range(terms):
            term = ring(sympy.QQ(rnd.randint(-5, 5), rnd.randint(1, 4)))
            for g in gens:
                term *= g ** rnd.randint(0, degree)
            out += term
        return out

    compared = cancelled = 0
    for _ in range(300):
        few = rnd.sample(ring.gens, rnd.randint(1, 3))
        common = (polynomial(rnd.randint(1, 3), few) or ring.one) * rnd.choice([1, 2, -3, sympy.QQ(1, 2)])
        numer = polynomial(rnd.randint(1, 6), ring.gens[: rnd.randint(2, 7)]) * common
        denom = polynomial(rnd.randint(1, 3), few) * common * rnd.choice([1, -1, 6])
        if not numer or not denom:
            continue
        expected = numer.cancel(denom)
        assert _cancelled(numer, denom) == expected, (numer, denom)
        compared += 1
        cancelled += expected[1] != denom
    assert compared > 250 and cancelled > 100  # most had a factor to cancel
    g0, g1 = ring.gens[:2]
    for numer, denom in [(g0 * g1 + 1, ring(2)), (g0 * g1 / 3 + 1, ring(sympy.QQ(-4, 3))), (2 * g0, ring.one)]:
        assert _cancelled(numer, denom) == numer.cancel(denom)  # constant denominators: contents and sign only


def _split_by_whole_walk(expr, variables):
    """The former walk of :func:`_split_denominators`: every tree node by ``sympy.preorder_traversal``."""
    replacements: dict = {}
    back: dict = {}
    for node in sympy.preorder_traversal(expr):
        if node.is_Pow and node.exp.is_Integer and node.exp < 0 and not (node.base.free_symbols & variables):
            base = node.base
            if base not in back.values():
                back[sympy.Dummy(f"d{len(back)}")] = base
            d = next(k for k, v in back.items() if v == base)
            replacements[node] = d ** int(-node.exp)
    if not replacements:
        return expr, {}, []
    return expr.xreplace(replacements), {d: 1 / v for d, v in back.items()}, list(back)


def test_denominators_are_split_as_a_walk_of_the_whole_tree_splits_them():
    import random

    from dirac.analysis.core.algebra import _split_denominators

    rnd = random.Random(3)
    m, g, k = sympy.symbols("m g k", positive=True)
    pieces = [x, y, x * y, x + y, 1 / m, 1 / (m + g), g / (k - m) ** 2, x / (m * g), (x + 1) / (k + 1), 1 / x]
    for _ in range(200):
        shared = sympy.Add(*rnd.sample(pieces, 3)) * rnd.choice(pieces)
        expr = sympy.Add(*[rnd.choice(pieces) * shared ** rnd.randint(1, 2) + rnd.choice(pieces) for _ in range(rnd.randint(1, 4))])
        new, old = _split_denominators(expr, {x, y}), _split_by_whole_walk(expr, {x, y})
        named = [{d: sympy.Symbol(f"D{i}") for i, d in enumerate(found[2])} for found in (new, old)]
        assert len(new[2]) == len(old[2])
        assert new[0].xreplace(named[0]) == old[0].xreplace(named[1])
        assert {named[0][d]: v for d, v in new[1].items()} == {named[1][d]: v for d, v in old[1].items()}
        assert [d.name for d in new[2]] == [d.name for d in old[2]]
