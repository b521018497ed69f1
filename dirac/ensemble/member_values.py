"""Members' values of expressions of the ensemble variables, and how a member is named in messages.

Shared by the member loops of general systems, analysed systems and the heavy top.
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np

__all__ = ["evaluate", "member_column", "member_label"]


def evaluate(expression: object, variables: tuple[str, ...], values: np.ndarray) -> np.ndarray:
    """An expression (sympy, or a number) of the ensemble variables at each member's values."""
    import sympy

    if not isinstance(expression, sympy.Basic):
        return np.full(values.shape[0], float(expression))  # type: ignore[arg-type]
    function = _numpy_function(expression, variables)
    result = function(*(values[:, k] for k in range(len(variables))))
    return np.broadcast_to(np.asarray(result, dtype=float), (values.shape[0],)).copy()


def member_column(value: float | str, where: str, names: tuple[str, ...], values: np.ndarray) -> np.ndarray:
    """A scene entry for every member: a number repeated, or an expression (a string, read by
    the safe expression parser; ``where`` names the entry in its errors) of the ensemble
    variables ``names`` at each member's ``values`` (rows)."""
    import sympy

    from dirac.model.expressions import parse_expression

    if isinstance(value, str):
        symbols = {name: sympy.Symbol(name, real=True) for name in names}
        return evaluate(parse_expression(value, symbols, what=where), names, values)
    return np.full(values.shape[0], float(value))


@functools.lru_cache(maxsize=256)
def _numpy_function(expression: Any, variables: tuple[str, ...]) -> Any:
    """``expression`` of the ensemble variables as a numpy function (made once per process:
    ``sympy.lambdify`` takes milliseconds, and every chunk evaluates the same expressions)."""
    import sympy

    return sympy.lambdify([sympy.Symbol(name, real=True) for name in variables], expression, "numpy")


def member_label(names: tuple[str, ...], row: np.ndarray) -> str:
    """``"a = 0.5, b = 1"``: a member's ensemble variables, every digit."""
    return ", ".join(f"{name} = {value:.17g}" for name, value in zip(names, row))
