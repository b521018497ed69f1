"""The parts of a ``sympy.physics.mechanics.LagrangesMethod`` that :meth:`dirac.Lagrangian.from_sympy` takes.

A ``LagrangesMethod(L, qs, hol_coneqs=...)`` holds the Lagrangian ``L``, the coordinates
``qs`` (``dynamicsymbols``) and the holonomic constraints ``chi(q, t) = 0``: exactly the
input of the Dirac–Bergmann analysis. Its multipliers ``lam1, lam2, ...`` in ``lm.eom``
are those of ``L - lam_a chi_a`` (``lam_coeffs = -d chi/dq``), the engine's ``lambda_a``;
docs/sympy_mechanics.md shows both side by side.

Not taken (refused with a clear error): non-holonomic constraints (the engine treats
holonomic ones) and a non-empty ``forcelist`` (generalized forces do not enter through
this path yet).
"""

from __future__ import annotations

from typing import Any

import sympy

from dirac.errors import InputError

__all__ = ["is_lagranges_method", "lagranges_method_parts"]


def is_lagranges_method(value: object) -> bool:
    """Whether ``value`` is a ``sympy.physics.mechanics.LagrangesMethod`` (without importing sympy's mechanics)."""
    return any(cls.__name__ == "LagrangesMethod" and cls.__module__.startswith("sympy.physics.mechanics")
               for cls in type(value).__mro__)


def lagranges_method_parts(method: Any) -> tuple[sympy.Expr, list[sympy.Expr], list[sympy.Expr]]:
    """``(L, coordinates, holonomic constraints)`` of a ``LagrangesMethod``.

    Raises
    ------
    InputError
        For non-holonomic constraints or a non-empty ``forcelist``.
    """
    L = method._L[0] if isinstance(method._L, sympy.MatrixBase) else method._L
    coordinates = list(method.q)
    holonomic = list(method._hol_coneqs) if method._hol_coneqs is not None else []
    if len(method.coneqs) > len(holonomic):
        raise InputError(
            f"the LagrangesMethod has {len(method.coneqs) - len(holonomic)} non-holonomic constraint(s) "
            "(nonhol_coneqs): dirac treats holonomic constraints chi(q, t) = 0 only; give them as hol_coneqs"
        )
    if method.forcelist:
        raise InputError(
            f"the LagrangesMethod has a forcelist ({len(method.forcelist)} load(s)): forces are not supported by "
            "this path yet; build the LagrangesMethod without forcelist (forces derived from a potential belong "
            "in the Lagrangian)"
        )
    return L, coordinates, holonomic
