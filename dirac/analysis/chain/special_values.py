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
from dataclasses import dataclass, replace

import numpy as np
import sympy
from sympy.polys.matrices import DomainMatrix

from dirac.analysis.core.numeric import ZERO_TOLERANCE, Numerics, numeric_rank
from dirac.analysis.core.phase_space import PhaseSpace
from dirac.errors import AnalysisError

__all__ = ["SpecialValue", "special_parameter_values", "MAX_BLOCK"]

#: blocks larger than this are not searched (their determinants are too large)
MAX_BLOCK = 4



@dataclass(frozen=True)
class SpecialValue:
    """A parameter value (or a curve of values) at which a rank of the analysis drops.

    Attributes
    ----------
    parameter
        The parameter's name.
    value
        The value (a number, or an expression in the other parameters).
    where
        What changes there, e.g. ``"rank of C drops from 2 to 0"`` (several joined by ``"; "``).
    factor
        The polynomial in the parameters whose zero set this is (``b - a**2`` for the curve
        ``b = a**2``, whose two branches ``a = +-sqrt(b)`` it also contains); ``None``: the
        set is ``parameter - value = 0``.
    """

    parameter: str
    value: sympy.Expr
    where: str
    factor: sympy.Expr | None = None

    def _symbol(self) -> sympy.Symbol:
        """The parameter's symbol (with the assumptions it has in the factor)."""
        inside = self.factor.free_symbols if self.factor is not None else set()
        return next((s for s in inside if s.name == self.parameter), sympy.Symbol(self.parameter))

    @property
    def is_curve(self) -> bool:
        """Whether the set involves several parameters (a curve or surface of values)."""
        expr = self.factor if self.factor is not None else self.value
        return any(s.name != self.parameter for s in expr.free_symbols)

    @property
    def equation(self) -> str:
        """The set as an equation, e.g. ``"M = 0"`` or ``"b - a**2 = 0"``."""
        own = self._symbol()
        if self.factor is None or not self.is_curve or sympy.degree(self.factor, own) == 1:
            return _equation(own, self.value)
        return f"{self.factor} = 0"

    def to_json(self) -> dict:
        """``{"parameter": ..., "value": ..., "equation": ..., "where": ...}`` (docs/file_formats.md)."""
        return {"parameter": self.parameter, "value": str(self.value), "equation": self.equation, "where": self.where}

    def holds_at(self, values: dict[str, float | None]) -> bool:
        """Whether the parameter values ``values`` (name -> number) lie on this set.

        On a curve ``f = 0`` the test is ``|f| <= 1e-12 (1 + sum |terms of f|)`` at the
        values, so that both branches (``a = +-sqrt(b)`` of ``b - a**2``) count.
        """
        own = values.get(self.parameter)
        if own is None:
            return False
        if self.factor is not None and self.is_curve:
            subs = {}
            for sym in self.factor.free_symbols:
                given = values.get(sym.name)
                if given is None:
                    return False
                subs[sym] = given
            expanded = sympy.expand(self.factor)
            terms = expanded.args if isinstance(expanded, sympy.Add) else (expanded,)
            size = 1 + sum(abs(complex(t.subs(subs))) for t in terms)
            return abs(complex(expanded.subs(subs))) <= 1e-12 * size
        subs = {}
        for s in self.value.free_symbols:
            given = values.get(s.name)
            if given is None:
                return False
            subs[s] = given
        target = complex(self.value.subs(subs))
        return abs(target.imag) < 1e-12 and abs(own - target.real) <= 1e-12 * (1 + abs(own))


def _equation(parameter: sympy.Symbol, value: sympy.Expr) -> str:
    """``parameter - value = 0`` written with the parameter first (``"b - a**2 = 0"``, ``"M = 0"``)."""
    if value == 0:
        return f"{parameter} = 0"
    rest = str(-value)
    return f"{parameter} - {rest[1:]} = 0" if rest.startswith("-") else f"{parameter} + {rest} = 0"


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


