"""The transcendental functions of ``q`` that a step has just evaluated, for the reductions.

The unconstrained RATTLE loop of a system whose mass depends on ``q`` (the double pendulum
in its angles, a top in Euler angles) evaluates the transcendental functions its
expressions share -- ``sin(th1)``, ``cos(th1 - th2)``, ... -- once per configuration, into
an array ``w`` (``transcendentals(q, t, c, w)`` of the system's module). Its last
evaluation in a step is at the step's final ``q`` (stage 3 of the step reads ``w`` at the
iterate of ``q1`` on which stage 2 converged, which becomes ``q``:
:data:`dirac.codegen.kernel_templates._HOISTED`). A member loop that evaluates its
reductions after every step -- ``x1 = l1 sin(th1)`` of the flip-time map -- can read those
values instead of calling ``sin`` again: the same function of the same argument, the same
bits.

:func:`step_transcendentals` reads back, from the module's source, which expression each
entry of ``w`` holds: the body of ``transcendentals`` is straight-line code of
:func:`dirac.codegen.kernel_source.emit_function` (assignments, arithmetic, ``math``
functions), rebuilt here as sympy expressions by a small evaluator of its syntax tree (no
``eval``). Anything it does not recognise gives ``None``: the reductions then compute
everything themselves, as before. :func:`substitute_transcendentals` replaces the
sub-expressions of the reductions that are entries of ``w`` by symbols of ``w``.

Only entries that do not depend on the time are offered: the step leaves ``w`` at the time
of its last stage, whose floating-point value need not be the member loop's step time.
"""

from __future__ import annotations

import ast
from collections.abc import Sequence
from typing import Any

__all__ = ["step_transcendentals", "substitute_transcendentals"]

#: the ``math`` functions of the printed code and their sympy counterparts (by name)
_FUNCTIONS = {
    "sin": "sin", "cos": "cos", "tan": "tan", "asin": "asin", "acos": "acos", "atan": "atan", "atan2": "atan2",
    "sinh": "sinh", "cosh": "cosh", "tanh": "tanh", "asinh": "asinh", "acosh": "acosh", "atanh": "atanh",
    "exp": "exp", "log": "log", "sqrt": "sqrt",
}


class _Unknown(Exception):
    """A construct the evaluator does not read: the caller falls back to no reuse."""


def step_transcendentals(source: str, coordinates: Sequence[Any], parameters: Sequence[Any],
                         time: Any) -> list[Any] | None:
    """The sympy expression of each entry of ``w`` that ``transcendentals(q, t, c, out)`` in
    ``source`` fills, in the symbols ``coordinates`` (``q[i]``), ``parameters`` (``c[j]``) and
    ``time`` (``t``); ``None`` when the module has no such function or its body is not the
    plain straight-line code expected (then nothing is reused).

    Parameters
    ----------
    source : str
        The system's generated module.
    coordinates, parameters : sequence of sympy.Symbol
        The symbols of ``q`` and ``c`` in order.
    time : sympy.Symbol
        The symbol of ``t``.
    """
    import sympy

    start = source.find("\ndef transcendentals(q, t, c, out):")
    if start < 0:
        return None
    stop = source.find("\n@", start + 1)
    text = source[start + 1:] if stop < 0 else source[start + 1:stop]
    try:
        function = ast.parse(text).body[0]
    except SyntaxError:
        return None
    if not isinstance(function, ast.FunctionDef):
        return None
    arrays = {"q": list(coordinates), "c": list(parameters)}
    local: dict[str, Any] = {"t": time}
    entries: dict[int, Any] = {}
    try:
        for statement in function.body:
            if isinstance(statement, ast.Expr) and isinstance(statement.value, ast.Constant):
                continue  # the docstring
            if isinstance(statement, ast.Return) and statement.value is None:
                continue
            if not (isinstance(statement, ast.Assign) and len(statement.targets) == 1):
                raise _Unknown
            target = statement.targets[0]
            value = _evaluate(statement.value, local, arrays, sympy)
            if isinstance(target, ast.Name):
                local[target.id] = value
            elif (isinstance(target, ast.Subscript) and isinstance(target.value, ast.Name) and target.value.id == "out"
                  and isinstance(target.slice, ast.Constant) and isinstance(target.slice.value, int)):
                entries[target.slice.value] = value
            else:
                raise _Unknown
    except (_Unknown, IndexError, KeyError, TypeError, ValueError, ZeroDivisionError):
        return None
    if sorted(entries) != list(range(len(entries))):
        return None
    return [entries[k] for k in range(len(entries))]


def _evaluate(node: ast.AST, local: dict[str, Any], arrays: dict[str, list[Any]], sympy: Any) -> Any:
    """The sympy expression of one right-hand side of the straight-line code."""
    if isinstance(node, ast.Name):
        return local[node.id]
    if isinstance(node, ast.Constant) and type(node.value) in (int, float):
        return sympy.Rational(node.value)  # the exact value of the double the code uses
    if isinstance(node, ast.Subscript) and isinstance(node.value, ast.Name) and node.value.id in arrays:
        index = node.slice
        if not (isinstance(index, ast.Constant) and type(index.value) is int):
            raise _Unknown
        return arrays[node.value.id][index.value]
    if isinstance(node, ast.UnaryOp):
        operand = _evaluate(node.operand, local, arrays, sympy)
        if isinstance(node.op, ast.USub):
            return -operand
        if isinstance(node.op, ast.UAdd):
            return operand
        raise _Unknown
    if isinstance(node, ast.BinOp):
        left = _evaluate(node.left, local, arrays, sympy)
        right = _evaluate(node.right, local, arrays, sympy)
        operations = {ast.Add: lambda a, b: a + b, ast.Sub: lambda a, b: a - b, ast.Mult: lambda a, b: a * b,
                      ast.Div: lambda a, b: a / b, ast.Pow: lambda a, b: a ** b}
        for kind, operation in operations.items():
            if isinstance(node.op, kind):
                return operation(left, right)
        raise _Unknown
    if (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and isinstance(node.func.value, ast.Name)
            and node.func.value.id == "math" and node.func.attr in _FUNCTIONS and not node.keywords):
        arguments = [_evaluate(a, local, arrays, sympy) for a in node.args]
        return getattr(sympy, _FUNCTIONS[node.func.attr])(*arguments)
    raise _Unknown


def substitute_transcendentals(expressions: Sequence[Any], entries: Sequence[Any] | None, fixed: set[Any]
                               ) -> tuple[list[Any], list[Any]] | None:
    """``expressions`` with each sub-expression that is an entry of ``w`` (``entries``) whose
    symbols are all in ``fixed`` (the coordinates and parameters: not the time) replaced by a
    symbol of ``w``; returns ``(substituted, w_symbols)``, or ``None`` when nothing is replaced.
    """
    import sympy

    if not entries or not expressions:
        return None
    symbols = [sympy.Symbol(f"_ensw{k}", real=True) for k in range(len(entries))]
    table = {entry: symbol for entry, symbol in zip(entries, symbols)
             if entry.free_symbols and entry.free_symbols <= fixed}
    if not table:
        return None
    substituted = [sympy.sympify(e).xreplace(table) for e in expressions]
    if all(new == old for new, old in zip(substituted, expressions)):
        return None
    return substituted, symbols
