"""Compiled values of expressions together with the sizes of their terms, from one source.

The numerical decisions of :class:`~dirac.analysis.core.numeric.Numerics` compare a value
with the size of the terms it was computed from (``1 + sum |term|``, a relative zero
test). Compiling the terms as expressions of their own prints and compiles every term's
sub-expressions a second time, although they are already named in the straight-line code
of the expression (``sharing="dag"``: one assignment per distinct sub-expression). Here
one function computes both: the shared straight-line body, then the values, or on
request the term sizes, or both from one pass (a caller that needs both at a point pays
for the body once), each size summed in the order of the terms
(``((1 + |t_1|) + |t_2|) + ...``, the same floating-point sums as adding the terms' values
one by one). Higham, *Accuracy and Stability of Numerical Algorithms* (2nd ed., 2002),
Sect. 4.2: recursive summation, whose result depends only on the order of the terms.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import sympy

from dirac.codegen import chained, straight_line

__all__ = ["BOTH", "ScaledFunction", "scaled_function", "terms_of"]

#: ``f(flag, *arguments)``: values (``flag`` false), term sizes (``flag`` true) or both (``flag == BOTH``)
ScaledFunction = Callable[..., Any]

#: the ``flag`` of a :data:`ScaledFunction` that returns ``(values, term sizes)`` from one pass
BOTH = 2


def terms_of(expr: sympy.Expr) -> tuple[sympy.Expr, ...]:
    """The top-level terms of ``expr``: the arguments of a sum, else ``expr`` itself."""
    return expr.args if isinstance(expr, sympy.Add) else (expr,)


def _literal(value: float) -> str:
    """Python source of a float that reads back as the same float (``inf`` and ``nan`` too)."""
    return repr(value) if math.isfinite(value) else f"float({repr(value)!r})"


def _nan_on_error(fn: ScaledFunction, arguments: Sequence[sympy.Symbol], expressions: list[sympy.Expr]) -> ScaledFunction:
    """``fn``, where a point outside the domain of some expressions gives NaN for those only.

    The expressions of a batch share one straight-line body, which stops at the first
    division by zero or math domain error of any of them: at a point on a pole of one
    expression, a polynomial of the same batch would read NaN too, and a rank or a zero test
    taken of it would be refused or wrong ((228)'s consistency matrix on ``det R = 0``, where
    its polynomial rows are defined). After such an error each expression is evaluated by a
    function of its own (compiled on the first error), so NaN marks exactly the undefined ones.
    """
    n = len(expressions)
    alone: list[ScaledFunction] = []

    def one_by_one(flag: int, *args: float) -> Any:
        if n == 1:
            return ([math.nan], [math.nan]) if flag == BOTH else [math.nan]
        if not alone:
            alone.extend(scaled_function(arguments, [e]) for e in expressions)
        parts = [f(BOTH, *args) for f in alone]
        values = [v[0] for v, _ in parts]
        sizes = [z[0] for _, z in parts]
        return (values, sizes) if flag == BOTH else (sizes if flag else values)

    def wrapped(flag: int, *args: float) -> Any:
        try:
            return fn(flag, *args)
        except (ValueError, ZeroDivisionError, OverflowError):
            return one_by_one(flag, *args)

    return wrapped


def scaled_function(arguments: Sequence[sympy.Symbol], expressions: Sequence[sympy.Expr]) -> ScaledFunction:
    """Compile ``expressions`` into ``f(flag, *arguments)``: their values, or with ``flag`` their term sizes.

    Parameters
    ----------
    arguments
        The symbols, in call order.
    expressions
        Expressions in ``arguments`` that are not numbers.

    Returns
    -------
    callable
        ``f(False, a_0, a_1, ...)``: the values of the expressions;
        ``f(True, a_0, a_1, ...)``: ``1 + |t_1| + |t_2| + ...`` for each expression, its
        terms ``t_i`` (:func:`terms_of`) added in their order, a term that is a number as
        ``|float(t)|``, of a complex value its real part;
        ``f(BOTH, a_0, a_1, ...)``: ``(values, sizes)``, the same numbers as the two calls
        above, from one pass through the body. A value (and its size) is NaN where
        the point is outside its expression's domain (a math domain error, a division by
        zero, an overflow); the other expressions keep their values (:func:`_nan_on_error`).

    Raises
    ------
    dirac.codegen.UnsupportedExpression
        For a node the scalar printer cannot compile.
    """
    expressions = list(expressions)
    inputs = {symbol: f"a{k}" for k, symbol in enumerate(arguments)}
    owned = [terms_of(e) for e in expressions]
    symbolic = list(dict.fromkeys(t for terms in owned for t in terms if not t.is_number))
    # the terms as further outputs: each is a node of its expression, already named in the body
    code = straight_line(inputs, [*expressions, *symbolic], "math", "dag")
    term_name = dict(zip(symbolic, code.outputs[len(expressions):]))

    size_lines: list[tuple[str, str]] = []  # the partial sums of long sizes (s<k>, apart from the body's t<k>)

    def size(terms: tuple[sympy.Expr, ...]) -> str:
        parts = [_literal(abs(float(t))) if t.is_number else f"abs(({term_name[t]}).real)" for t in terms]
        return chained(["1.0", *parts], " + ", size_lines, prefix="s")

    signature = ", ".join(["flag", *(f"a{k}" for k in range(len(arguments)))])
    values = f"[{', '.join(code.outputs[: len(expressions)])}]"
    sizes = ", ".join(size(terms) for terms in owned)
    sizes_body = "".join(f"\n        {name} = {text}" for name, text in size_lines)
    source = (
        f"def _f({signature}):\n" + "\n".join(code.body())
        + f"\n    if flag:{sizes_body}\n        sizes = [{sizes}]"
        + f"\n        return ({values}, sizes) if flag == {BOTH} else sizes"
        + f"\n    return {values}\n"
    )
    namespace: dict[str, Any] = {"math": math}
    exec(compile(source, "<dirac codegen>", "exec"), namespace)
    return _nan_on_error(namespace["_f"], arguments, expressions)
