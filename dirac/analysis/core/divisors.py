"""Divisions the analysis makes, and the loci of the constraint surface where they divide by zero.

The analysis divides by phase-space functions in several places: it solves the
velocities from the Hessian ``W = d^2 L / dq_dot^2`` (the Legendre map divides by
``det W``), it eliminates multipliers from the consistency conditions
``b_a + A_ak u_k ≈ 0`` ((210), (213)-(215)) and solves them, ``u = U + v_a V_a``
(Henneaux–Teitelboim (1.32)), and it inverts the bracket matrix ``C`` in the Dirac
bracket (240). Each division is exact only where its divisor does not vanish. An
irreducible factor ``f`` of a divisor is one of two kinds on the constraint surface
``S`` (Henneaux–Teitelboim, Sect. 1.1.2, regularity; Sundermeyer, "Constrained
Dynamics", Sect. 4.3 on points where ranks change):

* ``f`` vanishes on a whole part of the set where the consistency conditions can hold:
  the division lost a branch. The constraint chain works fraction-free there (the new
  constraint keeps the factor, :meth:`~dirac.analysis.chain.constraint_chain.ConstraintChain`),
  so the branch is followed or refused like any product constraint;
* ``f = 0`` meets ``S`` in a lower-dimensional locus: a *singular locus*, where the
  expressions of the analysis (the multipliers, the velocities) divide by zero. It is
  reported (:class:`SingularLocus`), never passed over.

:func:`singular_loci` first asks for a proof that a divisor never vanishes on ``S``:
an exact identity ``f = c + sum a_i phi_i`` with a constant ``c != 0``
(:func:`constant_on_surface`), or ``f = c det M`` with a Gram matrix ``M^T M`` constant on
``S`` and of nonzero determinant, so that ``f^2`` is a nonzero constant there
(:func:`square_on_surface`: ``det R = +-1`` on ``R^T R = 1``), or a numerator that is a principal
minor of the Gram matrix ``J W J^T`` of the holonomic constraints, a sum of squares with weights
of one sign by the Cauchy–Binet formula (:mod:`dirac.analysis.core.gram_proof`, given to
:func:`singular_loci` by the caller). Without a proof it tests the
divisor by sampling: a Gauss–Newton projection onto ``S`` and ``f = 0`` together
(:meth:`~dirac.analysis.core.numeric.Numerics.surface_points`) finds a point of the
locus, or shows none nearby in its attempts.

An expression too long to factor (over ``DIVISOR_TEXT_LIMIT`` characters: the multiplier
solutions of the rigid body's (228) and (19), nested eliminations) is not passed over: its
divisors as written are the bases of its negative powers, read off its graph
(:func:`structural_divisors`), and each is proven nonzero on the surface (the proofs
above, or node by node from parts constant there, :func:`value_on_surface`), found to
vanish at a point of it (for the multiplier solution, a pivot of the elimination where
the block it inverts is regular is a locus of the solved form only, :data:`PIVOT_SINGULAR`),
or left open with the reason (:class:`Undecided`): no point found is no proof.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from collections.abc import Set as AbstractSet
from dataclasses import dataclass
from math import factorial

import numpy as np
import sympy
from sympy.polys.matrices import DomainMatrix
from sympy.polys.polyerrors import BasePolynomialError

from dirac.analysis.core.algebra import printed, prints_shorter, rational_parts
from dirac.analysis.core.budget import cpu_clock
from dirac.analysis.core.phase_space import free_symbols_of
from dirac.analysis.core.pythagoras import pythagorean_form
from dirac.errors import AnalysisError

__all__ = [
    "Division", "SingularLocus", "Unsearched", "Undecided", "too_long_to_search", "structural_divisors", "value_on_surface", "denominator_factors", "singular_loci",
    "constant_on_surface", "square_on_surface", "determinant_grid", "nonvanishing_on", "pfaffian",
    "sum_of_squares_on_surface", "GramVerdict", "LEGENDRE_SINGULAR",
    "MULTIPLIERS_SINGULAR",
]

#: expressions longer than this (characters) are not searched for denominators (a gcd of large ones costs more than the analysis)
DIVISOR_TEXT_LIMIT = 4000

#: a trigonometric factor with at most this many terms is reduced with Pythagoras (``sin(x)**2 + cos(x)**2`` is no divisor)
TRIG_TERMS = 8

#: projections onto a locus tried before it counts as not meeting the surface
LOCUS_ATTEMPTS = 8

#: what happens on the locus of a divisor of the Legendre map
LEGENDRE_SINGULAR = (
    "the Legendre map is singular (det W = 0, W = d^2 L/dq_dot^2, or for a singular Lagrangian the rank of W "
    "drops below its generic rank): the velocities and H_c divide by zero there and the analysis holds off the "
    "locus; a coordinate singularity (sin(theta) = 0 of Euler or polar angles) is cured by another chart "
    "(Cartesian coordinates with a constraint, or a rotation matrix for a rigid body), otherwise the system on "
    "the locus is another system: analyse it with the locus as a constraint"
)
#: what happens on the locus of a divisor of the multiplier solution
MULTIPLIERS_SINGULAR = "the multiplier solution divides by zero"
#: what happens on the locus of a pivot of the multiplier solution's elimination where the solved matrix is regular
PIVOT_SINGULAR = (
    "the multiplier solution as written divides by zero (a pivot of the elimination that solved it); the block "
    "A_PQ of the consistency conditions it inverts is regular at the point of the locus where it was checked, so "
    "the multipliers are finite at that point: there the division is one of the solved form, not of the "
    "multipliers (elsewhere on the locus A_PQ is not checked; evaluate the multipliers near the locus by another "
    "pivot order, or numerically)"
)
#: added to what happens on the locus of a divisor read off a tree (no cancellation tried) when nothing else decides
AS_WRITTEN = " (as written: read off an expression too long to cancel, so a numerator may cancel the division)"


@dataclass(frozen=True)
class Division:
    """One division of the analysis: the (irreducible) ``divisor``, the ``stage`` it belongs to and ``what`` divides."""

    divisor: sympy.Expr
    stage: int
    what: str
    #: found as the base of a negative power of an expression too long to factor (:func:`structural_divisors`):
    #: a division as written, which a numerator may cancel
    structural: bool = False


@dataclass(frozen=True)
class SingularLocus:
    """A locus of the constraint surface where an expression of the analysis divides by zero.

    Attributes
    ----------
    expression
        The divisor (an irreducible factor): the locus is ``expression = 0`` on the surface.
    where
        The locus as an equation, with the variables the constraints fix put in
        (``"x = 0"`` for the divisor ``3*x - 4*z`` on the surface ``z = 0``).
    stage
        The stage of the constraint chain the division belongs to (``1`` for the Legendre
        map, whose primary constraints are stage 1).
    what
        What happens there (:data:`MULTIPLIERS_SINGULAR`, :data:`LEGENDRE_SINGULAR`).
    """

    expression: sympy.Expr
    where: str
    stage: int
    what: str

    def to_json(self) -> dict:
        """``{"expression", "where", "stage", "what"}`` (the ``"singular_loci"`` entries of the analysis JSON)."""
        return {"expression": shown(self.expression), "where": self.where, "stage": self.stage, "what": self.what}

    def __str__(self) -> str:
        return f"{self.where} (divisor {shown(self.expression)}, stage {self.stage}): {self.what}"


def _never_zero(factor: sympy.Expr) -> bool:
    """A factor that cannot vanish for real arguments (``x**2 + 1``, ``exp(x)``)."""
    return bool(factor.is_positive or factor.is_negative or (factor.func == sympy.exp))


def denominator_factors(
    expr: sympy.Expr, variables: Sequence[sympy.Symbol] | AbstractSet[sympy.Symbol],
    settled: Callable[[sympy.Expr], bool] | None = None,
) -> list[sympy.Expr]:
    """The distinct irreducible factors of the denominator of ``expr`` that depend on the ``variables``.

    The bases of the negative powers in ``expr`` (its denominators) are factored
    (``sympy.factor_list``; ``sin(theta)`` counts as a factor of ``sin(theta)**2``); a
    factor that a numerator would cancel is kept (no gcd is taken). A base is factored
    as the polynomial it is (:func:`~dirac.analysis.core.algebra.rational_parts`): one with
    parameters in its own denominators through its numerator (``x**2/m - y**2/m`` gives
    ``x - y`` and ``x + y``), one whose reduced denominator holds the variables (the pivot
    ``x - y**2/x`` of an elimination) is kept whole. Factors without real zeros and numbers are left out; an
    expression longer than ``DIVISOR_TEXT_LIMIT`` characters gives ``[]``. A denominator for which
    ``settled`` is true (proven nonzero on the surface, :func:`nonvanishing_on`) is not factored:
    a factor of a function that never vanishes there never vanishes there either.
    """
    names = _as_set(variables)
    if not prints_shorter(expr, DIVISOR_TEXT_LIMIT) or not (expr.free_symbols & names):  # size first: a shared tree is huge
        return []
    bases = list(dict.fromkeys(
        node.base for node in sympy.preorder_traversal(expr)
        if isinstance(node, sympy.Pow) and node.exp.is_negative and node.base.free_symbols & names
    ))  # every denominator of the tree, in one walk (no gcd: a factor the numerator cancels is kept)
    if settled is not None:
        bases = [b for b in bases if not settled(b)]
    return _irreducible_factors(bases, names)


def _irreducible_factors(bases: Sequence[sympy.Expr], names: AbstractSet[sympy.Symbol]) -> list[sympy.Expr]:
    """The distinct irreducible factors of the ``bases`` that depend on ``names``, without real-zero-free ones."""
    found: list[sympy.Expr] = []
    for base in bases:
        parts = rational_parts(base)
        if _quotient_in(parts, names):
            # a pivot a - b c/d of an elimination: no polynomial to factor, kept whole (sympy's
            # factor_list refuses it, after expanding it for up to seconds)
            found.append(base)
            continue
        try:  # a polynomial over numbers and parameters: its numerator's factors (those of the parameters drop out below)
            _, listed = sympy.factor_list(parts[0] if parts is not None else sympy.expand(base))
            found += [f for f, _ in listed]
        except (sympy.PolynomialError, sympy.CoercionFailed, NotImplementedError):
            found.append(base)
    out = []
    for f in _reduced_trigonometric(found):
        if f.free_symbols & names and not _never_zero(f):
            f = -f if f.could_extract_minus_sign() else f
            if f not in out:
                out.append(f)
    return out


def _quotient_in(parts: tuple[sympy.Expr, sympy.Expr] | None, names: AbstractSet[sympy.Symbol]) -> bool:
    """Whether the reduced fraction ``parts`` (:func:`~dirac.analysis.core.algebra.rational_parts`) has ``names``
    in its denominator: then the expression is no polynomial in them, however it is expanded."""
    return parts is not None and bool(parts[1].free_symbols & names)


def _reduced_trigonometric(factors: list[sympy.Expr]) -> list[sympy.Expr]:
    """The ``factors``, each of at most ``TRIG_TERMS`` terms in sines and cosines reduced with Pythagoras
    (:func:`~dirac.analysis.core.pythagoras.pythagorean_form`: ``sin(psi)**2 + cos(psi)**2`` is 1, exactly
    and in milliseconds, where ``trigsimp`` could take minutes) and factored again when that changed it
    (``sin(x)**2 + cos(x)**2 - y**2`` is ``(1 - y)(1 + y)``)."""
    out: list[sympy.Expr] = []
    for f in factors:
        if not (f.has(sympy.sin, sympy.cos) and len(f.args) <= TRIG_TERMS):
            out.append(f)
            continue
        reduced = pythagorean_form(f)
        if reduced == f:
            out.append(f)
            continue
        try:
            out += [g for g, _ in sympy.factor_list(reduced)[1]]
        except (BasePolynomialError, NotImplementedError):
            out.append(reduced)
    return out


def divisions(
    exprs: Sequence[sympy.Expr], stage: int, what: str, variables: Sequence[sympy.Symbol],
    settled: Callable[[sympy.Expr], bool] | None = None, *, unsearched: list[Unsearched] | None = None,
    structural: bool = False,
) -> list[Division]:
    """One :class:`Division` per distinct denominator factor of ``exprs`` (:func:`denominator_factors`; ``settled``
    names denominators proven nonzero on the surface, which are not factored).

    An expression in the ``variables`` too long to search (:func:`too_long_to_search`) gives
    no division, unless ``structural``: then the bases of its negative powers are collected
    (:func:`structural_divisors`) and each becomes a :class:`Division` marked ``structural``.
    What is left unsearched (all of it without ``structural``; with it, the expressions whose
    trees exceed ``STRUCTURAL_NODES`` distinct nodes) is counted in one :class:`Unsearched`
    record, appended to ``unsearched`` when given, so that the caller can say what was not searched.
    """
    found: dict[sympy.Expr, Division] = {}
    skipped = 0
    seen: set = set()  # nodes shared between the expressions are walked once
    memo: dict = {}  # ... and their free symbols found once
    names = frozenset(variables)  # once for all the expressions
    for e in exprs:
        e = sympy.sympify(e)
        if e.is_Number:  # no denominator in the variables (most entries of a large multiplier solution are 0)
            continue
        if too_long_to_search(e, names, memo):
            bases = structural_divisors(e, variables, settled, seen) if structural else None
            if bases is None:
                skipped += 1
                continue
            for f in bases:
                found.setdefault(f, Division(f, stage, what, structural=True))
            continue
        for f in denominator_factors(e, names, settled):
            found.setdefault(f, Division(f, stage, what))
    if skipped and unsearched is not None:
        unsearched.append(Unsearched(skipped, stage, what, STRUCTURAL_NODES if structural else None))
    return list(found.values())


def _nested(expr: sympy.Expr, names: AbstractSet[sympy.Symbol] | None = None) -> bool:
    """Whether ``expr`` holds a division or a fractional power (a pivot ``a - b c/d`` of an elimination).

    With ``names`` (the phase-space variables) a division by an expression free of them
    (``4 x1^2/m1 + 4 y1^2/m1``: a mass in a denominator) does not count: the expression is
    a polynomial in the variables, which the proofs take as it is.
    """
    for node in _nodes(expr):
        if isinstance(node, sympy.Pow) and not (node.exp.is_Integer and node.exp > 0):
            if names is None or not node.exp.is_Integer or node.base.free_symbols & names:
                return True
    return False


def _nodes(expr: sympy.Expr) -> set:
    """The distinct nodes of ``expr`` (its graph, each shared sub-tree once)."""
    seen: set = set()
    stack = [expr]
    while stack:
        node = stack.pop()
        if node not in seen:
            seen.add(node)
            stack.extend(node.args)
    return seen


#: distinct nodes of one expression's tree that :func:`structural_divisors` walks before it gives up
STRUCTURAL_NODES = 200_000


def structural_divisors(
    expr: sympy.Expr, variables: Sequence[sympy.Symbol], settled: Callable[[sympy.Expr], bool] | None = None,
    seen: set | None = None, limit: int | None = None,
) -> list[sympy.Expr] | None:
    """The divisors of an expression too long to factor, read off its tree: the bases of its negative powers.

    ``expr`` is walked as the directed acyclic graph it is (a node shared by many
    sub-trees once: an exact solve by elimination nests its pivots, so that the printed
    form of the multiplier solution of the rigid body (228) has tens of millions of
    nodes but its graph a few thousand). Every base ``f`` of a power ``f**(-n)`` that
    depends on the ``variables`` is a divisor of ``expr`` as written: ``expr`` is not
    defined where ``f = 0``. No ``together`` or ``cancel`` of the whole is taken, so a
    numerator may cancel the division (an elimination's pivot ``D_k/D_(k-1)``, a ratio of
    leading minors, vanishes where the solution need not). Short bases are factored
    (:func:`denominator_factors`), long ones kept whole; bases for which ``settled`` is
    true (proven nonzero on the surface) are left out. ``seen`` holds nodes already
    walked (shared between calls). ``None`` when the graph has more than ``limit``
    distinct nodes not seen before.
    """
    names = set(variables)
    limit = STRUCTURAL_NODES if limit is None else limit
    seen = set() if seen is None else seen
    memo: dict = {}  # free symbols of shared sub-trees, walked once
    stack = [expr]
    bases: list[sympy.Expr] = []
    fresh = 0
    while stack:
        node = stack.pop()
        if node in seen or not node.args:
            continue
        seen.add(node)
        fresh += 1
        if fresh > limit:
            return None
        if node.is_Pow and node.exp.is_negative and free_symbols_of([node.base], memo) & names:
            bases.append(node.base)
        stack.extend(node.args)
    out: list[sympy.Expr] = []
    for base in dict.fromkeys(bases):
        if not _nested(base) and prints_shorter(base, DIVISOR_TEXT_LIMIT):  # proofs and factoring expand: short polynomials only
            factors = [] if settled is not None and settled(base) else _irreducible_factors([base], names)
        else:
            factors = [base]  # kept as written (assumptions such as is_positive cost seconds on a nested pivot)
        out += [f for f in factors if f not in out]
    return out


def too_long_to_search(expr: sympy.Expr, variables: Sequence[sympy.Symbol] | AbstractSet[sympy.Symbol],
                       memo: dict | None = None) -> bool:
    """Whether ``expr`` depends on the ``variables`` and prints longer than ``DIVISOR_TEXT_LIMIT``
    characters: :func:`denominator_factors` gives ``[]`` for it without looking at its denominators.
    ``memo`` (:func:`~dirac.analysis.core.phase_space.free_symbols_of`) shares the walk of sub-trees
    between calls: the multipliers of one solve share most of theirs."""
    return not prints_shorter(expr, DIVISOR_TEXT_LIMIT) and bool(free_symbols_of([expr], memo) & _as_set(variables))


def _as_set(variables: Sequence[sympy.Symbol] | AbstractSet[sympy.Symbol]) -> AbstractSet[sympy.Symbol]:
    """``variables`` as a set (as given when already one: :func:`divisions` builds it once for all its expressions;
    a set of the 512 variables of a 128-site ring built for each of its 16,512 multiplier entries took 1.5 s)."""
    return variables if isinstance(variables, (set, frozenset)) else set(variables)


@dataclass(frozen=True)
class Unsearched:
    """Expressions of the analysis not searched for divisions by zero (too long to factor).

    A division by zero in them is neither found nor ruled out: the report says so
    (``singular loci: not searched ...``) instead of passing over it.
    """

    count: int
    stage: int
    what: str
    #: when the trees were walked for their divisors (:func:`structural_divisors`): the most distinct nodes walked
    nodes: int | None = None

    def __str__(self) -> str:
        walked = "" if self.nodes is None else f", and their trees have more than {self.nodes} distinct nodes to walk"
        return (f"not searched in {self.count} expression{'s' if self.count != 1 else ''} of stage {self.stage} "
                f"(longer than {DIVISOR_TEXT_LIMIT} characters, too long to factor{walked}): whether {self.what} on "
                "part of the surface is neither found nor ruled out")


def fixed_values(constraints: Sequence[sympy.Expr], variables: Sequence[sympy.Symbol]) -> dict[sympy.Symbol, sympy.Expr]:
    """``v -> -b/a`` for each constraint ``a v + b`` (numbers ``a != 0``, ``b``): the variables the surface fixes."""
    names = set(variables)
    values: dict[sympy.Symbol, sympy.Expr] = {}
    for c in constraints:
        free = c.free_symbols & names
        if len(free) != 1 or not (c.is_Symbol or ((c.is_Add or c.is_Mul) and len(c.args) <= 2)):
            continue
        (v,) = free
        if c.is_polynomial(v):
            poly = sympy.Poly(c, v)
            if poly.degree() == 1 and all(k.is_number for k in poly.all_coeffs()):
                a, b = poly.all_coeffs()
                values.setdefault(v, -b / a)
    return values


def locus_equation(divisor: sympy.Expr, fixed: dict[sympy.Symbol, sympy.Expr]) -> str:
    """``"x = 0"``: the divisor with the fixed variables put in, without a constant factor."""
    reduced = divisor.xreplace(fixed) if fixed else divisor
    if reduced.has(sympy.zoo, sympy.nan) or reduced.is_number:
        reduced = divisor
    _, reduced = sympy.factor_terms(sympy.expand(reduced)).as_coeff_Mul()
    if reduced.could_extract_minus_sign():
        reduced = -reduced
    return f"{reduced} = 0"


def constant_on_surface(
    divisor: sympy.Expr, surface: Sequence[sympy.Expr], variables: Sequence[sympy.Symbol], memo: dict | None = None
) -> sympy.Expr | None:
    """The value ``c`` when ``divisor = c + sum_i a_i phi_i`` exactly, with numbers or parameters ``a_i``, ``c``; else None.

    Then ``divisor = c`` on the whole surface ``phi_i = 0``: a certificate, not a
    sample. The rotation-matrix Lagrangian (78) divides by ``R_11^2 + R_21^2 + R_31^2``
    and by combinations of the squared column norms, ``1`` and ``2 I_3`` on ``R^T R = 1``:
    each is decided here by a linear system in the coefficients of the monomials,
    instead of a search for a point where it vanishes. Only the polynomial constraints
    in the divisor's variables are used; ``None`` says nothing (the search decides).
    ``memo`` (:func:`~dirac.analysis.core.phase_space.free_symbols_of`) keeps the free
    symbols of the constraints between calls: a long constraint is walked once.
    """
    own = sorted(divisor.free_symbols & set(variables), key=lambda s: s.name)
    if not own:
        return None
    if _quotient_in(rational_parts(divisor), set(own)):
        return None  # no polynomial in its variables: no such identity
    names = set(variables)
    memo = {} if memo is None else memo
    key = ("constraint polynomials", tuple(own))
    if key not in memo:  # the same constraints in the same generators, for every divisor in them
        used = [c for c in surface if (inside := free_symbols_of([c], memo) & names) and inside <= set(own)]
        try:
            memo[key] = sympy.parallel_poly_from_expr(used, *own)[0] if used else []
        except (sympy.PolynomialError, sympy.GeneratorsError):
            memo[key] = None
    constraint_polys = memo[key]
    if not constraint_polys:
        return None
    used = constraint_polys
    try:
        (first,), _ = sympy.parallel_poly_from_expr([divisor], *own)
        domain = first.domain.unify(constraint_polys[0].domain)
        polys = [first.set_domain(domain), *(c.set_domain(domain) for c in constraint_polys)]
    except (sympy.PolynomialError, sympy.GeneratorsError, sympy.CoercionFailed, sympy.UnificationFailed):
        return None
    domain = polys[0].domain
    if not domain.is_Field and not domain.is_Ring or domain.is_EX or domain.is_EXRAW:
        return None
    # divisor = c + sum_i a_i phi_i, coefficient by coefficient: one row per monomial, unknowns (c, a_1, ...)
    monomials = sorted({m for p in polys for m in p.monoms()})
    if len(monomials) > CONSTANT_TEST_EQUATIONS:
        return None
    field = domain.get_field()
    constant = (0,) * len(own)
    coefficients = [p.as_dict(native=True) for p in polys]
    rows = [
        [field.one if m == constant else field.zero, *(field.convert(c.get(m, domain.zero), domain) for c in coefficients[1:]),
         field.convert(coefficients[0].get(m, domain.zero), domain)]
        for m in monomials
    ]
    reduced, pivots = DomainMatrix(rows, (len(rows), len(used) + 2), field).rref()
    if len(used) + 1 in pivots or 0 not in pivots:
        return None  # no such identity (inconsistent), or c not fixed by it
    row = reduced.to_Matrix().row(pivots.index(0))
    if any(row[j] != 0 for j in range(1, len(used) + 1) if j not in pivots):
        return None  # c depends on a free coefficient: not fixed by the identity
    value = row[len(used) + 1]
    return _exact_value(value)


def _exact_value(value: sympy.Expr) -> sympy.Expr:
    """``value`` in a form whose comparison with 0 is exact: a number, or a cancelled rational function
    of the parameters (``cancel`` is 0 exactly when the function is); anything else is simplified."""
    if value.is_Rational:
        return value
    if value.is_rational_function():
        return sympy.cancel(value)
    return sympy.simplify(value)


#: largest size ``k`` of a ``k x k`` matrix that :func:`square_on_surface` recognises a divisor as the determinant of
GRID_SIZE = 4


def determinant_grid(divisor: sympy.Expr, variables: Sequence[sympy.Symbol]) -> tuple[sympy.Matrix, sympy.Expr] | None:
    """``(M, c)`` with ``divisor = c det M`` exactly, ``M`` a ``k x k`` matrix of distinct variables; else None.

    The ``k^2`` variables of a determinant of distinct variables fall into rows and
    columns: two of them share a row or a column exactly when no term of ``det M``
    holds both (each of its ``k!`` terms takes one entry of every row and of every
    column). The grid read off the terms is then checked by expanding ``c det M``
    against the divisor, so a divisor that only looks like a determinant is refused.
    """
    own = sorted(divisor.free_symbols & set(variables), key=lambda s: s.name)
    k = int(round(len(own) ** 0.5))
    if k < 2 or k > GRID_SIZE or k * k != len(own):
        return None
    try:
        poly = sympy.Poly(divisor, *own)
    except (sympy.PolynomialError, sympy.GeneratorsError):
        return None
    terms = poly.terms()
    if len(terms) != factorial(k) or any(sum(m) != k or max(m) != 1 for m, _ in terms):
        return None
    together = [{own[i] for i, e in enumerate(m) if e} for m, _ in terms]

    def apart(x: sympy.Symbol, y: sympy.Symbol) -> bool:  # same row or same column
        return not any(x in t and y in t for t in together)

    first = own[0]
    mates = [v for v in own[1:] if apart(first, v)]
    if len(mates) != 2 * (k - 1):
        return None
    row = [first, mates[0], *(v for v in mates[1:] if apart(mates[0], v))]
    column = [first, *(v for v in mates if v not in row)]
    if len(row) != k or len(column) != k:
        return None
    grid = [[sympy.S.Zero] * k for _ in range(k)]
    for j in range(k):
        grid[0][j] = row[j]
    for i in range(1, k):
        grid[i][0] = column[i]
        for j in range(1, k):
            cell = [v for v in own if v not in row and v not in column and apart(v, row[j]) and apart(v, column[i])]
            if len(cell) != 1:
                return None
            grid[i][j] = cell[0]
    M = sympy.Matrix(grid)
    det = sympy.Poly(M.det(method="berkowitz"), *own)
    monomial, coefficient = terms[0]
    c = coefficient / det.coeff_monomial(monomial) if det.coeff_monomial(monomial) != 0 else None
    if c is None or not sympy.Poly(c * det.as_expr() - divisor, *own).is_zero:
        return None
    return M, c


def square_on_surface(
    divisor: sympy.Expr, surface: Sequence[sympy.Expr], variables: Sequence[sympy.Symbol], memo: dict | None = None
) -> sympy.Expr | None:
    """The value ``s`` of ``divisor^2`` on the whole surface, proven by the Gram identity; else None.

    When ``divisor = c det M`` (:func:`determinant_grid`) and every entry of the Gram
    matrix ``G = M^T M`` (or ``M M^T``) is a constant ``K_ij`` on the surface
    (:func:`constant_on_surface`, an exact identity ``G_ij = K_ij + sum a phi``), then
    ``divisor^2 = c^2 det(M^T M) = c^2 det K`` at every point of the surface. For the
    rotation-matrix Lagrangians ((78), (228)) the legendre map divides by ``det R``, and
    ``R^T R = 1`` gives ``det(R)^2 = 1``: ``det R = +-1`` never vanishes there (a proof, where
    ``det R`` itself is no constant combination of the constraints). ``None`` says nothing
    (the search decides).
    """
    found = determinant_grid(divisor, variables)
    if found is None:
        return None
    M, c = found
    memo = {} if memo is None else memo
    own = set(M)
    names = set(variables)
    surface = [e for e in surface if free_symbols_of([e], memo) & names <= own]  # the Gram entries use no other constraint
    for gram in (M.T * M, M * M.T):
        K = _constant_matrix(gram, surface, variables, memo)
        if K is not None:
            return _exact_value(c**2 * K.det(method="berkowitz"))
    return None


def _constant_matrix(
    G: sympy.Matrix, surface: Sequence[sympy.Expr], variables: Sequence[sympy.Symbol], memo: dict
) -> sympy.Matrix | None:
    """The symmetric matrix ``K`` of the values of ``G`` on the surface (:func:`constant_on_surface`), or None."""
    k = G.shape[0]
    K = sympy.zeros(k, k)
    for i in range(k):
        for j in range(i, k):
            value = constant_on_surface(sympy.expand(G[i, j]), surface, variables, memo)
            if value is None:
                return None
            K[i, j] = K[j, i] = value
    return K


def pfaffian(A: sympy.Matrix) -> sympy.Expr:
    """The Pfaffian of an antisymmetric matrix of even size, ``det A = Pf(A)^2``.

    Expansion along the first row, ``Pf(A) = sum_{j > 1} (-1)^j a_1j Pf(A without rows and
    columns 1, j)`` (Cayley 1852; e.g. Lang, *Algebra*, XV.9); for the small bracket
    matrices of the Dirac bracket (``(2n - 1)!!`` terms: 105 at size 8). The bracket matrix
    of a pendulum's four second-class constraints has ``Pf(C) = C_14 C_23`` (``C_12 =
    C_13 = 0``), a constant on the surface where ``det C`` itself is no constant
    combination of the constraints.
    """
    size = A.shape[0]
    if size == 0:
        return sympy.Integer(1)
    total = sympy.Integer(0)
    for j in range(1, size):
        entry = A[0, j]
        if entry == 0:
            continue
        keep = [k for k in range(1, size) if k != j]
        total += (-1) ** (j + 1) * entry * pfaffian(A.extract(keep, keep))
    return total


def sum_of_squares_on_surface(
    divisor: sympy.Expr, surface: Sequence[sympy.Expr], variables: Sequence[sympy.Symbol], memo: dict | None = None
) -> bool:
    """Whether ``divisor`` is proven nonzero on the surface as a product of sums of squares.

    A factor (of a product, to any integer power) is settled when it is a nonzero number
    or expression of the parameters (at generic parameter values, as :func:`singular_loci`
    reads them), a nonzero constant on the surface (:func:`constant_on_surface`), or a sum
    ``sum_k c_k b_k^(2 j_k)`` of even powers of real expressions with positive numbers
    ``c_k`` in which one term is positive on the whole surface: a positive number, or an
    even power of a base that is a nonzero constant there. Then the sum is at least that
    term (the phase-space variables are real). The bracket matrix of a pendulum in
    Cartesian coordinates gives ``(4 (x^2 + y^2)/m)^2 ((4 (x^2 + y^2)/m)^2 + (...)^2 + ...)``:
    both factors are settled on ``x^2 + y^2 = l^2``. ``False`` says only that there is no
    proof.
    """

    phase_space = set(variables)

    def constant(expr: sympy.Expr) -> bool:
        """A nonzero number or expression of the parameters, or a nonzero constant on the surface."""
        if not expr.free_symbols & phase_space:
            return bool(expr != 0)
        value = constant_on_surface(expr, surface, variables, memo)
        return value is not None and value != 0

    def nonnegative_term(term: sympy.Expr) -> tuple[bool, bool]:
        """(term >= 0 proven, term > 0 on the whole surface proven): ``c prod b_i^(2 j_i)``,
        ``c > 0``, is >= 0, and > 0 when every ``b_i`` is a nonzero constant on the surface."""
        coefficient, rest = term.as_coeff_Mul()
        if not (coefficient.is_Number and coefficient > 0):
            return False, False
        bases = []
        for factor in sympy.Mul.make_args(rest):
            if factor == 1:
                continue
            base, exponent = factor.as_base_exp()
            if not (exponent.is_Integer and exponent % 2 == 0):
                return False, False
            bases.append(base)
        return True, all(constant(base) for base in bases)

    def settled(factor: sympy.Expr) -> bool:
        if constant(factor):
            return True
        if factor.is_Add:
            signs = [nonnegative_term(term) for term in factor.args]
            return all(nonnegative for nonnegative, _ in signs) and any(positive for _, positive in signs)
        return False

    for factor in sympy.Mul.make_args(divisor):
        base, exponent = factor.as_base_exp()
        if not exponent.is_Integer or not settled(base):
            return False
    return True


def nonvanishing_on(surface: Sequence[sympy.Expr], variables: Sequence[sympy.Symbol]) -> Callable[[sympy.Expr], bool]:
    """``f -> bool``: whether ``f`` is proven nonzero on the whole surface ``surface = 0``.

    A proof is :func:`constant_on_surface` or :func:`square_on_surface` with a value that
    is not 0 (at generic parameter values, as :func:`singular_loci` reads them); ``False``
    says only that there is no proof. Answers are remembered per expression.
    """
    memo: dict = {}
    answers: dict[sympy.Expr, bool] = {}

    def settled(f: sympy.Expr) -> bool:
        if f not in answers:
            value = constant_on_surface(f, surface, variables, memo)
            if value is None:
                value = square_on_surface(f, surface, variables, memo)
            answers[f] = value is not None and value != 0
        return answers[f]

    return settled


#: largest number of monomial equations :func:`constant_on_surface` solves (above it, the search decides)
CONSTANT_TEST_EQUATIONS = 200


#: CPU seconds the decisions on the divisors read off trees (:func:`structural_divisors`) may take in all
#: (CPU, not wall time: what is decided should not depend on the load of the machine)
STRUCTURAL_BUDGET = 2.0
#: divisors read off trees searched for a point of their locus, at most (each search compiles the divisor's gradient)
STRUCTURAL_SEARCHES = 8
#: ... and only those that print shorter than this (characters): the projections onto a longer one, a nested pivot
#: of (228) of thousands of characters, cost a third of a second each and found no point there
SEARCH_TEXT_LIMIT = 1000


@dataclass(frozen=True)
class GramVerdict:
    """The answer of an optional proof rule about one divisor (:class:`~dirac.analysis.core.gram_proof.GramProver`).

    ``proven`` is true only with a certificate; ``reason`` says why not when the rule
    recognised the divisor (or ran out of its budget), else is empty: it is added to the
    divisor's :class:`Undecided` reason.
    """

    proven: bool
    reason: str = ""


@dataclass(frozen=True)
class Undecided:
    """A divisor that is neither proven nonzero on the surface nor found to vanish there
    (:func:`singular_loci`): the report says so, with the ``reason`` and the divisor's
    ``origin`` (read off the tree of a long expression, or a factor of a denominator)."""

    divisor: sympy.Expr
    stage: int
    what: str
    reason: str
    origin: str = "a base of a negative power of an expression too long to factor"

    def __str__(self) -> str:
        return (f"not ruled out at stage {self.stage}: whether {self.what} where the divisor {shown(self.divisor, DIVISOR_SHOWN)} vanishes "
                f"({self.origin}): {self.reason}")


#: characters of a divisor shown in the report (a longer one is described, not printed)
DIVISOR_SHOWN = 400


def shown(expr: sympy.Expr, limit: int = DIVISOR_TEXT_LIMIT) -> str:
    """``str(expr)`` when shorter than ``limit`` characters, else a description (a divisor read off the tree of
    a long expression can print to millions of characters)."""
    if prints_shorter(expr, limit):
        return printed(expr)
    return f"(an expression of {limit} characters or more, not printed)"

#: why a divisor read off a tree stays undecided when no point of the locus is found
NOT_FOUND = (f"no point of the surface where it vanishes was found in {LOCUS_ATTEMPTS} projections, which "
             "is no proof that there is none")
#: where a short divisor comes from (a factor of a denominator, factored)
FACTOR_ORIGIN = "a factor of a denominator"
#: ... when it is too long to search
TOO_LONG_TO_SEARCH = (f"not searched: it prints to {SEARCH_TEXT_LIMIT} characters or more (the projections onto "
                      "its zeros would cost more than the analysis)")
#: CPU seconds the searches for a point of the loci of the other divisors (factors of denominators) may take in
#: all: each costs milliseconds on a system of a few coordinates, but eight failed projections onto a 24-link
#: chain's Gram pivot took 1.5 s
SEARCH_BUDGET = 2.0
#: why such a divisor stays undecided when that budget ran out before or during its search
SEARCH_OUT_OF_TIME = ("no point of the surface where it vanishes was found before the budget of these searches "
                      f"({SEARCH_BUDGET:g} s of CPU time) ran out, which is no proof that there is none")
#: ... and when the time budget ran out before it was searched
OUT_OF_TIME = (f"not searched: the budget for divisors read off long expressions ({STRUCTURAL_SEARCHES} searches, "
               f"{STRUCTURAL_BUDGET:g} s of CPU time) ran out")


def value_on_surface(
    expr: sympy.Expr, surface: Sequence[sympy.Expr], variables: Sequence[sympy.Symbol], memo: dict, cache: dict,
) -> sympy.Expr | None:
    """The constant ``c`` (a number or a function of the parameters) that ``expr`` equals at every point of the
    surface, proven node by node; else None.

    By induction on the tree: a node free of the ``variables`` is its own value; a
    polynomial node short enough has the value of :func:`constant_on_surface` (an
    identity ``node = c + sum a_i phi_i``); a sum, product or integer power of nodes with
    values has the value of the same operation on them, a negative power only when the
    base's value is not 0 (then the base vanishes nowhere on the surface and the node is
    defined there). The pivots of an elimination whose entries are constant on the surface
    (the multiplier solution of four point masses at fixed distances, (19)) are proven
    nonzero so, where their expanded forms are far too long for a polynomial identity.
    ``cache`` keeps the value of each node between calls (shared sub-trees are decided once).
    """
    names = set(variables)

    def value(node: sympy.Expr) -> sympy.Expr | None:
        if node in cache:
            return cache[node]
        out: sympy.Expr | None = None
        if not (free_symbols_of([node], memo) & names):
            out = node
        elif node.is_Add:
            polynomial = [a for a in node.args if not _divides(a)]  # the terms without division, decided together
            parts = []
            if polynomial:
                whole = sympy.Add(*polynomial)
                parts.append(_ring_constant(whole, surface, variables, memo)
                             if prints_shorter(whole, DIVISOR_TEXT_LIMIT) else None)
            for arg in node.args:
                if parts and parts[-1] is None:
                    break
                if _divides(arg):
                    parts.append(value(arg))
            if parts and all(part is not None for part in parts):
                out = _exact_value(sympy.Add(*parts))
        elif node.is_Mul:  # factor by factor (a product's expanded form is longer, and no constant combination)
            parts = []
            for arg in node.args:
                part = value(arg)
                if part is None:
                    break
                parts.append(part)
            else:
                out = _exact_value(sympy.Mul(*parts))
        elif node.is_Pow and node.exp.is_Integer:
            base = value(node.base)
            if base is not None and (node.exp > 0 or base != 0):
                out = _exact_value(base**node.exp)
        cache[node] = out  # a variable alone, or any other function, is no proven constant
        return out

    def _divides(node: sympy.Expr) -> bool:
        key = ("divides", node)
        if key not in cache:
            cache[key] = bool(node.is_Pow and not (node.exp.is_Integer and node.exp > 0)) or any(_divides(a) for a in node.args)
        return cache[key]

    return value(expr)


def _ring_constant(
    expr: sympy.Expr, surface: Sequence[sympy.Expr], variables: Sequence[sympy.Symbol], memo: dict
) -> sympy.Expr | None:
    """:func:`constant_on_surface` of a polynomial ``expr``, with the polynomials built by ring arithmetic.

    The same identity ``expr = c + sum_i a_i phi_i`` (numbers or parameters ``a_i``, the
    polynomial constraints in ``expr``'s variables), decided by the same linear system;
    ``expr`` and the constraints become elements of ``QQ(parameters)[variables]`` by one walk
    of their trees (:func:`~dirac.analysis.core.algebra.ring_value`) instead of ``expand``
    and ``Poly`` (a tenth of the time on the pivots of (19)). ``None`` says nothing.
    """
    from sympy.polys.rings import ring as polynomial_ring

    from dirac.analysis.core.algebra import NotInRing, ring_value

    names = set(variables)
    own = tuple(sorted(free_symbols_of([expr], memo) & names, key=lambda v: v.name))
    if not own:
        return None
    key = ("ring constraints", own)
    if key not in memo:
        params = sorted(set().union(*(free_symbols_of([c], memo) for c in surface)) - names, key=lambda v: v.name)
        domain = sympy.QQ.frac_field(*params) if params else sympy.QQ
        R, *gens = polynomial_ring(list(own), domain)
        mapping: dict = dict(zip(own, gens))
        mapping.update({p: R(domain.from_sympy(p)) for p in params})
        used = []
        for c in surface:
            inside = free_symbols_of([c], memo) & names
            if inside and inside <= set(own):
                try:
                    used.append(ring_value(c, mapping, R))
                except NotInRing:
                    continue
        memo[key] = (R, mapping, used)
    R, mapping, used = memo[key]
    if not used:
        return None
    try:
        value = ring_value(expr, mapping, R)
    except (NotInRing, sympy.CoercionFailed):
        return None
    if set(free_symbols_of([expr], memo)) - names - set(mapping):
        return None  # a symbol outside the ring's parameters
    polys = [value, *used]
    field = R.domain
    monomials = sorted({m for p in polys for m in p.keys()})
    if len(monomials) > CONSTANT_TEST_EQUATIONS:
        return None
    constant = (0,) * len(own)
    rows = [[field.one if m == constant else field.zero, *(p.get(m, field.zero) for p in used), value.get(m, field.zero)]
            for m in monomials]
    reduced, pivots = DomainMatrix(rows, (len(rows), len(used) + 2), field).rref()
    if len(used) + 1 in pivots or 0 not in pivots:
        return None
    row = reduced.to_Matrix().row(pivots.index(0))
    if any(row[j] != 0 for j in range(1, len(used) + 1) if j not in pivots):
        return None
    return _exact_value(row[len(used) + 1])


class _SearchSpent(Exception):
    """The budget of the searches for points of loci (:data:`SEARCH_BUDGET`) ran out before a search."""


def singular_loci(
    found: Sequence[Division],
    surface: Sequence[sympy.Expr],
    numerics,
    variables: Sequence[sympy.Symbol],
    *,
    undecided: list[Undecided] | None = None,
    regular_at: Callable[[np.ndarray], bool] | None = None,
    budget: float = STRUCTURAL_BUDGET,
    gram: Callable[[sympy.Expr], GramVerdict | None] | None = None,
) -> tuple[SingularLocus, ...]:
    """The divisions whose divisor vanishes somewhere on the surface ``surface = 0``, as :class:`SingularLocus`.

    One Gauss–Newton projection onto ``surface`` and the divisor together (up to
    ``LOCUS_ATTEMPTS`` random starts, points near an assumed-nonzero expression excluded)
    decides whether the locus meets the surface. A divisor met twice is reported once, at
    its earliest stage.

    A divisor read off a tree (``Division.structural``, :func:`structural_divisors`) is
    first put to the proofs (:func:`constant_on_surface`, :func:`square_on_surface` when
    short, :func:`value_on_surface`); then searched. A point found is a locus: for the
    multiplier solution, ``regular_at`` (when given) says whether the matrix it inverts is
    regular at that point, and if so the locus is one of the solved form only
    (:data:`PIVOT_SINGULAR`); otherwise its ``what`` says that a numerator may cancel
    (:data:`AS_WRITTEN`). No point found is no proof: such a divisor goes to
    ``undecided`` (:class:`Undecided`), unless it is a short divisor that
    :func:`sum_of_squares_on_surface` proves nonzero, or ``gram`` (when given: a
    :class:`~dirac.analysis.core.gram_proof.GramProver`, whose :class:`GramVerdict` reason is added
    when it recognised the divisor) proves a principal minor of ``J W J^T`` positive on the surface by
    the Cauchy–Binet formula; so do the divisors read off trees left
    when ``budget`` CPU seconds of these decisions, or ``STRUCTURAL_SEARCHES`` searches, have
    run out, and the other divisors whose search was cut short or not started because the
    searches for them together took ``SEARCH_BUDGET`` CPU seconds (a projection that fails runs
    its full count of steps: on a large chain eight of them take seconds).
    """
    fixed = fixed_values(list(surface), variables)
    seen: dict[sympy.Expr, Division] = {}
    for d in sorted(found, key=lambda d: d.stage):
        seen.setdefault(d.divisor, d)
    out = []
    memo: dict = {}  # free symbols of the constraints, walked once for all the divisors
    cache: dict = {}  # values on the surface of the nodes of the divisors read off trees (value_on_surface)
    deadline: float | None = None
    search_deadline: float | None = None  # of the searches for the other divisors' loci (SEARCH_BUDGET)
    searched = 0  # divisors read off trees searched for a point so far (at most STRUCTURAL_SEARCHES)
    names = set(variables)
    plain = {d.divisor: not d.structural or (not _nested(d.divisor, names) and prints_shorter(d.divisor, DIVISOR_TEXT_LIMIT))
             for d in seen.values()}
    # the divisors read off trees after the others, short polynomials first: the budget goes to the cheap ones
    for d in sorted(seen.values(), key=lambda d: (d.structural, not plain[d.divisor])):
        short = plain[d.divisor]
        if d.structural:
            deadline = cpu_clock() + budget if deadline is None else deadline
            if cpu_clock() > deadline or searched >= STRUCTURAL_SEARCHES:
                if undecided is not None:
                    undecided.append(Undecided(d.divisor, d.stage, d.what, OUT_OF_TIME))
                continue
        value = constant_on_surface(d.divisor, surface, variables, memo) if short else None
        if value is not None and value != 0:
            continue  # a constant on the whole surface (nonzero at generic parameter values, as the search samples): no locus
        square = square_on_surface(d.divisor, surface, variables, memo) if value is None and short else None
        if square is not None and square != 0:
            continue  # divisor^2 is a nonzero constant on the whole surface (det R = +-1 on R^T R = 1): no locus
        if d.structural:
            proven = value_on_surface(d.divisor, surface, variables, memo, cache)
            if proven is not None and proven != 0:
                continue  # built from parts constant on the surface, into a nonzero constant: no locus
        if d.structural and not prints_shorter(d.divisor, SEARCH_TEXT_LIMIT):
            if undecided is not None:
                undecided.append(Undecided(d.divisor, d.stage, d.what, TOO_LONG_TO_SEARCH))
            continue
        if gram is not None and short and not d.structural:
            verdict = gram(d.divisor)  # before the search: a proof saves its projections (and is remembered)
            if verdict is not None and verdict.proven:
                continue  # its numerator is a Gram minor, positive on the surface by Cauchy-Binet: no locus
        searched += d.structural
        limit: float | None = None  # the searches for divisors not read off trees share SEARCH_BUDGET
        if not d.structural:
            search_deadline = cpu_clock() + SEARCH_BUDGET if search_deadline is None else search_deadline
            limit = search_deadline
        try:
            if limit is not None and cpu_clock() > limit:
                raise _SearchSpent
            points = numerics.surface_points([*surface, d.divisor], 1, attempts=LOCUS_ATTEMPTS, deadline=limit)
        except (AnalysisError, _SearchSpent):
            cut = limit is not None and cpu_clock() > limit
            if undecided is not None and (d.structural or not sum_of_squares_on_surface(d.divisor, surface, variables, memo)):
                verdict = gram(d.divisor) if gram is not None else None
                if verdict is not None and verdict.proven:
                    continue  # its numerator is a Gram minor, positive on the surface by Cauchy-Binet: no locus
                reason = (SEARCH_OUT_OF_TIME if cut else NOT_FOUND) + (
                    f"; {verdict.reason}" if verdict is not None and verdict.reason else "")
                undecided.append(Undecided(d.divisor, d.stage, d.what, reason, *(() if d.structural else (FACTOR_ORIGIN,))))
            continue  # no point found: proven nonzero, or said not ruled out
        what = d.what
        if d.structural:
            if d.what == MULTIPLIERS_SINGULAR and regular_at is not None:
                what = PIVOT_SINGULAR if regular_at(points[0]) else d.what  # singular there: the multipliers' own locus
            else:
                what = d.what + AS_WRITTEN
        where = locus_equation(d.divisor, fixed) if short else f"{shown(d.divisor)} = 0"
        out.append(SingularLocus(d.divisor, where, d.stage, what))
    return tuple(out)
