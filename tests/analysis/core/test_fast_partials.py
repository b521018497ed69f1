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


def _long_sum(seed: int) -> tuple[sympy.Expr, tuple[sympy.Symbol, ...]]:
    """A sum of 120 squares of local differences with parameter coefficients (a lattice energy)."""
    import random

    rng = random.Random(seed)
    xs = sympy.symbols("z0:40", real=True)
    terms = []
    for _ in range(120):
        a, b = rng.sample(xs, 2)
        terms.append(rng.choice([1, -3, g, g / m, sympy.Rational(1, 3), sympy.sqrt(g)]) * (a - b + rng.choice([0, 1, k])) ** 2)
    return sympy.Add(*terms), xs


def test_partials_of_a_long_sum_term_by_term_equal_sympy_diff():
    expr, xs = _long_sum(1)
    found = PolynomialPartials(xs, (m, g, k)).partials(expr, xs)
    assert set(found) == {s for s in xs if expr.has(s)}
    for s, d in found.items():
        assert sympy.expand(d - sympy.diff(expr, s)) == 0
        assert d == sympy.expand(sympy.diff(expr, s))  # expanded, as for a short expression


def test_tidy_of_a_long_sum_term_by_term_is_the_whole_expansion():
    from dirac.analysis.core import algebra

    expr, xs = _long_sum(2)
    by_term = algebra.tidy(expr, xs, sign=True)
    assert sympy.expand(by_term - expr) == 0 or sympy.expand(by_term + expr) == 0
    saved = algebra.PIECEWISE_TERMS
    try:
        algebra.PIECEWISE_TERMS = 10**9  # the whole sum in one ring of all its generators
        assert algebra.tidy(expr, xs, sign=True) == by_term
    finally:
        algebra.PIECEWISE_TERMS = saved


def test_hessian_of_a_long_lattice_lagrangian_is_sparse_and_equals_sympy_hessian():
    # L = sum_i (v_i - (c_{i+1} - c_i))^2 / 2 - g/2 sum_i (c_{i+1} - c_i)^2 on a ring of 70 sites
    n = 70
    c = sympy.symbols(f"c0:{n}", real=True)
    v = sympy.symbols(f"v0:{n}", real=True)
    L = sympy.Add(*[(v[i] - (c[(i + 1) % n] - c[i])) ** 2 for i in range(n)]) / 2 - g / 2 * sympy.Add(
        *[(c[(i + 1) % n] - c[i]) ** 2 for i in range(n)]
    )
    W, a, V = quadratic_parts(L, c, v, (g,))
    assert isinstance(W, sympy.SparseMatrix) and W.shape == (n, n)
    assert W == sympy.eye(n)
    assert all(sympy.expand(a[i] + (c[(i + 1) % n] - c[i])) == 0 for i in range(n))
    assert sympy.expand(V + L.subs({vi: 0 for vi in v})) == 0


def test_canonical_expr_is_the_expression_sympy_builds():
    """The fast conversion gives sympy's own ``as_expr`` (same arguments, same order), also for constants and signs."""
    import random

    from sympy.polys.rings import PolyRing

    from dirac.analysis.core.fast_partials import canonical_expr

    x, y, m = sympy.symbols("x y m")
    ring = PolyRing([x, y, m, sympy.Dummy("a0")], sympy.QQ)
    rnd = random.Random(7)
    for _ in range(300):
        p = ring.zero
        for _ in range(rnd.randint(0, 6)):
            monomial = ring.one
            for gen in ring.gens:
                monomial *= gen ** rnd.choice([0, 0, 1, 2, 3])
            p += sympy.QQ(rnd.randint(-5, 5), rnd.randint(1, 4)) * monomial
        assert sympy.srepr(canonical_expr(p)) == sympy.srepr(p.as_expr())
