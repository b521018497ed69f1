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

The ranks searched are those of every stage, not only the last one's: each stage that
added constraints fixed multipliers with its own block of ``{Phi_a, phi_k}`` over the
constraints known then (:attr:`~dirac.analysis.chain.constraint_chain.ConstraintChain.stage_pivots`),
decided on that stage's surface (:attr:`RankUse.surface`). Where that block's rank drops the
chain goes another way from there on: in Fierz-Pauli the mass term gives the secondaries of
``h0i`` a bracket with the primaries, so stage 2 fixes their multipliers and the chain goes
on to stages 3 and 4; at ``m = 0`` that block vanishes, the chain stops at stage 2 and the
theory is linearised Einstein (8 first class instead of 10 second class). Blocks larger
than :data:`MAX_BLOCK` are scanned numerically at :data:`SCAN_VALUES` (with a note), not skipped.

Entries with radicals (``sqrt(c**2 m**2 + p**2)`` of a relativistic particle) are not
handed to sympy's domain of arbitrary expressions, where a 4 x 4 determinant takes
minutes: each radical becomes a new symbol with its defining relation, removed again by a
resultant (:func:`_radical_free_numerator`). The whole symbolic search has a CPU-time
budget (:data:`SEARCH_SECONDS`); a block it cuts is scanned numerically at the simple
values :data:`SCAN_VALUES` instead, and a note says what was not searched.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import sympy
from sympy.polys.matrices import DomainMatrix

from dirac.analysis.core.algebra import rational_parts
from dirac.analysis.core.budget import CpuBudget, OverBudget
from dirac.analysis.core.numeric import ZERO_TOLERANCE, Numerics, numeric_rank
from dirac.analysis.core.phase_space import PhaseSpace, free_symbols_of
from dirac.codegen.printer import distinct_nodes
from dirac.errors import AnalysisError

__all__ = ["SpecialValue", "admissible", "special_parameter_values", "MAX_BLOCK", "SEARCH_SECONDS", "SCAN_SECONDS", "SCAN_VALUES"]

#: blocks larger than this are not searched symbolically (their determinants are too large): they are scanned
#: numerically at :data:`SCAN_VALUES` instead (:func:`_scan`)
MAX_BLOCK = 4

#: CPU seconds the symbolic search of all the blocks of one analysis may take (:func:`special_parameter_values`)
SEARCH_SECONDS = 2.0

#: CPU seconds of the numeric scan of the blocks whose symbolic search ran over SEARCH_SECONDS
SCAN_SECONDS = 1.0

#: points of the surface at which the numeric scan reads each rank (the rank most of them give counts)
SCAN_POINTS = 4

#: the values each parameter of a block is set to, one at a time, by the numeric scan
SCAN_VALUES = tuple(sympy.Rational(v) for v in ("0", "1", "-1", "2", "-2", "1/2", "-1/2"))


def admissible(parameter: sympy.Symbol, value: sympy.Expr) -> bool:
    """Whether ``parameter = value`` is allowed by the assumptions the parameter was declared with.

    A principal moment declared ``positive=True`` never takes the value 0, so a rank drop
    there is no case of the system; the symbolic road already drops such values (``sympy.solve``
    respects the assumptions), and the numeric scan asks this before evaluating a value.
    """
    checks = (
        (parameter.is_positive, value.is_positive),
        (parameter.is_negative, value.is_negative),
        (parameter.is_nonnegative, value.is_nonnegative),
        (parameter.is_nonpositive, value.is_nonpositive),
        (parameter.is_nonzero, value.is_nonzero),
        (parameter.is_integer, value.is_integer),
    )
    return not any(declared and holds is False for declared, holds in checks)



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
    #: the constraints whose surface the rank was decided on, when not all of them (an earlier stage's surface)
    surface: Sequence[sympy.Expr] | None = None
    #: the free symbols of ``block`` when the caller knows them (a walk of a large block's shared sub-trees is not free)
    symbols: frozenset | None = None
    #: ``matrix`` is a bracket matrix (``C_ba = -C_ab``, zero diagonal): the numeric scan evaluates the entries above
    #: its diagonal only (:mod:`dirac.analysis.core.antisymmetric`)
    antisymmetric: bool = False

    def block_symbols(self) -> frozenset:
        """The free symbols of ``block`` (:func:`~dirac.analysis.core.phase_space.free_symbols_of`)."""
        return self.symbols if self.symbols is not None else free_symbols_of(self.block)

    def constraints(self, constraints_at: Callable[[dict], list[sympy.Expr]], substitution: dict) -> list[sympy.Expr]:
        """The constraints of this decision's surface with ``substitution`` (``[]`` off the surface)."""
        if not self.on_surface:
            return []
        if self.surface is not None:
            return [c.subs(substitution) for c in self.surface]
        return constraints_at(substitution)


