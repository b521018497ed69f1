"""Assumptions that pick a part of the phase space: ``"EXPR != 0"`` and ``"EXPR = 0"``.

Where the constraint surface has parts of different structure (the light-cone Yang–Mills
surface: ``A_- != 0`` and ``A_- = 0``), ranks decided at random points of the surface mix
the parts. An assumption ``EXPR != 0`` keeps the sample points away from ``EXPR = 0``
(:attr:`dirac.analysis.core.numeric.Numerics.avoid`), so every rank is that of the part
where ``EXPR != 0``. ``EXPR = 0`` (a function of the phase-space variables and parameters)
is imposed as a constraint of stage 2, without a multiplier of its own
(:attr:`dirac.analysis.chain.constraint_chain.ConstraintChain.imposed`): the Lagrangian is
unchanged, and the later stages keep the part of the surface on which the motion keeps
``EXPR = 0`` (Dirac's consistency conditions applied to the restriction). Adding it as a
holonomic constraint instead would add a reaction force along its gradient: another
system.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass

import sympy

from dirac.errors import InputError

__all__ = ["Assumption", "parse_assumptions"]


@dataclass(frozen=True)
class Assumption:
    """``expression != 0`` (``nonzero=True``) or ``expression = 0``."""

    expression: sympy.Expr
    nonzero: bool

    def __str__(self) -> str:
        return f"{self.expression} {'!=' if self.nonzero else '='} 0"


def parse_assumptions(items: Iterable[str], names: Mapping[str, sympy.Symbol]) -> list[Assumption]:
    """``["am1**2 + am2**2 != 0", "x - y = 0"]`` -> assumptions; :class:`InputError` for malformed ones.

    ``LHS != RHS`` and ``LHS = RHS`` (also ``==``) become ``LHS - RHS != 0`` / ``= 0``;
    ``names`` are the symbols the expression may use.
    """
    from dirac.validate import did_you_mean

    out = []
    for item in items:
        text = str(item)
        if "!=" in text:
            left, right, nonzero = *text.split("!=", 1), True
        elif "==" in text:
            left, right, nonzero = *text.split("==", 1), False
        elif text.count("=") == 1:
            left, right, nonzero = *text.split("=", 1), False
        else:
            raise InputError(f"assumption {text!r} is malformed: write EXPR != 0 or EXPR = 0, e.g. \"x**2 + y**2 != 0\"")
        try:
            expr = sympy.sympify(left, locals=dict(names)) - sympy.sympify(right, locals=dict(names))
        except (sympy.SympifyError, SyntaxError, TypeError) as exc:
            raise InputError(f"assumption {text!r} is not an expression: {exc}") from None
        unknown = sorted(s.name for s in expr.free_symbols if s.name not in names or names[s.name] != s)
        if unknown:
            raise InputError(
                f"assumption {text!r} uses unknown name(s) {', '.join(unknown)}{did_you_mean(unknown[0], list(names))}"
            )
        if expr == 0 or not expr.free_symbols:
            raise InputError(f"assumption {text!r} does not depend on any variable: write a condition on the phase space")
        out.append(Assumption(sympy.expand(expr), nonzero))
    return out
