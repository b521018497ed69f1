"""The three backends of dirac.codegen agree on random expressions at random points."""

from __future__ import annotations

import numpy as np
import sympy
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from dirac.codegen import GeneratedFunction, array_function, generate_module, scalar_function
from dirac.flows.constrained_kernels import call

x, y, z = SYMBOLS = sympy.symbols("x y z", real=True)

#: leaves: the symbols and small rationals
leaves = st.one_of(
    st.sampled_from(SYMBOLS),
    st.builds(sympy.Rational, st.integers(-5, 5), st.integers(1, 4)),
)


def _positive(e: sympy.Expr) -> sympy.Expr:
    """An expression of the same size that stays >= 1 (safe to divide by, to take roots of)."""
    return 1 + e**2


def _grow(children: st.SearchStrategy) -> st.SearchStrategy:
    two = st.tuples(children, children)
    return st.one_of(
        st.builds(lambda p: p[0] + p[1], two),
        st.builds(lambda p: p[0] * p[1], two),
        st.builds(lambda p: p[0] - p[1], two),
        st.builds(lambda e, k: e**k, children, st.integers(1, 5)),
        st.builds(lambda e, k: _positive(e) ** -k, children, st.integers(1, 5)),
        st.builds(lambda e: sympy.sqrt(_positive(e)), children),
        st.builds(lambda e: _positive(e) ** sympy.Rational(1, 3), children),
        st.builds(sympy.sin, children),
        st.builds(sympy.cos, children),
        st.builds(lambda e: sympy.exp(sympy.sin(e)), children),
        st.builds(lambda e: sympy.log(_positive(e)), children),
        st.builds(lambda p: sympy.atan2(p[0], _positive(p[1])), two),
    )


expressions = st.recursive(leaves, _grow, max_leaves=12)


@settings(max_examples=12, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(exprs=st.lists(expressions, min_size=1, max_size=6), points=st.lists(
    st.tuples(*[st.floats(-1.5, 1.5, allow_nan=False) for _ in SYMBOLS]), min_size=1, max_size=4))
def test_numba_numpy_and_scalar_backends_agree(exprs, points):
    module = generate_module([GeneratedFunction("f", tuple(SYMBOLS), exprs, "random expressions")])
    numpy_f = array_function(SYMBOLS, exprs)
    scalar_f = scalar_function(SYMBOLS, exprs)
    for point in points:
        compiled = call(module.f, np.array(point), np.zeros(0), len(exprs))
        array = numpy_f(*point)
        scalar = np.array(scalar_f(*point), dtype=float)
        scale = np.maximum(1.0, np.abs(array))
        assert np.all(np.abs(compiled - array) <= 1e-9 * scale), (exprs, point, compiled, array)
        assert np.all(np.abs(scalar - array) <= 1e-9 * scale), (exprs, point, scalar, array)