def _numerator_of_determinant(block: sympy.Matrix) -> sympy.Expr:
    """Numerator of ``det block`` for a block whose entries are rational functions of the parameters.

    Computed over the field of rational functions (sympy's ``DomainMatrix``), much faster
    than a sympy determinant followed by ``together``. Entries with radicals (the square
    root ``sqrt(c**2 m**2 + p**2)`` of a relativistic particle) go to
    :func:`_radical_free_numerator` instead: over sympy's domain of arbitrary expressions
    (``EX``) a 4 x 4 determinant takes minutes.
    """
    if _radicals(block):
        return _radical_free_numerator(block)
    try:
        matrix = DomainMatrix.from_Matrix(block).to_field()
        return sympy.fraction(matrix.domain.to_sympy(matrix.det()))[0]  # reduced in the field already
    except (sympy.PolynomialError, sympy.CoercionFailed, NotImplementedError, ValueError, TypeError):
        return sympy.fraction(sympy.together(block.det(method="berkowitz")))[0]


def _is_radical(power: sympy.Basic) -> bool:
    """Whether ``power`` is ``base**(p/q)`` with a fraction ``p/q`` (a square root, a cube root)."""
    return isinstance(power, sympy.Pow) and power.exp.is_Rational and not power.exp.is_Integer


def _radicals(matrix: sympy.Matrix) -> set[sympy.Pow]:
    # each shared sub-tree walked once (``atoms`` walks every occurrence: the bracket matrix of a relativistic
    # particle repeats its square root and the sums around it many times)
    return {p for entry in matrix for p in distinct_nodes(entry) if _is_radical(p)}


def _radicals_to_symbols(matrix: sympy.Matrix) -> tuple[sympy.Matrix, list[tuple[sympy.Symbol, int, sympy.Expr]]]:
    """``matrix`` with each radical ``X**(p/q)`` written ``r**(p Q/q)`` for a new symbol ``r`` with ``r**Q = X``.

    The innermost radicals are replaced first, so that nested ones (``sqrt(1 + sqrt(a))``)
    get relations in the symbols of the inner ones. Returns the new matrix and the
    relations ``(r, Q, X)`` in the order they were made (inner first).
    """
    relations: list[tuple[sympy.Symbol, int, sympy.Expr]] = []
    while True:
        found = _radicals(matrix)
        inner = [p for p in found if not any(_is_radical(q) for q in p.base.atoms(sympy.Pow))]
        if not inner:
            return matrix, relations
        by_base: dict[sympy.Expr, list[sympy.Pow]] = {}
        for p in sorted(inner, key=sympy.default_sort_key):
            by_base.setdefault(p.base, []).append(p)
        replace_by: dict[sympy.Expr, sympy.Expr] = {}
        for base, powers in by_base.items():
            order = int(sympy.ilcm(1, *[int(p.exp.q) for p in powers]))
            r = sympy.Dummy(f"r{len(relations)}")
            for p in powers:
                replace_by[p] = r ** int(p.exp * order)
            relations.append((r, order, base))
        matrix = matrix.xreplace(replace_by)
        relations = [(r, order, base.xreplace(replace_by)) for r, order, base in relations]