def _candidates(
    block: sympy.Matrix, variables: Sequence[sympy.Symbol], parameters: Sequence[sympy.Symbol], rng: np.random.Generator
) -> list[tuple[sympy.Expr, list[tuple[sympy.Symbol, sympy.Expr]]]]:
    """Zeros of the parameter-only factors of ``det block`` (the content of its numerator in ``variables``).

    The content is the gcd of the numerators of ``det block`` at two random rational
    points of phase space (a factor common to both by accident is removed by the check
    that follows in :func:`special_parameter_values`).

    Returns
    -------
    list of (factor, list of (parameter, value))
        Each irreducible factor ``f`` with the solutions that describe ``f = 0``: the one
        solution ``p = g(others)`` for a parameter in which ``f`` is linear with a constant
        coefficient (``b = a**2`` for ``f = a**2 - b``: the whole curve, both branches
        ``a = +-sqrt(b)``), else every solution for every parameter of ``f``.
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
    found: list[tuple[sympy.Expr, list[tuple[sympy.Symbol, sympy.Expr]]]] = []
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
        names = sorted(factor.free_symbols, key=lambda s: s.name)
        linear = [p for p in names if sympy.degree(factor, p) == 1 and not sympy.diff(factor, p).free_symbols]
        solutions: list[tuple[sympy.Symbol, sympy.Expr]] = []
        for p in linear[-1:] or names:
            for value in sympy.solve(factor, p):
                if value.is_real is not False and (p, value) not in solutions:
                    solutions.append((p, value))
        if solutions:
            found.append((factor, solutions))
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
    found: dict[str, list[str]] = {}
    values: dict[str, SpecialValue] = {}
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
        for factor, solutions in candidates:
            curve = len(factor.free_symbols) > 1
            for p, value in solutions:
                at = _rank_at(space, generic, use, {p: value}, constraints_at, seed, time)
                if at == UNDEFINED or (at is not None and at >= use.rank):
                    continue
                change = f"rank of the {use.label} drops from {use.rank} to {at}" if at is not None else (
                    f"the {use.label} block is singular (no point of the constraint surface found there)"
                )
                # a curve is one set (its first branch that drops stands for it); values are one set each
                key = SpecialValue(p.name, value, "", factor if curve else None).equation
                if key not in values:
                    values[key] = SpecialValue(p.name, value, "", factor if curve else None)
                found.setdefault(key, [])
                if change not in found[key]:
                    found[key].append(change)
                if curve:
                    break
    return [replace(values[key], where="; ".join(w)) for key, w in found.items()], notes


def _exact_zeros(matrix: sympy.Matrix) -> sympy.Matrix:
    """``matrix`` with every entry that is exactly zero (after expansion over a common denominator) set to 0.

    After a substitution such as ``b = a**2`` an entry like ``a*(a - 1) + a - b`` is the
    zero polynomial ``a*(a - 1) + a - a**2``, but evaluated in floating point it leaves
    round-off (``1e-16``): decided exactly here, it is 0. Entries too large to expand
    cheaply (more than ``EXACT_OPS`` operations) are left to the numeric test.
    """

    def reduce(entry: sympy.Expr) -> sympy.Expr:
        if entry == 0 or sympy.count_ops(entry) > EXACT_OPS:
            return entry
        try:
            numerator = sympy.expand(sympy.fraction(sympy.together(entry))[0])
        except (sympy.PolynomialError, NotImplementedError, TypeError):
            return entry
        return sympy.S.Zero if numerator == 0 else entry

    return matrix.applyfunc(reduce)


#: entries with more operations than this are not expanded by :func:`_exact_zeros`
EXACT_OPS = 400


def _constant_rank(matrix: sympy.Matrix, numbers: dict[sympy.Symbol, float]) -> int:
    """Rank of a matrix that depends on the parameters only, with the same zero test as :func:`_rank_at`."""
    values = np.zeros(len(matrix))
    scales = np.ones(len(matrix))
    for k, entry in enumerate(matrix):
        terms = entry.args if isinstance(entry, sympy.Add) else (entry,)
        values[k] = float(sympy.re(entry.subs(numbers)))
        scales[k] += sum(abs(complex(t.subs(numbers))) for t in terms)
    values = np.where(np.abs(values) <= ZERO_TOLERANCE * scales, 0.0, values)
    return numeric_rank(values.reshape(matrix.shape), scale=float(np.max(scales)))


def _rank_at(
    space: PhaseSpace,
    generic: dict[sympy.Symbol, float],
    use: RankUse,
    substitution: dict[sympy.Symbol, sympy.Expr],
    constraints_at: Callable[[dict], list[sympy.Expr]],
    seed: int,
    time: sympy.Symbol | None = None,
) -> int | None:
    """Rank of ``use.matrix`` with ``substitution``, at points of the surface there (None: no point found).

    Round-off is never counted as rank: entries that are exactly zero after the
    substitution are set to 0 (:func:`_exact_zeros`); the others count as zero where they
    are below ``ZERO_TOLERANCE`` times the size of their terms (the terms that cancelled,
    :meth:`~dirac.analysis.core.numeric.Numerics.term_scale`), and the singular-value cut of
    :func:`~dirac.analysis.core.numeric.numeric_rank` is relative to the largest term size too.
    """
    numbers = dict(generic)
    for p, value in substitution.items():
        numbers[p] = float(sympy.re(value.subs(generic)))
    matrix = use.matrix.subs(substitution)
    constraints = constraints_at(substitution) if use.on_surface else []
    if any(e.has(sympy.zoo, sympy.nan, sympy.oo, -sympy.oo) for e in [*matrix, *constraints]):
        return UNDEFINED  # a denominator vanishes: the expressions are undefined there, not of lower rank
    if matrix.shape[0] == 0 or matrix.shape[1] == 0:
        return 0
    matrix = _exact_zeros(matrix)
    if not use.on_surface and not matrix.subs(numbers).free_symbols:  # constant in phase space (and time)
        return _constant_rank(matrix, numbers)
    numerics = Numerics(space, numbers, seed=seed, time=time)
    if use.on_surface:
        try:
            points = numerics.surface_points(constraints, 4, attempts=20)
        except AnalysisError:
            return None
    else:
        points = [numerics.random_point() for _ in range(4)]
    entries = list(matrix)
    values = numerics.evaluate(entries, points)
    scales = numerics.term_scale(entries, points)
    ranks = []
    for v, sc in zip(values, scales):
        if not np.all(np.isfinite(v)):
            ranks.append(use.rank)
            continue
        v = np.where(np.abs(v) <= ZERO_TOLERANCE * sc, 0.0, v).reshape(matrix.shape)
        ranks.append(numeric_rank(v, scale=float(np.max(sc))))
    return max(set(ranks), key=ranks.count)
