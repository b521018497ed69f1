"""The numba backend: generated cfuncs, cached on disk by the hash of their source."""

from __future__ import annotations

import numpy as np
import pytest
import sympy

from dirac.codegen import GeneratedFunction, cache_directory, generate_module, numpy_function
from dirac.flows.constrained_kernels import call, evaluate, quiet

x, y, a = sympy.symbols("x y a", real=True)


def test_numba_and_numpy_backends_agree():
    expressions = sympy.Matrix([[sympy.sin(x) * y**2 + a, sympy.sqrt(x**2 + y**2)],
                                [sympy.exp(-x * y) / (1 + a), x**-3 + sympy.Rational(1, 3) * y**5]])
    module = generate_module([GeneratedFunction("f", (x, y), expressions, "test")], (a,))
    point = np.array([0.7, -1.3])
    out = np.empty(4)
    with quiet():
        evaluate(module.f, point, np.array([2.5]), out)
    reference = numpy_function((x, y), expressions, (a,), [2.5])(point)
    exact = np.array(expressions.subs({x: 0.7, y: -1.3, a: 2.5}).evalf(30), dtype=float)
    assert np.allclose(out.reshape(2, 2), reference, rtol=1e-14, atol=0)
    assert np.allclose(out.reshape(2, 2), exact, rtol=1e-14, atol=0)


def test_values_by_hand_arguments_then_parameters():
    module = generate_module([
        GeneratedFunction("f", (x, y), [x * y + a, x - y, sympy.Integer(7)], "x*y + a, x - y, 7"),
        GeneratedFunction("nothing", (x,), [], "no outputs"),
    ], (a,))
    assert np.array_equal(call(module.f, np.array([3.0, 2.0]), np.array([0.5]), 3), [6.5, 1.0, 7.0])
    call(module.nothing, np.array([1.0]), np.array([0.5]), 0)


def test_the_same_source_is_generated_once_into_the_cache():
    functions = [GeneratedFunction("g", (x,), [x**2], "x squared")]
    first = generate_module(functions, title="cache test")
    assert generate_module(functions, title="cache test") is first
    path = cache_directory() / f"{first.__name__}.py"
    assert path.exists() and "def g(x, params, out):" in path.read_text()


def test_a_symbol_that_is_neither_argument_nor_parameter_is_named():
    with pytest.raises(ValueError, match="function h: .* neither arguments nor parameters: a"):
        generate_module([GeneratedFunction("h", (x,), [x * a])])
