"""Numpy backend: sympy expressions -> functions that evaluate on numpy arrays.

What ``sympy.lambdify(..., "numpy")`` gave, printed by
:func:`dirac.codegen.printer.straight_line` (target ``"numpy"``, sympy's numpy printer and
lambdify's names, so the values are the same): the arguments may be numbers or arrays
(they broadcast), values outside a function's domain give NaN or inf with numpy's
warnings instead of exceptions. Used outside time steps: cross-checks of the
compiled kernels and one-off evaluations (samples of a matrix at a few points, bracket
matrices at sampled points).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import Any, TypeAlias

import numpy as np
import sympy

from dirac.codegen.printer import flat_expressions, input_name, straight_line

__all__ = ["array_function", "numpy_function"]

#: one argument of an array function: a symbol, or a group of symbols passed as one sequence
Argument: TypeAlias = "sympy.Symbol | Sequence[sympy.Symbol]"


def _shape(expressions: object, size: int) -> tuple[int, ...]:
    if isinstance(expressions, sympy.MatrixBase):
        return tuple(expressions.shape)
    return (size,)


def array_function(arguments: Sequence[Argument], expressions: Iterable[object], cse: bool = True) -> Callable[..., np.ndarray]:
    """Compile ``expressions`` into ``f(*values) -> ndarray``.

    Parameters
    ----------
    arguments
        Call order. Each item is a symbol (one value) or a sequence of symbols (one
        argument holding their values along its first axis, like ``lambdify([[x, y], z],
        ...)``).
    expressions
        A sympy matrix (the result has its shape) or a sequence of expressions (shape
        ``(len,)``).
    cse
        ``True``: shared sub-expressions found by :func:`sympy.cse` (as
        ``lambdify(..., cse=True)``); ``False``: every output printed whole.

    Returns
    -------
    callable
        ``f(*values)``: array of shape ``expression shape + broadcast shape of the values``
        (float, or complex where a value is complex).
    """
    symbols: list[sympy.Symbol] = []
    groups: list[int | None] = []  # None: a single symbol; k: a group of k symbols
    for item in arguments:
        if isinstance(item, sympy.Basic):
            symbols.append(item)
            groups.append(None)
        else:
            members = list(item)
            symbols.extend(members)
            groups.append(len(members))
    flat = flat_expressions(expressions)
    shape = _shape(expressions, len(flat))
    names: list[str] = []
    for k, symbol in enumerate(symbols):
        names.append(input_name(symbol, k, set(names)))
    code = straight_line(dict(zip(symbols, names)), expressions, "numpy", "cse" if cse else "tree")
    signature = ", ".join(names)
    source = f"def _f({signature}):\n" + "\n".join(code.body()) + f"\n    return ({''.join(o + ', ' for o in code.outputs)})\n"
    namespace: dict[str, Any] = {"math": math, "numpy": np}
    exec(compile(source, "<dirac codegen numpy>", "exec"), namespace)
    compiled = namespace["_f"]

    def evaluate(*values: Any) -> np.ndarray:
        if len(values) != len(groups):
            raise TypeError(f"expected {len(groups)} arguments, got {len(values)}")
        flat_values: list[Any] = []
        for value, group in zip(values, groups):
            array = np.asarray(value, dtype=complex if np.iscomplexobj(value) else float)
            if group is None:
                flat_values.append(array)
            else:
                if len(array) != group:
                    raise ValueError(f"an argument of {group} values has {len(array)}")
                flat_values.extend(array[k] for k in range(group))
        results = [np.asarray(r) for r in compiled(*flat_values)]
        if not results:
            return np.zeros(shape)
        arrays = np.broadcast_arrays(*results)
        return np.stack(arrays).reshape(shape + arrays[0].shape)

    return evaluate


def numpy_function(
    arguments: Sequence[sympy.Symbol],
    expressions: Iterable[object],
    parameters: Sequence[sympy.Symbol] = (),
    parameter_values: Sequence[float] | Mapping[str, float] = (),
) -> Callable[[np.ndarray], np.ndarray]:
    """A numpy function ``f(x) -> ndarray`` of the expressions, with the calling order of
    the numba backend (``x[i]`` is ``arguments[i]``).

    Parameters are substituted by their values first. The result has the shape of
    ``expressions`` (a matrix) or ``(len(expressions),)``. Used for cross-checks and
    one-off evaluations outside the time loop.
    """
    values = list(parameter_values.values()) if isinstance(parameter_values, Mapping) else list(parameter_values)
    substitution = {p: sympy.Float(v, 17) for p, v in zip(parameters, values)}
    flat = [e.xreplace(substitution) for e in flat_expressions(expressions)]
    shape = _shape(expressions, len(flat))
    compiled = array_function([list(arguments)], flat)

    def evaluate(x: np.ndarray) -> np.ndarray:
        return np.asarray(compiled(np.asarray(x, dtype=float)), dtype=float).reshape(shape)

    return evaluate