def _pfaffian(matrix: sympy.Matrix) -> sympy.Expr:
    """Pfaffian of an antisymmetric matrix, ``Pf(A)^2 = det A``, by expansion along the first row."""
    n = matrix.shape[0]
    if n == 0:
        return sympy.S.One
    if n % 2:
        return sympy.S.Zero
    total = sympy.S.Zero
    for j in range(1, n):
        if matrix[0, j] != 0:
            rest = [k for k in range(1, n) if k != j]
            total += (-1) ** (j + 1) * matrix[0, j] * _pfaffian(matrix[rest, rest])
    return total


def _is_antisymmetric(matrix: sympy.Matrix) -> bool:
    n = matrix.shape[0]
    return all(matrix[i, j] == -matrix[j, i] for i in range(n) for j in range(i, n))


def _radical_free_numerator(block: sympy.Matrix) -> sympy.Expr:
    """A polynomial in the parameters that vanishes wherever ``det block`` does, for a block with radicals.

    Each radical ``X**(1/Q)`` is written as a new symbol ``r`` with ``r**Q = X``; the
    determinant (the Pfaffian ``Pf``, ``Pf^2 = det``, of an antisymmetric block such as
    the bracket matrix ``C``: a handful of products instead of a determinant) is then a
    rational function of the parameters and ``r``, computed over an ordinary field of
    rational functions. Its numerator ``N(r)`` is freed of ``r`` by the resultant
    ``Res_r(N(r), den(X) r**Q - num(X))``, the product of ``N`` over every branch ``r``
    of the radical: it vanishes wherever ``N`` vanishes on the principal branch, and
    perhaps on the others too (Cox, Little, O'Shea, *Ideals, Varieties, and Algorithms*,
    Sect. 3.6). The zeros found are candidates only: each is checked numerically
    (:func:`_rank_at`), so a zero of another branch is dropped there.

    Raises
    ------
    NotPolynomial
        When other functions of the parameters (``sin(a)``) remain.
    """
    matrix, relations = _radicals_to_symbols(block)
    try:
        if _is_antisymmetric(matrix):
            numerator = _fraction(_pfaffian(matrix))[0]
        else:
            field = DomainMatrix.from_Matrix(matrix).to_field()
            if field.domain.is_EX or field.domain.is_EXRAW:
                raise NotPolynomial(f"det of the {block.shape[0]}x{block.shape[0]} block is not a rational function of the parameters and its radicals")
            numerator = sympy.fraction(field.domain.to_sympy(field.det()))[0]
        for r, order, base in reversed(relations):  # outer radicals first: their relations may hold inner ones
            num, den = _fraction(base)
            numerator = _resultant(numerator, den * r**order - num, r)
        numerator = sympy.expand(numerator)
    except (sympy.PolynomialError, sympy.CoercionFailed, NotImplementedError, ValueError, TypeError) as exc:
        raise NotPolynomial(f"det of the {block.shape[0]}x{block.shape[0]} block with radicals: {exc}") from None
    if numerator.atoms(sympy.Function) or _radicals(sympy.Matrix([numerator])):
        raise NotPolynomial(f"det of the {block.shape[0]}x{block.shape[0]} block is not a polynomial in the parameters")
    return numerator


def _fraction(expr: sympy.Expr) -> tuple[sympy.Expr, sympy.Expr]:
    """``(N, D)`` with ``expr = N / D`` in lowest terms.

    One walk into the field of rational functions over ``QQ``
    (:func:`~dirac.analysis.core.algebra.rational_parts`), where ``together`` and
    ``cancel`` on the expression tree took three times as long on the relativistic
    particle's bracket matrix; an expression outside that field (a float) goes to them.
    """
    parts = rational_parts(expr) if expr.free_symbols else None
    if parts is None:
        return sympy.fraction(sympy.cancel(sympy.together(expr)))
    return parts


