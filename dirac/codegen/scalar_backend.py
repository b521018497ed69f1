"""Scalar backend: sympy expressions -> a plain-Python function of floats, fast to build.

``sympy.lambdify`` prints every expression as a tree, so large brackets (sums of
products of shared derivatives) print exponentially long, and a global common
sub-expression search costs more than the few evaluations the engine needs.
:func:`scalar_function` prints the expressions with
:func:`dirac.codegen.printer.straight_line` (``sharing="dag"``: one assignment per
distinct sub-expression) and compiles the lines with Python's ``compile``. The result
evaluates scalars at one point (the engine's decisions need a few points only); sympy
never runs in the evaluation.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import sympy

from dirac.codegen.printer import straight_line

__all__ = ["scalar_function"]


def _nan_on_error(fn: Callable[..., list[float]], n: int) -> Callable[..., list[float]]:
    def wrapped(*args: float) -> list[float]:
        try:
            return fn(*args)
        except (ValueError, ZeroDivisionError, OverflowError):
            return [math.nan] * n

    return wrapped


def scalar_function(arguments: Sequence[sympy.Symbol], expressions: Sequence[sympy.Expr]) -> Callable[..., list[float]]:
    """Compile ``expressions`` into ``f(*arguments) -> list[float]`` (NaN where undefined).

    Parameters
    ----------
    arguments
        The symbols, in call order.
    expressions
        Expressions in ``arguments`` (sums, products, powers and the elementary
        functions of :mod:`math`).

    Returns
    -------
    callable
        ``f(a_0, a_1, ...)``: the values of the expressions; every value is NaN when the
        point is outside the domain (a math domain error, a division by zero, an overflow).

    Raises
    ------
    dirac.codegen.printer.UnsupportedExpression
        For a node the printer cannot compile (a ``TypeError``; use
        :func:`dirac.codegen.numpy_backend.array_function` then).
    """
    inputs = {symbol: f"a{k}" for k, symbol in enumerate(arguments)}
    code = straight_line(inputs, expressions, "math", "dag")
    signature = ", ".join(f"a{k}" for k in range(len(arguments)))
    source = f"def _f({signature}):\n" + "\n".join(code.body()) + f"\n    return [{', '.join(code.outputs)}]\n"
    namespace: dict[str, Any] = {"math": math}
    exec(compile(source, "<dirac codegen>", "exec"), namespace)
    return _nan_on_error(namespace["_f"], len(code.outputs))
