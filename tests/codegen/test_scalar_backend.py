"""The scalar backend: plain-Python functions of floats, NaN outside the domain."""

from __future__ import annotations

import math

import pytest
import sympy

from dirac.codegen import UnsupportedExpression, scalar_function

x, y = sympy.symbols("x y", real=True)


def test_values_by_hand():
    f = scalar_function((x, y), [x**2 * y, sympy.sqrt(x) / y, sympy.Rational(1, 4) + sympy.cos(sympy.pi * x), y])
    assert f(4.0, 0.5) == [8.0, 4.0, 1.25, 0.5]


def test_argument_order_is_the_given_order():
    f = scalar_function((y, x), [x - y])
    assert f(1.0, 3.0) == [2.0]


def test_every_value_is_nan_outside_the_domain():
    f = scalar_function((x, y), [x + y, sympy.sqrt(x), 1 / y])
    assert all(math.isnan(v) for v in f(-1.0, 2.0))
    assert all(math.isnan(v) for v in f(1.0, 0.0))


def test_constant_outputs_and_no_outputs():
    assert scalar_function((x,), [sympy.Integer(3), sympy.pi])(0.0) == [3.0, math.pi]
    assert scalar_function((x,), [])(0.0) == []


def test_unsupported_nodes_raise_a_type_error():
    with pytest.raises(UnsupportedExpression):
        scalar_function((x,), [sympy.Piecewise((x, x > 0), (0, True))])
    assert issubclass(UnsupportedExpression, TypeError)
