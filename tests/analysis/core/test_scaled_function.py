"""Values and term sizes from one compiled function (dirac.analysis.core.scaled_function).

The expected numbers are computed by hand from the expressions below (a sum's terms are
its arguments, each taken in absolute value, added after 1 in their order).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy

from dirac.analysis.core.numeric import Numerics
from dirac.analysis.core.phase_space import PhaseSpace
from dirac.analysis.core.scaled_function import BOTH, scaled_function, terms_of

x, y, a = sympy.symbols("x y a")


def test_values_and_sizes_by_hand() -> None:
    """f = x*y - 3 + sin(x), g = x**2 at (x, y) = (2, 0.5): values and 1 + sum |term| as derived by hand."""
    f = x * y - 3 + sympy.sin(x)
    g = x**2
    fn = scaled_function([x, y], [f, g])
    assert fn(False, 2.0, 0.5) == [2.0 * 0.5 - 3 + math.sin(2.0), 4.0]
    sizes = fn(True, 2.0, 0.5)
    expected_f = 1.0
    for term in terms_of(f):  # the order of sympy's arguments, as Numerics sums them
        expected_f += {x * y: 1.0, sympy.Integer(-3): 3.0, sympy.sin(x): math.sin(2.0)}[term]
    assert sizes == [expected_f, 1.0 + 4.0]


def test_sizes_of_a_cancelling_sum() -> None:
    """x - y at x = y = 1: value 0, size 1 + |x| + |-y| = 3 (the terms' sizes stay where the value cancels)."""
    fn = scaled_function([x, y], [x - y])
    assert fn(False, 1.0, 1.0) == [0.0]
    assert fn(True, 1.0, 1.0) == [3.0]


def test_domain_error_gives_nan() -> None:
    """log(x) at x = -1 is outside the domain: every value and size is NaN."""
    fn = scaled_function([x], [sympy.log(x) + 1])
    assert all(math.isnan(v) for v in fn(False, -1.0))
    assert all(math.isnan(v) for v in fn(True, -1.0))


def test_a_pole_of_one_expression_leaves_the_others_of_its_batch_defined() -> None:
    """A batch of x*y + 1, 1/(x - y) and y**2 at x = y = 2: the second divides by zero, the others
    are 5 and 4 with sizes 1 + 4 + 1 = 6 and 1 + 4 = 5 (by hand). The shared body stops at the
    division; the values of the others must not be lost with it (a consistency matrix of the
    rigid body in matrix coordinates read NaN in polynomial rows on det R = 0)."""
    fn = scaled_function([x, y], [x * y + 1, 1 / (x - y), y**2])
    values = fn(False, 2.0, 2.0)
    assert values[0] == 5.0 and math.isnan(values[1]) and values[2] == 4.0
    sizes = fn(True, 2.0, 2.0)
    assert sizes[0] == 6.0 and math.isnan(sizes[1]) and sizes[2] == 5.0
    both = fn(2, 2.0, 2.0)
    assert both[0][0] == 5.0 and both[1][2] == 5.0 and math.isnan(both[0][1])
    assert fn(False, 3.0, 2.0) == [7.0, 1.0, 4.0]  # off the pole: the shared body, as before


def test_term_scale_of_numerics_by_hand() -> None:
    """Numerics.term_scale of a*x + y - 2 (parameter a = 3) at x = 1, y = -4: 1 + 3 + 4 + 2 = 10."""
    space = PhaseSpace((x,), (y,), (a,))
    numerics = Numerics(space, {a: 3.0})
    expr = a * x + y - 2
    z = np.array([1.0, -4.0])
    assert numerics.evaluate([expr], [z])[0, 0] == 3.0 - 4.0 - 2.0
    assert numerics.term_scale([expr, sympy.S.Zero, sympy.Integer(5)], [z]).tolist() == [[10.0, 1.0, 6.0]]


def test_term_scale_before_and_after_compilation_agree() -> None:
    """The sizes of expressions not compiled yet (compiled by term_scale) and of compiled ones are the hand sums."""
    space = PhaseSpace((x,), (y,))
    numerics = Numerics(space, {})
    exprs = [x * y + x**2 - y, x - 7]
    z = np.array([2.0, -3.0])
    hand = [[1.0 + 6.0 + 4.0 + 3.0, 1.0 + 2.0 + 7.0]]
    assert numerics.term_scale(exprs, [z]).tolist() == hand  # compiled here
    assert numerics.term_scale(exprs, [z]).tolist() == hand  # from the compiled function


def test_both_from_one_pass_by_hand() -> None:
    """flag BOTH: (values, sizes) of x*y - 3, x**2 at (2, 0.5): (-2, 4) and (1 + 1 + 3, 1 + 4) by hand; NaN pairs off the domain."""
    fn = scaled_function([x, y], [x * y - 3, x**2])
    assert fn(BOTH, 2.0, 0.5) == ([-2.0, 4.0], [5.0, 5.0])
    values, sizes = scaled_function([x], [sympy.log(x) + 1])(BOTH, -1.0)
    assert math.isnan(values[0]) and math.isnan(sizes[0])


def test_values_after_sizes_at_the_same_point_and_at_another() -> None:
    """Numerics: sizes then values at a point, then values at another point and with another parameter value, by hand.

    f = a*x - y with a = 2: at (1, 3) the value -1 (size 1 + 2 + 3 = 6); at (1, -0.0) the
    value 2; with a = 5 at (1, 3) the value 2 (values kept with the sizes belong to their
    point and parameters only).
    """
    space = PhaseSpace((x,), (y,), (a,))
    numerics = Numerics(space, {a: 2.0})
    f = a * x - y
    z = np.array([1.0, 3.0])
    assert numerics.term_scale([f], [z]).tolist() == [[6.0]]
    assert numerics.evaluate([f], [z]).tolist() == [[-1.0]]
    assert numerics.evaluate([f], [np.array([1.0, -0.0])]).tolist() == [[2.0]]
    numerics.parameter_vector = np.array([5.0])
    assert numerics.evaluate([f], [z]).tolist() == [[2.0]]


def test_a_sum_of_thousands_of_terms_compiles_with_its_sizes():
    """``dirac analyze`` used to stop with a traceback on a sum of about 3,000 terms (a RecursionError of
    Python's compiler on one line of ``a + b + ...``): 3,500 distinct monomials of 20 variables compile; the
    value is the sum of the terms (to rounding) and the size ``1 + sum |t_i|`` (by hand, term by term)."""
    import itertools
    import math
    import random

    xs = sympy.symbols("x0:20", real=True)
    monomials = list(itertools.combinations(range(20), 3))  # 1,140 distinct
    terms = [sympy.Rational(k % 13 + 1, 7) * sympy.Mul(*[xs[i] ** (1 + k // len(monomials) if j == 0 else 1)
                                                       for j, i in enumerate(m)])
             for k, m in enumerate(itertools.islice(itertools.cycle(monomials), 3500))]
    expression = sympy.Add(*terms)
    assert len(expression.args) == 3500
    f = scaled_function(list(xs), [expression])
    rng = random.Random(3)
    point = [rng.uniform(-1.5, 1.5) for _ in xs]
    values, sizes = f(BOTH, *point)
    by_term = [float(t.subs(dict(zip(xs, point)))) for t in expression.args]
    assert values[0] == pytest.approx(math.fsum(by_term), rel=1e-12, abs=1e-12 * math.fsum(map(abs, by_term)))
    assert sizes[0] == pytest.approx(1.0 + math.fsum(map(abs, by_term)), rel=1e-13)
