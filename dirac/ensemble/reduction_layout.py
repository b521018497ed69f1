"""The reductions of a general ensemble scene as expressions and a layout of the kernel's arrays.

Shared by the member loops that are generated from a system's own step (the RATTLE /
forced-RATTLE / midpoint loop of :mod:`dirac.ensemble.general_kernel` and the analysed
system's Dirac flow of :mod:`dirac.ensemble.analysed_members`): each reduction's text is
parsed against the names a reduction may use and put where the member loop looks for it.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from dirac.ensemble.general_scene import GeneralEnsembleScene, split_condition

__all__ = ["reduction_layout"]


def reduction_layout(scene: GeneralEnsembleScene, state: Mapping[str, Any]
                     ) -> tuple[list[Any], list[tuple[Any, str]], dict[str, list]]:
    """``(exprs, conditions, layout)`` of ``scene``'s reductions in the names ``state``.

    ``exprs`` are the expressions the member loop evaluates after every step (sympy);
    ``conditions`` the ``when`` conditions as ``(value, op)``, true when ``value op 0``
    (``A > B`` becomes ``A - B > 0``, ``A <= B`` becomes ``B - A >= 0``); ``layout`` maps
    ``"cross"`` to ``(name, [(expr index, condition index or -1), ...])`` per
    ``first_crossing``, ``"ext"`` to ``(name, "max" | "min", expr index)`` and
    ``"poincare"`` to ``(name, expr index, count)``.
    """
    from dirac.model.expressions import parse_expression

    exprs: list[Any] = []
    conditions: list[tuple[Any, str]] = []
    layout: dict[str, list] = {"cross": [], "ext": [], "poincare": []}
    for reduction in scene.reductions:
        parsed = [parse_expression(text, dict(state), what=f"reduction {reduction.name}") for text in reduction.exprs]
        if reduction.kind == "first_crossing":
            group = []
            for text, when in zip(parsed, reduction.whens):
                exprs.append(text)
                cond = -1
                if when is not None:
                    lhs, op, rhs = split_condition(when, reduction.name)
                    left = parse_expression(lhs, dict(state), what=f"reduction {reduction.name} when")
                    right = parse_expression(rhs, dict(state), what=f"reduction {reduction.name} when")
                    value = left - right if op in (">", ">=") else right - left
                    conditions.append((value, ">" if op in (">", "<") else ">="))
                    cond = len(conditions) - 1
                group.append((len(exprs) - 1, cond))
            layout["cross"].append((reduction.name, group))
        elif reduction.kind in ("max", "min"):
            exprs.append(parsed[0])
            layout["ext"].append((reduction.name, reduction.kind, len(exprs) - 1))
        elif reduction.kind == "poincare":
            exprs.append(parsed[0])
            layout["poincare"].append((reduction.name, len(exprs) - 1, reduction.count))
    return exprs, conditions, layout