def _resultant(f: sympy.Expr, g: sympy.Expr, r: sympy.Symbol) -> sympy.Expr:
    """``Res_r(f, g)`` of two polynomials, with its rational coefficients cleared.

    Taken on ``Poly`` objects with ``r`` as the main variable (sympy's subresultant
    PRS; Cox, Little, O'Shea, Sect. 3.6), without the expansions and the ``together`` of
    the expression road; with rational coefficients, up to a non-zero rational factor,
    which leaves its zeros alone.
    """
    gens = [r, *sorted((f.free_symbols | g.free_symbols) - {r}, key=lambda s: s.name)]
    resultant = sympy.Poly(f, *gens).resultant(sympy.Poly(g, *gens))
    if not isinstance(resultant, sympy.Poly):
        return sympy.sympify(resultant)
    if resultant.domain.is_QQ or resultant.domain.is_ZZ:
        return resultant.clear_denoms()[1].as_expr()
    return sympy.fraction(sympy.together(resultant.as_expr()))[0]  # floats among the coefficients: as before


def _gcd(f: sympy.Expr, g: sympy.Expr) -> sympy.Expr:
    """``gcd(f, g)`` of two polynomials, taken on ``Poly`` objects in their symbols (a quarter of the time of
    ``sympy.gcd`` on the expressions, which guesses the generators and the domain again)."""
    gens = sorted(f.free_symbols | g.free_symbols, key=lambda s: s.name)
    if not gens:
        return sympy.gcd(f, g)
    return sympy.Poly(f, *gens).gcd(sympy.Poly(g, *gens)).as_expr()


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
        content = numerators[0] if len(numerators) == 1 else _gcd(numerators[0], numerators[1])
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


class _Projections:
    """Surface points found by the scan of one rank decision, handed to the next one that asks for the same.

    The decisions on the final surface (the consistency matrix ``{Phi_a, phi_k}`` and the
    bracket matrix ``C``) are scanned at the same parameter values onto the same
    constraints, each with a :class:`~dirac.analysis.core.numeric.Numerics` of the same
    seed, in the same order: their projections are the same computation. A projection is
    a function of the constraints, the arguments, the parameter values, the held
    variables, the expressions avoided and the state of the random generator; with all of
    these in the key, the points (or the refusal) and the generator's state after the call
    are replayed bit for bit. On (228) the two scans of 21 parameter values each spent
    about half their time projecting.
    """

    def __init__(self) -> None:
        self._found: dict[tuple, tuple[list[np.ndarray] | AnalysisError, Mapping[str, Any]]] = {}

    def surface_points(self, numerics: Numerics, constraints: Sequence[sympy.Expr], count: int, **options: Any) -> list[np.ndarray]:
        """:meth:`Numerics.surface_points` ``(constraints, count, **options)``, or its replay."""
        start = options.get("start")
        key = (
            tuple(constraints), count, tuple(sorted((k, v) for k, v in options.items() if k != "start")),
            None if start is None else np.asarray(start, dtype=float).tobytes(),
            numerics.parameter_vector.tobytes(), numerics.time, tuple(numerics.hold), tuple(numerics.avoid),
            repr(numerics.rng.bit_generator.state),
        )
        hit = self._found.get(key)
        if hit is not None:
            outcome, after = hit
            numerics.rng.bit_generator.state = after
            if isinstance(outcome, AnalysisError):
                raise outcome
            return [z.copy() for z in outcome]
        try:
            points = numerics.surface_points(constraints, count, **options)
        except AnalysisError as error:
            self._found[key] = (error, numerics.rng.bit_generator.state)
            raise
        self._found[key] = ([z.copy() for z in points], numerics.rng.bit_generator.state)
        return points


