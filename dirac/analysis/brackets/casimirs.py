"""The Jacobi identity checked numerically, and the polynomial Casimirs of a linear structure.

:func:`jacobi_residual` evaluates ``{w_a, {w_b, w_c}} + cyclic`` of a bracket at points;
:func:`casimirs` finds the polynomial Casimirs of a linear (Lie–Poisson) structure, e.g.
``|M|^2`` for so(3) (248).
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence

import numpy as np
import sympy

from dirac.analysis.brackets.named_brackets import Bracket, StructureBracket
from dirac.errors import InputError

__all__ = ["JACOBI_TOLERANCE", "jacobi_residual", "casimirs"]

#: tolerance of the numerical Jacobi check (relative; central differences for Dirac)
JACOBI_TOLERANCE = 1e-6


def jacobi_residual(bracket: Bracket, points: Sequence[Mapping[str, float]]) -> float:
    """Largest ``|{w_a, {w_b, w_c}} + cyclic|`` over all triples of variables and points.

    For a :class:`StructureBracket` the derivatives of ``J(w)`` are exact; for the
    Dirac and canonical brackets the inner bracket is differentiated by central
    differences on phase space (expect residuals of order 1e-8, not round-off).
    The residual is relative to ``max(1, |J|)`` at the point.
    """
    worst = 0.0
    for point in points:
        scale = max(1.0, float(np.max(np.abs(bracket.matrix(point)))))
        residual = bracket.jacobiator(point)
        if residual.size:
            worst = max(worst, float(np.max(np.abs(residual))) / scale)
    return worst


def _monomials(symbols: Sequence[sympy.Symbol], degree: int) -> list[sympy.Expr]:
    result: list[sympy.Expr] = []
    for d in range(1, degree + 1):
        for combo in itertools.combinations_with_replacement(symbols, d):
            result.append(sympy.Mul(*combo))
    return result


def casimirs(bracket: StructureBracket, degree: int = 2) -> list[sympy.Expr]:
    """Polynomial Casimirs of a linear (Lie–Poisson) structure, up to ``degree``.

    A Casimir ``C`` has ``{w_a, C} = sum_b J_ab(w) dC/dw_b = 0`` for every ``a``. With
    ``C`` a general polynomial without constant term, these are linear equations for
    its coefficients; the returned polynomials are a basis of their solutions (exact
    rational arithmetic). For so(3) the result is ``[M_1**2 + M_2**2 + M_3**2]``; for
    the Chetaev bracket, the six entries of ``R R^T`` (the rows' lengths and mutual
    scalar products).

    Raises
    ------
    InputError
        If the structure is not linear in the variables.
    """
    if not isinstance(bracket, StructureBracket) or not bracket.is_linear:
        raise InputError(f"bracket {bracket.name!r} is not a linear Poisson structure: Casimirs are found only for those")
    if degree < 1:
        raise InputError(f"degree = {degree}: give a degree >= 1")
    w = bracket.w
    monomials = _monomials(w, degree)
    coefficients = sympy.symbols(f"c_0:{len(monomials)}")
    candidate = sum(c * mono for c, mono in zip(coefficients, monomials))
    equations = []
    for a in range(len(w)):
        condition = sympy.expand(sum(bracket.structure[a, b] * sympy.diff(candidate, w[b]) for b in range(len(w))))
        if condition != 0:
            equations.extend(sympy.Poly(condition, *w).coeffs())
    if not equations:
        return list(monomials)
    A, _ = sympy.linear_eq_to_matrix(equations, coefficients)
    basis = A.nullspace()
    result = []
    for vector in basis:
        vector = vector / max((abs(v) for v in vector if v != 0), default=1)
        result.append(sympy.expand(sum(v * mono for v, mono in zip(vector, monomials))))
    return result
