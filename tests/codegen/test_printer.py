"""The one printer of dirac.codegen: the code it writes for known expressions."""

from __future__ import annotations

import pytest
import sympy

from dirac.codegen import StraightLineCode, UnsupportedExpression, straight_line

x, y = sympy.symbols("x y", real=True)
INPUTS = {x: "a0", y: "a1"}


def test_kernel_code_unrolls_small_powers_and_prints_numbers_as_floats():
    code = straight_line(INPUTS, [x**2 * y**-3 + sympy.Rational(1, 3) * sympy.sqrt(x)], "math", "cse")
    assert code.assignments == ()
    assert code.outputs == ("((1.0/3.0))*math.sqrt(a0) + ((a0)*(a0))/((a1)*(a1)*(a1))",)


def test_cse_shares_a_repeated_sub_expression_once():
    shared = sympy.sin(x + y)
    code = straight_line(INPUTS, [shared**2 + 1, shared * x], "math", "cse")
    assert code.assignments == (("t0", "math.sin(a0 + a1)"),)
    assert code.outputs == ("((t0)*(t0)) + 1.0", "a0*t0")


def test_dag_code_has_one_line_per_distinct_node():
    code = straight_line(INPUTS, [(x + y) ** 3 * sympy.exp(x + y)], "math", "dag")
    assert isinstance(code, StraightLineCode)
    names = dict(code.assignments)
    assert names["t0"] == "a0 + a1"  # x + y printed once, used twice
    assert "t0**3" in names.values() and "math.exp(t0)" in names.values()
    assert code.body()[0] == "    t0 = a0 + a1"


def test_dag_code_keeps_every_bit_of_a_float():
    third = sympy.Float(1.0 / 3.0)
    code = straight_line(INPUTS, [third * x], "math", "dag")
    assert repr(1.0 / 3.0) in code.assignments[-1][1]


def test_numpy_target_prints_numpy_functions():
    code = straight_line(INPUTS, [sympy.atan2(x, y) + sympy.sqrt(x)], "numpy", "tree")
    assert code.outputs == ("numpy.sqrt(a0) + numpy.arctan2(a0, a1)",)


def test_a_symbol_that_is_not_an_input_is_named():
    z = sympy.Symbol("z")
    with pytest.raises(ValueError, match="neither arguments nor parameters: z"):
        straight_line(INPUTS, [x * z], "math", "cse", "function f")
    with pytest.raises(UnsupportedExpression):
        straight_line(INPUTS, [x * z], "math", "dag")


def test_dag_code_refuses_what_it_cannot_print():
    with pytest.raises(UnsupportedExpression):
        straight_line(INPUTS, [sympy.Piecewise((x, y > 0), (y, True))], "math", "dag")
    with pytest.raises(UnsupportedExpression):
        straight_line(INPUTS, [sympy.Function("f")(x)], "math", "dag")


def test_unknown_target_and_sharing_are_named():
    with pytest.raises(ValueError, match="target"):
        straight_line(INPUTS, [x], "fortran", "cse")  # type: ignore[arg-type]  # an unknown target, on purpose
    with pytest.raises(ValueError, match="sharing"):
        straight_line(INPUTS, [x], "math", "global")  # type: ignore[arg-type]  # an unknown sharing mode, on purpose


def test_a_large_expression_skips_the_basic_preprocessing_and_keeps_its_value(monkeypatch):
    """cse's "basic" preprocessing (sympy's ``factor_terms`` and its sign normalisation) runs on expressions
    within ``BASIC_CSE_NODES`` distinct sub-expressions only; a larger one is shared as it is. With the limit
    lowered below the size of ``x*y - x*y**2`` (8 distinct nodes: the sum, two products, a power, ``x``, ``y``,
    ``-1``, ``2``), ``factor_terms`` no longer pulls out ``x*y``; the printed code evaluates to the
    expression's value either way."""
    import math

    import dirac.codegen.printer as printer

    expr = x * y - x * y**2
    assert printer._within(expr, 8) and not printer._within(expr, 7)
    whole = straight_line(INPUTS, [expr], "math", "cse")
    assert whole.outputs == ("a0*a1*(1.0 - a1)",)
    monkeypatch.setattr(printer, "BASIC_CSE_NODES", 7)
    plain = straight_line(INPUTS, [expr], "math", "cse")
    assert plain.outputs == ("-a0*((a1)*(a1)) + a0*a1",)
    for code in (whole, plain):
        value = eval(code.outputs[0], {"math": math, "a0": 0.7, "a1": -1.3})  # noqa: S307 (generated from sympy)
        assert value == pytest.approx(0.7 * -1.3 - 0.7 * 1.69, rel=1e-15)


def test_a_long_sum_is_split_into_lines_that_add_in_the_same_order():
    """A line of 3,000 or more operands is deeper than CPython's compiler recurses (RecursionError at
    compile time); the dag printer splits sums and products longer than ``CHAIN_OPERANDS`` into lines
    that continue one another. 450 operands (under the limit, so that one line compiles too) give the
    same bits both ways, the same additions in the same order; 5,000 compile and equal ``math.fsum`` to
    rounding."""
    import math
    import random

    from dirac.codegen.printer import CHAIN_OPERANDS

    rng = random.Random(7)
    for count in (450, 5000):
        xs = sympy.symbols(f"x0:{count}", real=True)
        code = straight_line({x: f"a[{k}]" for k, x in enumerate(xs)}, [sympy.Add(*xs), sympy.Mul(*xs[:450])],
                             "math", "dag")
        assert max(text.count(" + ") for _, text in code.assignments) <= CHAIN_OPERANDS - 1
        source = "def f(a):\n" + "\n".join(code.body()) + f"\n    return {code.outputs[0]}, {code.outputs[1]}\n"
        namespace: dict = {"math": math}
        exec(compile(source, "<test>", "exec"), namespace)
        values = [rng.uniform(-1.0, 1.0) for _ in range(count)]
        total, product = namespace["f"](values)
        order = [int(str(x)[1:]) for x in sympy.Add(*xs).args]  # the printed order of the terms
        assert total == pytest.approx(math.fsum(values), abs=1e-12 * count)
        if count == 450:
            one_line = eval(" + ".join(f"values[{k}]" for k in order))  # noqa: S307 (a test's own text)
            assert total == one_line
            factors = [int(str(x)[1:]) for x in sympy.Mul(*xs[:450]).args]
            assert product == eval(" * ".join(f"values[{k}]" for k in factors))  # noqa: S307