def special_parameter_values(
    space: PhaseSpace,
    generic: dict[sympy.Symbol, float],
    uses: Sequence[RankUse],
    constraints_at: Callable[[dict], list[sympy.Expr]],
    seed: int = 20240607,
    time: sympy.Symbol | None = None,
    budget: float | None = None,
    scan_budget: float | None = None,
    compiled: Numerics | None = None,
    starts: Sequence[np.ndarray] = (),
) -> tuple[list[SpecialValue], list[str]]:
    """The special parameter values of the rank decisions ``uses``, checked numerically.

    The symbolic search (determinants, their content, its factors, and the numerical
    check of each candidate) runs under a CPU-time budget of ``budget`` seconds for all
    the blocks together (:mod:`dirac.analysis.core.budget`). A block whose search the
    budget cuts takes the numeric road instead: its rank is evaluated with each of its
    parameters in turn at the values :data:`SCAN_VALUES` (the others generic), within
    ``scan_budget`` more seconds, and a note says what was not searched (other values,
    curves such as ``b = a**2``); candidates found but not checked are named in a note too.

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
    budget, scan_budget
        CPU seconds of the symbolic search and of the numeric scan; default
        :data:`SEARCH_SECONDS` and :data:`SCAN_SECONDS`.
    compiled
        The analysis' :class:`~dirac.analysis.core.numeric.Numerics` (its parameters are
        arguments of its compiled functions): the scan evaluates the same matrices and
        constraints at other parameter values without compiling them again.
    starts
        Points of the analysis' constraint surface at the generic values: the scan's
        projections onto the surface at a scanned value start from them (a few
        Gauss-Newton steps instead of a projection from a random point), random starts
        fill in where one does not converge.

    Returns
    -------
    (list of SpecialValue, list of str)
        The special values, and notes on what was not searched (blocks too large, over
        the budget, not polynomial).
    """
    parameters = list(space.parameters)
    if not parameters:
        return [], []
    rng = np.random.default_rng(seed)
    found: dict[str, list[str]] = {}
    values: dict[str, SpecialValue] = {}
    notes: list[str] = []
    clock = CpuBudget(SEARCH_SECONDS if budget is None else budget)
    projections = _Projections()  # the decisions on one surface project onto it at the same values: once

    def record(use: RankUse, p: sympy.Symbol, value: sympy.Expr, at: int | None, curve_factor: sympy.Expr | None) -> None:
        change = f"rank of the {use.label} drops from {use.rank} to {at}" if at is not None else (
            f"the {use.label} block is singular (no point of the constraint surface found there)"
        )
        # a curve is one set (its first branch that drops stands for it); values are one set each
        key = SpecialValue(p.name, value, "", curve_factor).equation
        if key not in values:
            values[key] = SpecialValue(p.name, value, "", curve_factor)
        found.setdefault(key, [])
        if change not in found[key]:
            found[key].append(change)

    cut: list[RankUse] = []
    large: list[RankUse] = []
    for use in uses:
        if use.rank == 0 or not (use.block_symbols() & set(parameters)):
            continue
        if use.block.shape[0] > MAX_BLOCK:
            large.append(use)  # too large for a symbolic determinant: the numeric road
            continue
        try:
            with clock.interrupting():
                candidates = _candidates(use.block, space.variables, parameters, rng)
        except NotPolynomial as exc:
            notes.append(f"special parameter values: not searched in the {use.label}: {exc}")
            continue
        except OverBudget:
            cut.append(use)
            continue
        unchecked: list[str] = []
        for factor, solutions in candidates:
            curve = len(factor.free_symbols) > 1
            for p, value in solutions:
                try:
                    with clock.interrupting():
                        at = _rank_at(space, generic, use, {p: value}, constraints_at, seed, time, projections)
                except OverBudget:
                    unchecked.append(f"{factor} = 0" if curve else _equation(p, value))
                    continue
                if at == UNDEFINED or (at is not None and at >= use.rank):
                    continue
                record(use, p, value, at, factor if curve else None)
                if curve:
                    break
        if unchecked:
            notes.append(
                f"special parameter values: candidates of the {use.label} not checked (the search ran over its "
                f"budget of {clock.seconds:g} s CPU): {', '.join(dict.fromkeys(unchecked))}; the rank may drop there"
            )
    if cut or large:
        scan = CpuBudget(SCAN_SECONDS if scan_budget is None else scan_budget)
        for use in cut:
            why = f"the symbolic search in the {use.label} ran over its budget of {clock.seconds:g} s CPU and was not finished"
            notes.append(_scan(space, generic, use, constraints_at, seed, time, why, scan, record, compiled, starts, projections))
        for use in large:
            n = use.block.shape[0]
            why = f"the {use.label} was not searched symbolically (its {n}x{n} block is larger than {MAX_BLOCK}x{MAX_BLOCK})"
            notes.append(_scan(space, generic, use, constraints_at, seed, time, why, scan, record, compiled, starts, projections))
    return [replace(values[key], where="; ".join(w)) for key, w in found.items()], notes


