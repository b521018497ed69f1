"""Special parameter values: where a rank the analysis used drops.

The analysis keeps its parameters symbolic and decides ranks at generic random values
(:func:`dirac.analysis.constraint_analysis._generic_parameter_values`). At particular
values the structure can change: the Proca-type Lagrangian
``1/2 (A1_dot - A0)^2 - M^2/2 (A1^2 - A0^2)`` has two second-class constraints for
``M != 0`` and two first-class ones at ``M = 0``. A rank ``r`` of a matrix ``X`` (the
Hessian ``W``, the block ``A_PQ = {Phi_P, phi_Q}`` of the consistency conditions that fixes
multipliers (213)-(215), the second-class block of ``C_ab = {Phi_a, Phi_b}`` (240)) was
read from an invertible ``r x r`` block ``B``; where ``det B`` vanishes the rank may drop.
Writing ``det B`` (its numerator) as a polynomial in the phase-space variables, the
factors of the gcd of its coefficients (its content) depend on the parameters alone
(found as the gcd of ``det B`` at two random rational points); their zeros are the
candidates, each checked by evaluating the rank again with the
parameter at that value (on points of the surface of the constraints at that value).
Factors that vanish only on the constraint surface are not searched.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import sympy
from sympy.polys.matrices import DomainMatrix

from dirac.analysis.numeric import Numerics, numeric_rank
from dirac.analysis.phase_space import PhaseSpace
from dirac.errors import AnalysisError

__all__ = ["SpecialValue", "special_parameter_values", "MAX_BLOCK"]

#: blocks larger than this are not searched (their determinants are too large)
MAX_BLOCK = 4



@dataclass(frozen=True)
class SpecialValue:
    """A parameter value at which a rank of the analysis drops.

    Attributes
    ----------
    parameter
        The parameter's name.
    value
        The value (a number, or an expression in the other parameters).
    where
        What changes there, e.g. ``"rank of C drops from 2 to 0"`` (several joined by ``"; "``).
    """

    parameter: str
    value: sympy.Expr
    where: str

    def to_json(self) -> dict:
        """``{"parameter": ..., "value": ..., "where": ...}`` (docs/file_formats.md)."""
        return {"parameter": self.parameter, "value": str(self.value), "where": self.where}

    def holds_at(self, values: dict[str, float | None]) -> bool:
        """Whether the parameter values ``values`` (name -> number) lie on this special value."""
        own = values.get(self.parameter)
        if own is None:
            return False
        subs = {}
        for s in self.value.free_symbols:
            given = values.get(s.name)
            if given is None:
                return False
            subs[s] = given
        target = complex(self.value.subs(subs))
        return abs(target.imag) < 1e-12 and abs(own - target.real) <= 1e-12 * (1 + abs(own))


#: returned by :func:`_rank_at` where a denominator of the analysis vanishes
UNDEFINED = -1


@dataclass
class RankUse:
    """One rank decision: ``block`` (square, invertible generically) inside ``matrix`` of generic rank ``rank``."""

    label: str
    block: sympy.Matrix
    matrix: sympy.Matrix
    rank: int
    on_surface: bool


def _numerator_of_determinant(block: sympy.Matrix) -> sympy.Expr:
    """Numerator of ``det block`` for a block whose entries are rational functions of the parameters.

    Computed over the field of rational functions (sympy's ``DomainMatrix``), much faster
    than a sympy determinant followed by ``together``.
    """
    try:
        matrix = DomainMatrix.from_Matrix(block).to_field()
        return sympy.fraction(matrix.domain.to_sympy(matrix.det()))[0]  # reduced in the field already
    except (sympy.PolynomialError, sympy.CoercionFailed, NotImplementedError, ValueError, TypeError):
        return sympy.fraction(sympy.together(block.det(method="berkowitz")))[0]


class NotPolynomial(ValueError):
    """The determinant of a block is not a polynomial in the parameters: no search there."""


def _candidates(block: sympy.Matrix, variables: Sequence[sympy.Symbol], parameters: Sequence[sympy.Symbol], rng: np.random.Generator) -> list[tuple[sympy.Symbol, sympy.Expr]]:
    """Zeros of the parameter-only factors of ``det block`` (the content of its numerator in ``variables``).

    The content is the gcd of the numerators of ``det block`` at two random rational
    points of phase space (a factor common to both by accident is removed by the check
    that follows in :func:`special_parameter_values`).
    """
    params = set(parameters)
    # every symbol that is not a parameter (phase-space variables, and the time t of a
    # time-dependent system) is set to random rationals
    present = sorted(block.free_symbols - params, key=lambda s: s.name)
    numerators = []
    for _ in range(2 if present else 1):
        point = {v: sympy.Rational(int(rng.integers(1, 89)), int(rng.integers(1, 11))) for v in present}
        numerators.append(_numerator_of_determinant(block.xreplace(point)))
        if not numerators[-1].free_symbols & params:
            return []  # free of parameters at one point: no parameter-only factor anywhere
    found: list[tuple[sympy.Symbol, sympy.Expr]] = []
    try:
        content = numerators[0] if len(numerators) == 1 else sympy.gcd(numerators[0], numerators[1])
        if content == 0:
            return found
        factors = sympy.factor_list(content)[1]
    except (sympy.PolynomialError, sympy.CoercionFailed, NotImplementedError):
        raise NotPolynomial(f"det of the {block.shape[0]}x{block.shape[0]} block is not polynomial in the parameters") from None
    for factor, _ in factors:
        if not factor.free_symbols or not factor.free_symbols <= params:
            continue
        for p in sorted(factor.free_symbols, key=lambda s: s.name):
            for value in sympy.solve(factor, p):
                if value.is_real is not False and (p, value) not in found:
                    found.append((p, value))
    return found


def special_parameter_values(
    space: PhaseSpace,
    generic: dict[sympy.Symbol, float],
    uses: Sequence[RankUse],
    constraints_at: Callable[[dict], list[sympy.Expr]],
    seed: int = 20240607,
    time: sympy.Symbol | None = None,
) -> tuple[list[SpecialValue], list[str]]:
    """The special parameter values of the rank decisions ``uses``, checked numerically.

    Parameters
    ----------
    space
        The phase space (its parameters are the symbolic ones).
    generic
        The generic parameter values the analysis used.
    uses
        The rank decisions (:class:`RankUse`).
    constraints_at
        ``substitution -> constraints`` (the constraints, reducible ones included, with
        the parameter substituted): where the ranks on the surface are evaluated again.
    time
        The time ``t`` of a time-dependent system (sampled like a variable), else ``None``.

    Returns
    -------
    (list of SpecialValue, list of str)
        The special values, and notes on blocks that were too large to search.
    """
    parameters = list(space.parameters)
    if not parameters:
        return [], []
    rng = np.random.default_rng(seed)
    found: dict[tuple[str, str], list[str]] = {}
    values: dict[tuple[str, str], sympy.Expr] = {}
    notes: list[str] = []
    for use in uses:
        if use.rank == 0 or not (use.block.free_symbols & set(parameters)):
            continue
        if use.block.shape[0] > MAX_BLOCK:
            notes.append(
                f"special parameter values: not searched in the {use.label} (its {use.block.shape[0]}x"
                f"{use.block.shape[0]} block is too large for a symbolic determinant)"
            )
            continue
        try:
            candidates = _candidates(use.block, space.variables, parameters, rng)
        except NotPolynomial as exc:
            notes.append(f"special parameter values: not searched in the {use.label}: {exc}")
            continue
        for p, value in candidates:
            at = _rank_at(space, generic, use, {p: value}, constraints_at, seed, time)
            if at == UNDEFINED or (at is not None and at >= use.rank):
                continue
            change = f"rank of the {use.label} drops from {use.rank} to {at}" if at is not None else (
                f"the {use.label} block is singular (no point of the constraint surface found there)"
            )
            key = (p.name, str(value))
            values[key] = value
            found.setdefault(key, [])
            if change not in found[key]:
                found[key].append(change)
    return [SpecialValue(name, values[(name, text)], "; ".join(w)) for (name, text), w in found.items()], notes


def _rank_at(
    space: PhaseSpace,
    generic: dict[sympy.Symbol, float],
    use: RankUse,
    substitution: dict[sympy.Symbol, sympy.Expr],
    constraints_at: Callable[[dict], list[sympy.Expr]],
    seed: int,
    time: sympy.Symbol | None = None,
) -> int | None:
    """Rank of ``use.matrix`` with ``substitution``, at points of the surface there (None: no point found)."""
    numbers = dict(generic)
    for p, value in substitution.items():
        numbers[p] = float(sympy.re(value.subs(generic)))
    matrix = use.matrix.subs(substitution)
    constraints = constraints_at(substitution) if use.on_surface else []
    if any(e.has(sympy.zoo, sympy.nan, sympy.oo, -sympy.oo) for e in [*matrix, *constraints]):
        return UNDEFINED  # a denominator vanishes: the expressions are undefined there, not of lower rank
    if not use.on_surface and not matrix.subs(numbers).free_symbols:  # constant in phase space (and time)
        return numeric_rank(np.array(matrix.subs(numbers).evalf(), dtype=float))
    numerics = Numerics(space, numbers, seed=seed, time=time)
    if use.on_surface:
        try:
            points = numerics.surface_points(constraints, 4, attempts=20)
        except AnalysisError:
            return None
    else:
        points = [numerics.random_point() for _ in range(4)]
    if matrix.shape[0] == 0 or matrix.shape[1] == 0:
        return 0
    values = numerics.evaluate(list(matrix), points).reshape(len(points), *matrix.shape)
    ranks = [numeric_rank(v) if np.all(np.isfinite(v)) else use.rank for v in values]
    return max(set(ranks), key=ranks.count)
