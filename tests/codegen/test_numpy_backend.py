"""The numpy backend: array evaluation with broadcasting, the values lambdify gave."""

from __future__ import annotations

import numpy as np
import pytest
import sympy

from dirac.codegen import array_function, numpy_function

x, y, a = sympy.symbols("x y a", real=True)


def test_values_by_hand_and_the_matrix_shape():
    f = array_function((x, y), sympy.Matrix([[x * y, 2], [sympy.sqrt(x), y**2]]))
    assert np.array_equal(f(4.0, 3.0), [[12.0, 2.0], [2.0, 9.0]])


def test_arguments_broadcast_and_constants_follow():
    f = array_function((x, y), [x + y, sympy.Integer(1)])
    values = f(np.array([1.0, 2.0, 3.0]), 10.0)
    assert values.shape == (2, 3)
    assert np.array_equal(values, [[11.0, 12.0, 13.0], [1.0, 1.0, 1.0]])


def test_grouped_arguments_are_unpacked_in_order():
    f = array_function([[x, y], a], [x - y + 10 * a])
    assert np.array_equal(f([5.0, 2.0], 1.0), [13.0])
    with pytest.raises(ValueError, match="2 values"):
        f([5.0], 1.0)


def test_outside_the_domain_gives_nan_not_an_exception():
    f = array_function((x,), [sympy.sqrt(x), sympy.log(x)])
    with np.errstate(all="ignore"):
        values = f(-1.0)
    assert np.all(np.isnan(values))


@pytest.mark.parametrize("cse", [True, False])
def test_values_are_bit_for_bit_those_of_lambdify(cse):
    rng = np.random.default_rng(3)
    R = sympy.Matrix(3, 3, lambda i, j: sympy.Symbol(f"R_{i + 1}{j + 1}", real=True))
    expressions = sympy.Matrix(R.adjugate() * R.T).applyfunc(sympy.expand) / R.det()
    ours = array_function(list(R), expressions, cse=cse)
    theirs = sympy.lambdify(list(R), expressions, "numpy", cse=cse)
    for _ in range(5):
        point = rng.normal(size=9)
        assert np.array_equal(ours(*point), np.asarray(theirs(*point), dtype=float))


def test_numpy_function_takes_the_numba_calling_order():
    f = numpy_function((x, y), [x * a + y], (a,), [2.0])
    assert np.array_equal(f(np.array([3.0, 1.0])), [7.0])
    g = numpy_function((x, y), sympy.Matrix([[x, y]]), (a,), {"a": 1.0})
    assert g(np.array([1.0, 2.0])).shape == (1, 2)
