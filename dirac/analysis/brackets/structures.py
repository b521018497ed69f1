"""The built-in structure matrices of the rigid body and :func:`named_bracket`.

* Chetaev bracket (248)–(249) on ``(M_1, M_2, M_3, R_11, …, R_33)``: so(3) ⋉ the three
  rows of ``R``;
* Lie–Poisson bracket of so(3) (248) on ``M`` alone.

:func:`named_bracket` builds any of :data:`BRACKET_NAMES` for an analysed system: the two
structures above, its Dirac bracket (240) and the canonical Poisson bracket.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import sympy

from dirac.analysis.brackets.named_brackets import (
    AnalysisBracket,
    Bracket,
    CanonicalBracket,
    StructureBracket,
    analysis_variables,
)
from dirac.analysis.brackets.noncanonical import NoncanonicalVariables
from dirac.errors import InputError

__all__ = ["BRACKET_NAMES", "chetaev_structure", "lie_poisson_so3_structure", "named_bracket"]

#: the built-in bracket names accepted by :func:`named_bracket` and ``--compare``
BRACKET_NAMES = ("dirac", "canonical", "chetaev", "lie_poisson_so3")


def _eps(i: int, j: int, k: int) -> int:
    return int(sympy.LeviCivita(i, j, k))


def chetaev_structure(M: Sequence[sympy.Symbol], R: sympy.Matrix) -> sympy.Matrix:
    """Chetaev bracket (248)–(249) on ``(M_1, M_2, M_3, R_11, …, R_33)``::

        {M_i, M_j} = -eps_ijk M_k,  {M_i, R_jk} = -eps_ikm R_jm,  {R_ij, R_ab} = 0.

    The Lie–Poisson bracket of so(3) ⋉ (R^3)^3: ``M`` acts on each row of ``R``.
    """
    J = sympy.zeros(12, 12)
    for i in range(3):
        for j in range(3):
            J[i, j] = -sum(_eps(i, j, k) * M[k] for k in range(3))
        for j in range(3):
            for k in range(3):
                column = 3 + 3 * j + k
                J[i, column] = -sum(_eps(i, k, m) * R[j, m] for m in range(3))
                J[column, i] = -J[i, column]
    return J


def lie_poisson_so3_structure(M: Sequence[sympy.Symbol]) -> sympy.Matrix:
    """Lie–Poisson bracket of so(3) on ``M``: ``{M_i, M_j} = -eps_ijk M_k`` (248)."""
    return sympy.Matrix(3, 3, lambda i, j: -sum(_eps(i, j, k) * M[k] for k in range(3)))


def named_bracket(name: str, analysis: Any, variables: NoncanonicalVariables | None = None) -> Bracket:
    """One of the built-in brackets :data:`BRACKET_NAMES` on the variables of ``analysis``.

    ``dirac`` (the engine's (240)), ``canonical``, ``chetaev`` ((248)–(249), on
    ``M, R``), ``lie_poisson_so3`` ((248), on ``M`` only).

    Raises
    ------
    InputError
        For an unknown name, or ``chetaev``/``lie_poisson_so3`` on a system without
        coordinates ``R_11 … R_33``.
    """
    variables = variables if variables is not None else analysis_variables(analysis)
    if name == "dirac":
        return AnalysisBracket(analysis, variables)
    if name == "canonical":
        return CanonicalBracket(variables)
    if name in ("chetaev", "lie_poisson_so3"):
        if not all(f"M_{k}" in variables.names for k in (1, 2, 3)):
            raise InputError(
                f"bracket {name!r} acts on the body angular momentum M: it needs a rigid-body "
                "system with coordinates R_11 … R_33 (rigid_body_matrix, rigid_body_momentum)"
            )
        M = [variables.symbols[f"M_{k}"] for k in (1, 2, 3)]
        if name == "lie_poisson_so3":
            return StructureBracket(
                name, "Lie-Poisson bracket of so(3): {M_i, M_j} = -eps_ijk M_k (248)",
                variables, [f"M_{k}" for k in (1, 2, 3)], lie_poisson_so3_structure(M),
            )
        R = sympy.Matrix(3, 3, lambda i, j: variables.symbols[f"R_{i + 1}{j + 1}"])
        names = [*(f"M_{k}" for k in (1, 2, 3)), *(f"R_{i}{j}" for i in (1, 2, 3) for j in (1, 2, 3))]
        return StructureBracket(
            name, "Chetaev bracket (248)-(249): so(3) acting on the rows of R",
            variables, names, chetaev_structure(M, R),
        )
    raise InputError(f"unknown bracket {name!r}: choose from {', '.join(BRACKET_NAMES)}")
