"""Straight-line numeric code for sympy expressions, fast to generate.

``sympy.lambdify`` prints every expression as a tree, so large brackets (sums of
products of shared derivatives) print exponentially long, and its ``cse=True`` pays
for a global optimisation. :func:`compile_expressions` instead walks the expression
DAG once and emits one assignment per distinct sub-expression (structural sharing via
sympy's hashing), then compiles the lines with Python's ``compile``. The result
evaluates scalars at one point (the engine's decisions need a few points only); sympy
never runs in the evaluation.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import sympy

__all__ = ["compile_expressions"]

_FUNCTIONS = {
    sympy.sin: "math.sin",
    sympy.cos: "math.cos",
    sympy.tan: "math.tan",
    sympy.asin: "math.asin",
    sympy.acos: "math.acos",
    sympy.atan: "math.atan",
    sympy.sinh: "math.sinh",
    sympy.cosh: "math.cosh",
    sympy.tanh: "math.tanh",
    sympy.exp: "math.exp",
    sympy.log: "math.log",
    sympy.Abs: "abs",
}


def _nan_on_error(fn: Callable, n: int) -> Callable:
    def wrapped(*args: float) -> list[float]:
        try:
            return fn(*args)
        except (ValueError, ZeroDivisionError, OverflowError):
            return [math.nan] * n

    return wrapped


def compile_expressions(args: Sequence[sympy.Symbol], exprs: Sequence[sympy.Expr]) -> Callable[..., list[float]]:
    """Compile ``exprs`` into ``f(*args) -> list[float]`` (NaN where undefined).

    Parameters
    ----------
    args
        The symbols, in call order.
    exprs
        Expressions in ``args`` (elementary functions, rational powers, sqrt allowed).
    """
    names: dict = {}
    for k, s in enumerate(args):
        names[s] = f"a{k}"
    lines: list[str] = []
    counter = [0]

    def atom(e: sympy.Expr) -> str | None:
        if e in names:
            return names[e]
        if e.is_Number:
            if e.is_Integer:
                return f"{int(e)}.0"
            if e.is_Rational:
                return f"({int(e.p)}.0/{int(e.q)}.0)"
            return repr(float(e))
        if e is sympy.pi:
            return "math.pi"
        if e is sympy.E:
            return "math.e"
        return None

    def emit(root: sympy.Expr) -> str:
        done = atom(root)
        if done is not None:
            return done
        stack = [(root, False)]
        while stack:
            node, expanded = stack.pop()
            if atom(node) is not None:
                continue
            if not expanded:
                stack.append((node, True))
                for a in node.args:
                    if atom(a) is None:
                        stack.append((a, False))
                continue
            parts = [atom(a) for a in node.args]
            if node.is_Add:
                code = " + ".join(parts)
            elif node.is_Mul:
                code = " * ".join(parts)
            elif node.is_Pow:
                base, exp = parts
                if node.exp.is_Integer:
                    k = int(node.exp)
                    code = f"{base}**{k}" if k > 0 else f"1.0/({base}**{-k})"
                elif node.exp == sympy.S.Half:
                    code = f"math.sqrt({base})"
                else:
                    code = f"{base}**{exp}"
            elif node.func in _FUNCTIONS:
                code = f"{_FUNCTIONS[node.func]}({', '.join(parts)})"
            elif isinstance(node, sympy.atan2):
                code = f"math.atan2({parts[0]}, {parts[1]})"
            else:
                raise TypeError(f"cannot compile {node.func}")
            name = f"t{counter[0]}"
            counter[0] += 1
            lines.append(f"    {name} = {code}")
            names[node] = name
        return names[root]

    outputs = [emit(sympy.sympify(e)) for e in exprs]
    signature = ", ".join(f"a{k}" for k in range(len(args)))
    source = f"def _f({signature}):\n" + "\n".join(lines) + f"\n    return [{', '.join(outputs)}]\n"
    namespace: dict = {"math": math}
    exec(compile(source, "<dirac codegen>", "exec"), namespace)
    return _nan_on_error(namespace["_f"], len(exprs))