class _Scanner:
    """Ranks of one matrix at numeric parameter values, its expressions compiled once.

    The parameters stay arguments of the compiled functions
    (:class:`~dirac.analysis.core.numeric.Numerics` takes them as a vector), so that each
    value scanned costs a few evaluations and a Gauss-Newton projection onto the surface,
    not a substitution and a compilation.
    """

    def __init__(self, space: PhaseSpace, generic: dict[sympy.Symbol, float], use: RankUse,
                 constraints: list[sympy.Expr], seed: int, time: sympy.Symbol | None,
                 compiled: Numerics | None = None, starts: Sequence[np.ndarray] = (),
                 projections: _Projections | None = None) -> None:
        self.space, self.generic, self.use, self.constraints = space, generic, use, constraints
        self.projections = _Projections() if projections is None else projections
        self.seed, self.time = seed, time
        self.starts = list(starts)[:SCAN_POINTS]
        self.entries = list(use.matrix)
        self.numerics = (Numerics(space, generic, seed=seed, time=time) if compiled is None
                         else compiled.sharing_compiled(generic, seed))
        #: the positions above the diagonal, whose entries alone are evaluated for an antisymmetric matrix
        self.upper: tuple[np.ndarray, np.ndarray] | None = None
        k, columns = use.matrix.shape
        if use.antisymmetric and k == columns and all(use.matrix[i, i] == 0 for i in range(k)):
            self.upper = np.triu_indices(k, 1)

    def _values(self, points: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        """The term sizes and the values of the matrix's entries at ``points`` (rows: points; entries in row-major order).

        For an antisymmetric matrix the entries above the diagonal are evaluated, and those
        below are their mirrors negated with their mirrors' sizes; the diagonal's zeros
        have size 1 and value 0, as :meth:`~dirac.analysis.core.numeric.Numerics.term_scale`
        and :meth:`~dirac.analysis.core.numeric.Numerics.evaluate` give them for a zero.
        """
        numerics = self.numerics
        if self.upper is None:
            scales = numerics.term_scale(self.entries, points)  # first: the values below come with the sizes
            return scales, numerics.evaluate(self.entries, points)
        matrix = self.use.matrix
        rows, cols = self.upper
        above = [matrix[int(i), int(j)] for i, j in zip(rows, cols)]
        upper_scales = numerics.term_scale(above, points)  # first: the values below come with the sizes
        upper_values = numerics.evaluate(above, points)
        k = matrix.shape[0]
        scales = np.ones((len(points), k, k))
        values = np.zeros((len(points), k, k))
        scales[:, rows, cols] = upper_scales
        scales[:, cols, rows] = upper_scales
        values[:, rows, cols] = upper_values
        values[:, cols, rows] = -upper_values
        return scales.reshape(len(points), k * k), values.reshape(len(points), k * k)

    def rank(self, p: sympy.Symbol, value: float) -> int | None:
        """Rank with ``p = value`` (others generic); ``UNDEFINED`` where the entries are not finite; None: no surface point."""
        numerics = self.numerics
        numerics.parameter_vector = np.array([value if q == p else float(self.generic[q]) for q in numerics.parameters])
        if self.use.on_surface:
            points = []
            project = self.projections.surface_points
            for start in self.starts:  # from the generic surface: the surface at this value is near (or empty)
                try:
                    points += project(numerics, self.constraints, 1, attempts=1, start=start)
                except AnalysisError:
                    continue
            try:
                points += project(numerics, self.constraints, SCAN_POINTS - len(points), attempts=20) if len(points) < SCAN_POINTS else []
            except AnalysisError:
                return None
        else:
            points = [numerics.random_point() for _ in range(SCAN_POINTS)]
        scales, values = self._values(points)
        ranks = []
        for v, sc in zip(values, scales):
            if not (np.all(np.isfinite(v)) and np.all(np.isfinite(sc))):
                return UNDEFINED  # a denominator vanishes there
            v = np.where(np.abs(v) <= ZERO_TOLERANCE * sc, 0.0, v).reshape(self.use.matrix.shape)
            ranks.append(numeric_rank(v, scale=float(np.max(sc))))
        return max(set(ranks), key=ranks.count)


def _scan(
    space: PhaseSpace,
    generic: dict[sympy.Symbol, float],
    use: RankUse,
    constraints_at: Callable[[dict], list[sympy.Expr]],
    seed: int,
    time: sympy.Symbol | None,
    why: str,
    scan: CpuBudget,
    record: Callable[[RankUse, sympy.Symbol, sympy.Expr, int | None, sympy.Expr | None], None],
    compiled: Numerics | None = None,
    starts: Sequence[np.ndarray] = (),
    projections: _Projections | None = None,
) -> str:
    """The numeric road of a block not searched symbolically (over the budget, or too large); returns the note.

    The rank of ``use.matrix`` is evaluated with one parameter of the block at a time set
    to each of :data:`SCAN_VALUES` (the other parameters at their generic values); a drop
    is recorded as a special value. Only these values are searched.
    """
    params = sorted(use.block_symbols() & set(space.parameters), key=lambda s: s.name)
    scanned: list[str] = []
    left_out: list[str] = []
    scanner = _Scanner(space, generic, use, use.constraints(constraints_at, {}), seed, time, compiled, starts, projections)
    for p in params:
        done = True
        for value in (v for v in SCAN_VALUES if admissible(p, v)):
            try:
                with scan.interrupting():
                    at = scanner.rank(p, float(value))
            except OverBudget:
                done = False
                break
            if at != UNDEFINED and (at is None or at < use.rank):
                record(use, p, value, at, None)
        (scanned if done else left_out).append(p.name)
    shown = ", ".join(str(v) for v in SCAN_VALUES)
    note = (
        f"special parameter values: {why}; scanned numerically instead: "
        + (f"{', '.join(scanned)} at {shown} (one at a time, the others generic; values a parameter's declared "
           "assumptions exclude, such as 0 for a positive one, left out)" if scanned else "nothing")
        + "; other values and curves of several parameters (such as b = a**2) were not searched"
    )
    if left_out:
        note += f"; not scanned (the scan's budget of {scan.seconds:g} s CPU ran out): {', '.join(left_out)}"
    return note


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
    projections: _Projections | None = None,
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
    constraints = use.constraints(constraints_at, substitution)
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
            points = (projections or _Projections()).surface_points(numerics, constraints, 4, attempts=20)
        except AnalysisError:
            return None
    else:
        points = [numerics.random_point() for _ in range(4)]
    entries = list(matrix)
    scales = numerics.term_scale(entries, points)  # first: the values below come with the sizes
    values = numerics.evaluate(entries, points)
    ranks = []
    for v, sc in zip(values, scales):
        if not np.all(np.isfinite(v)):
            ranks.append(use.rank)
            continue
        v = np.where(np.abs(v) <= ZERO_TOLERANCE * sc, 0.0, v).reshape(matrix.shape)
        ranks.append(numeric_rank(v, scale=float(np.max(sc))))
    return max(set(ranks), key=ranks.count)
