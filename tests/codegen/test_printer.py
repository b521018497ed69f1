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


def _inlined(code: StraightLineCode, text: str) -> str:
    """``text`` with the name of each line of ``code`` replaced by that line's code, last line first (a line
    uses only earlier ones): one line of code again."""
    import re

    for name, line in reversed(code.assignments):
        text = re.sub(rf"\b{name}\b", lambda _: line, text)  # noqa: B023 (used at once)
    return text


def _function(code: StraightLineCode, count: int, modules: dict) -> object:
    source = ("def f(a):\n" + "".join(f"    a{k}_ = a[{k}]\n" for k in range(count)) + "\n".join(code.body())
              + f"\n    return ({''.join(o + ', ' for o in code.outputs)})\n")
    namespace = dict(modules)
    exec(compile(source, "<test>", "exec"), namespace)  # noqa: S102 (generated from sympy)
    return namespace["f"]


ROADS = [("math", "cse"), ("math", "tree"), ("numpy", "cse"), ("numpy", "tree")]


def _long_expressions(count: int) -> tuple[dict, list[sympy.Expr]]:
    """Inputs ``a<k>_`` and expressions with sums and products of ``count`` operands, alone and nested:
    in a function and a power, in a product, a quotient of two long products (no two sums share terms,
    so that cse leaves them whole)."""
    xs = sympy.symbols(f"x0:{count}", real=True)
    total = sympy.Add(*[(-1) ** k * x for k, x in enumerate(xs)])
    nested = [total, sympy.sin(total + 1) + 2 * total**2, sympy.Mul(*xs[:count // 2]) / sympy.Mul(*xs[count // 2:]),
              xs[0] * (sympy.Add(*[2 * x for x in xs[1:]]) + 1)]
    return {x: f"a{k}_" for k, x in enumerate(xs)}, nested


@pytest.mark.parametrize(("target", "sharing"), ROADS)
def test_long_sums_on_the_cse_and_tree_roads_are_split_into_lines_that_keep_the_operations(target, sharing,
                                                                                          monkeypatch):
    """Sums and products of more than ``CHAIN_OPERANDS`` operands, also inside a function, a power, a
    product or a quotient, are printed over lines continuing one another: with each line's name replaced
    by its code, the text is the one line sympy prints (the printer with the limit out of reach), so the
    same operations in the same order: 450 operands (the one line compiles too) give the same bits both
    ways, on random inputs."""
    import math
    import random

    import numpy as np

    import dirac.codegen.printer as printer

    count = 450
    inputs, expressions = _long_expressions(count)
    code = straight_line(inputs, expressions, target, sharing)
    assert max(len(text.split()) for _, text in code.assignments) <= 2 * printer.CHAIN_OPERANDS - 1
    names = [name for name, _ in code.assignments]
    assert len(set(names)) == len(names) and not set(names) & set(inputs.values())
    with monkeypatch.context() as patch:
        patch.setattr(printer, "CHAIN_OPERANDS", 10**9)
        whole = straight_line(inputs, expressions, target, sharing)
    assert len(whole.assignments) < len(code.assignments)
    assert [_inlined(code, text) for text in code.outputs] == [_inlined(whole, text) for text in whole.outputs]
    modules = {"math": math, "numpy": np}
    rng = random.Random(11)
    for _ in range(3):
        values = [rng.uniform(0.5, 2.0) for _ in range(count)]
        assert _function(code, count, modules)(values) == _function(whole, count, modules)(values)  # == on floats


@pytest.mark.parametrize(("target", "sharing"), [("math", "cse"), ("numpy", "tree")])
def test_a_sum_of_3000_terms_compiles_once_split(target, sharing, monkeypatch):
    """A sum of 2,987 or more names on one line does not compile at the top level of a script (CPython
    3.11's compiler recurses into the left-deep tree: RecursionError; 3 operands fewer per frame of the
    caller's stack), on every road and target (the kernels' road, "cse" and "math", in
    test_kernel_source.py). Split, 3,000 compile and equal ``math.fsum`` to rounding."""
    import math
    import random

    import numpy as np

    import dirac.codegen.printer as printer

    count = 3000
    inputs, expressions = _long_expressions(count)
    code = straight_line(inputs, expressions[:1], target, sharing)
    rng = random.Random(3)
    values = [rng.uniform(0.5, 2.0) for _ in range(count)]
    (total,) = _function(code, count, {"math": math, "numpy": np})(values)
    assert total == pytest.approx(math.fsum((-1) ** k * v for k, v in enumerate(values)), rel=0, abs=1e-15 * count)
    if sharing == "tree":  # printed on one line, as before (cse's road: twice the time of sympy's cse)
        monkeypatch.setattr(printer, "CHAIN_OPERANDS", 10**9)
        with pytest.raises(RecursionError):
            _function(straight_line(inputs, expressions[:1], target, sharing), count, {})
