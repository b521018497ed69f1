"""The Dirac–Bergmann constraint chain: stage-by-stage consistency ``{Phi, H_T} ≈ 0``.

With ``H_T = H_c + u_k phi_k`` (one multiplier per primary constraint, (207), (234)),
the time derivative of every constraint found so far must vanish weakly:

    {Phi_a, H_c} + u_k {Phi_a, phi_k} ≈ 0          ((210), (213)-(215)).

For a constraint that depends explicitly on the time ``t`` (a rheonomic system) the
total time derivative has the partial derivative as well,
``d Phi_a/dt = {Phi_a, H_T} + d_t Phi_a`` (Dirac, "Lectures on quantum mechanics";
Gitman–Tyutin), so ``b_a = {Phi_a, H_c} + d_t Phi_a`` below; ``t`` is not a phase-space
variable, so the brackets are unchanged.

Writing ``b_a = {Phi_a, H_c}`` and ``A_ak = {Phi_a, phi_k}``, the rows of ``A`` that are
independent on the surface fix multipliers; every other row ``a`` is, after eliminating
``u`` with those pivot rows, the condition ``psi_a = b_a - c_a . b_P ≈ 0`` (``c_a`` the
coefficients of row ``a`` in the pivot rows). Each ``psi_a`` is (i) weakly zero — an
identity, or (ii) a new constraint of the next stage. Pivot rows are chosen among rows
whose ``b`` already vanishes weakly first, so that usually ``psi_a = b_a`` exactly
(this reproduces the chains (206), (209), (210), (215) of the paper). When a stage has
new constraints of that direct kind, the conditions that would need multipliers
eliminated are deferred to the next stage and re-examined there, on the smaller
surface, where more multipliers are usually fixed by rows with ``b ≈ 0``: the final
surface is the same (the chain only stops when no row of any kind adds a constraint),
and the stages follow the paper's order for (228) — ``pi -> R^T R - 1`` first, then
``d(R^T R)/dt = 0`` fixes ``v = 0`` and ``P_dot = 0`` fixes ``lambda`` (Sect. XI). New constraints
that follow from the earlier ones (gradient dependent on the new surface) are dropped; a
condition free of phase-space variables (``1 = 0``) is an inconsistency. The chain stops
when a stage adds nothing; the last system then fixes the determined multipliers, and its
general solution ``u = U + v_a V_a`` is built by :mod:`dirac.analysis.classes.multiplier_solution`.

Regularity (Henneaux–Teitelboim, Sect. 1.1.2): every sample point is a regular point of
the surface found so far (independent gradients of the kept constraints, checked). A
new constraint whose gradient vanishes where it holds is replaced by its square-free
part (Cawley's ``z^2 = 0`` -> ``z = 0``, with a note) or refused; a product whose
branches cross is refused. New constraints whose gradients depend on the others on the
regular part of the surface (a reducible set, ``x . J = 0`` for ``J = x × p``) are kept
in :attr:`ConstraintChain.reducible`: they do not enter the classification but still
define the surface on which points are sampled.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, fields

import numpy as np
import sympy

from dirac.analysis.chain.chain_regularity import gradient_values, irregular_candidates
from dirac.analysis.classes.multiplier_solution import (
    FixedMultipliers,
    MultiplierSolution,
    general_multiplier_solution,
    unsolved_multipliers,
)
from dirac.analysis.core.algebra import prints_shorter, tidy
from dirac.analysis.core.divisors import Division, Unsearched
from dirac.analysis.core.divisors import divisions as divisions_of
from dirac.analysis.core.linear_solve import SingularAtSamplePoint, weak_solve
from dirac.analysis.core.numeric import (
    LARGE_ROWS,
    Numerics,
    SingularSurface,
    columns_invertible_everywhere,
    independent_rows,
    numeric_rank,
)
from dirac.analysis.core.phase_space import PhaseSpace
from dirac.analysis.core.rank_loci import BracketBlocks, DivisorLocus, EntryBlock
from dirac.analysis.core.sparse_surface import LARGE_SYSTEM
from dirac.analysis.legendre.regularity import (
    IRREGULAR_GRADIENT,
    MAX_FACTOR_TERMS,
    ROUND_OFF,
    branch_hint,
    branches,
    factors,
    normal_components,
    square_free_part,
)
from dirac.errors import AnalysisError, InconsistentSystemError, SeparableParts

__all__ = ["ConstraintChain", "tidy"]

SAMPLE_POINTS = 4


#: new constraints with at most this many terms are factored, to find their branches (a few
#: ms each; most are linear in a variable and skip it); larger products are left to the
#: regular-point and rank checks at the sample points. Holonomic constraints of the
#: Lagrangian (met once) are factored up to ``MAX_FACTOR_TERMS`` terms.
FACTOR_TERMS = 24
#: a variable at most this large at every sample point spans a suspected singular locus (:meth:`ConstraintChain._off_singular_locus`)
LOCUS_SIZE = 1e-2

#: largest block of pivot rows whose exact coefficients are solved to find what the elimination divides by (:meth:`ConstraintChain._cleared`)
MAX_CLEARED_BLOCK = 2

#: length (characters) above which a stage's reducibility note is given briefly (counts, the relation, a few shown)
LONG_NOTE = 2000

#: constraints shown in a brief reducibility note
REDUCIBLE_SHOWN = 4


class _Split(Exception):
    """A new constraint is the union of branches that do not meet: each is followed on its own."""

    def __init__(self, constraint: sympy.Expr, parts: list[sympy.Expr], stage: int):
        super().__init__(f"{constraint} splits")
        self.constraint, self.parts, self.stage = constraint, parts, stage


@dataclass
class ConstraintChain:
    """Run the Dirac–Bergmann algorithm from the primary constraints.

    Parameters
    ----------
    phase_space
        The canonical phase space.
    numerics
        Numerical evaluator (surface points, weak-zero tests).
    canonical_hamiltonian
        ``H_c`` on the primary surface.
    primary
        Primary constraints ``phi_k`` (stage 1).
    multipliers
        Their multipliers ``u_k`` in ``H_T``.
    time
        The time ``t`` when the system depends on it explicitly (then the partial time
        derivative enters every consistency condition), else ``None``.

    After :meth:`run`: ``stages``, ``constraints``, ``fixed_alone`` (names of the multipliers
    the chain determines), ``solved_multipliers`` (name -> exact expression of those, read
    from the general solution, which is solved on first use), ``undetermined`` (multiplier symbols
    not fixed alone), ``multiplier_solution`` (the general solution ``u = U + v_a V_a``),
    ``points`` (regular points of the final surface), ``reducible`` (constraints
    that hold but whose gradients depend on the kept ones on the regular part of the
    surface, e.g. ``x . J = 0`` among ``J = x × p``; they still define the surface) and
    ``notes`` (``regularity_notes``: regularised and reducible constraints, for the report).
    ``written`` maps the expanded form (as :func:`tidy` gives it) of a constraint the
    user wrote as a product to that product, so that its branches are checked;
    ``holonomic`` maps the expanded form of each holonomic constraint of the Lagrangian
    to its number (an irregular one cannot be regularised inside the chain: its
    multiplier term in ``H_c`` would stay irregular). ``choices`` maps a constraint that is
    the union of disjoint branches to the branch this chain follows (or to itself when the
    union is analysed whole, its branches having the same structure). ``forces`` maps the
    momentum ``p_r`` of a coordinate to the generalized force ``Q_r`` in phase-space
    variables: Lagrange's equations with forces give ``p_dot = -dH/dq + Q``, so every
    consistency condition gains ``sum_r dPhi/dp_r Q_r`` and the multipliers are solved with it.
    ``imposed`` are phase-space functions an assumption ``EXPR = 0`` sets to zero
    (:mod:`dirac.analysis.chain.assumptions`): they join the chain as stage 2, before the
    consistency conditions of the primary constraints, without multipliers of their own, so
    that the chain finds the part of the surface on which the motion keeps them zero.
    """

    phase_space: PhaseSpace
    numerics: Numerics
    canonical_hamiltonian: sympy.Expr
    primary: list[sympy.Expr]
    multipliers: tuple[sympy.Symbol, ...]
    stages: list[list[sympy.Expr]] = field(default_factory=list)
    fixed_alone: list[str] = field(default_factory=list)
    undetermined: list[sympy.Symbol] = field(default_factory=list)
    points: list[np.ndarray] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    multiplier_solution: MultiplierSolution | None = None
    time: sympy.Symbol | None = None
    reducible: list[sympy.Expr] = field(default_factory=list)
    regularity_notes: list[str] = field(default_factory=list)
    written: dict[sympy.Expr, sympy.Expr] = field(default_factory=dict)
    holonomic: dict[sympy.Expr, int] = field(default_factory=dict)
    choices: dict[sympy.Expr, sympy.Expr] = field(default_factory=dict)
    forces: dict[sympy.Symbol, sympy.Expr] = field(default_factory=dict)
    imposed: list[sympy.Expr] = field(default_factory=list)
    #: the Hessian ``W = d^2 L / dq_dot^2`` and its rank at generic configurations (the Legendre transform's)
    hessian: sympy.Matrix | None = None
    hessian_rank: int = 0
    #: divisions by functions that are no branch: the elimination of multipliers at a stage (:meth:`_cleared`)
    divisions: list[Division] = field(default_factory=list)
    #: coefficients of those eliminations too long to search for divisions by zero (said in the report)
    unsearched: list[Unsearched] = field(default_factory=list)
    #: the rank decisions of the stages before the last: ``(s, n, rows, cols)`` for each stage ``s`` that added
    #: constraints, the pivot rows and multiplier columns of ``{Phi_a, phi_k}`` over its first ``n`` constraints
    #: (stages ``1..s``); searched for special parameter values (:mod:`dirac.analysis.chain.special_values`)
    stage_pivots: list[tuple[int, int, list[int], list[int]]] = field(default_factory=list)

    @property
    def constraints(self) -> list[sympy.Expr]:
        """All constraints, stage by stage."""
        return [c for stage in self.stages for c in stage]

    @property
    def solved_multipliers(self) -> Mapping[str, sympy.Expr]:
        """Name -> exact expression of the multipliers fixed alone (from :attr:`multiplier_solution`, solved on first use)."""
        if not self.fixed_alone or self.multiplier_solution is None:
            return {}
        return FixedMultipliers(self.fixed_alone, self.multiplier_solution)

    @property
    def total_hamiltonian(self) -> sympy.Expr:
        """``H_T = H_c + sum_k u_k phi_k`` ((207), (234))."""
        # one sum (adding term by term re-sorts the growing sum each time: O(n^2))
        return sympy.Add(self.canonical_hamiltonian, *(u * phi for u, phi in zip(self.multipliers, self.primary)))

    # ------------------------------------------------------------------ helpers
    def _rows(self, constraint: sympy.Expr) -> tuple[sympy.Expr, list[sympy.Expr]]:
        cached = self._row_cache.get(constraint)
        if cached is None:
            pb = self.phase_space.poisson_bracket
            b = pb(constraint, self.canonical_hamiltonian)
            if self.time is not None:  # d Phi/dt = {Phi, H_T} + d_t Phi for a rheonomic system
                b = b + sympy.diff(constraint, self.time)
            for momentum, force in self.forces.items():  # p_dot = -dH/dq + Q: + sum_r dPhi/dp_r Q_r
                b = b + sympy.diff(constraint, momentum) * force
            row = [sympy.S.Zero] * len(self.primary)
            support = []
            for k in self._sharing(constraint):  # only primaries sharing a canonical pair can give a non-zero bracket
                row[k] = pb(constraint, self.primary[k])
                if row[k] != 0:
                    support.append(k)
            cached = (b, row)
            self._row_cache[constraint] = cached
            self._row_support[constraint] = support
        return cached

    def _sharing(self, constraint: sympy.Expr) -> list[int]:
        """Primary constraints that contain the ``p`` of a ``q`` in ``constraint`` or the ``q`` of a ``p`` in it."""
        index = getattr(self, "_primary_index", None)
        if index is None or index[0] is not self.primary:
            by_q: dict[sympy.Symbol, list[int]] = {}
            by_p: dict[sympy.Symbol, list[int]] = {}
            for k, phi in enumerate(self.primary):
                dq, dp = self.phase_space.partials(phi)
                for q in dq:
                    by_q.setdefault(q, []).append(k)
                for q in dp:
                    by_p.setdefault(q, []).append(k)
            index = self._primary_index = (self.primary, by_q, by_p)
        _, by_q, by_p = index
        dq, dp = self.phase_space.partials(constraint)
        found = {k for q in dq for k in by_p.get(q, ())} | {k for q in dp for k in by_q.get(q, ())}
        return sorted(found)

    def _numeric_rows(self, constraints: list[sympy.Expr], points: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        """``b_a`` and ``A_ak`` at the points (shapes ``(points, rows)``, ``(points, rows, K)``); only non-zero entries are evaluated."""
        K = len(self.primary)
        where: list[int] = []
        exprs = []
        where = []  # flat positions of the entries that are not identically zero (most, at scale, are)
        for a, c in enumerate(constraints):
            b, A = self._rows(c)
            if b != 0:
                exprs.append(b)
                where.append(a * (K + 1))
            for k in self._row_support[c]:
                exprs.append(A[k])
                where.append(a * (K + 1) + k + 1)
        flat = np.zeros((len(points), len(constraints) * (K + 1)))
        if exprs:
            flat[:, where] = self.numerics.evaluate(exprs, points)
        values = flat.reshape(len(points), len(constraints), K + 1)
        return values[:, :, 0], values[:, :, 1:]

    # ------------------------------------------------------------------ the algorithm
    def run(self, max_stages: int | None = None) -> ConstraintChain:
        """Carry out the algorithm; returns ``self``.

        A new constraint that is the union of branches that do not meet (``z (z + 2) = 0``)
        is followed branch by branch through the next stages (:meth:`_follow_branches`).

        Raises
        ------
        InconsistentSystemError
            When a consistency condition cannot hold (``1 = 0`` kind), on every branch.
        AnalysisError
            When the chain does not terminate within the phase-space dimension, or
            branches with consistent motion differ in structure.
        """
        try:
            return self._run(max_stages)
        except _Split as split:
            return self._follow_branches(split, max_stages)

    def _run(self, max_stages: int | None) -> ConstraintChain:
        self._row_cache: dict = {}
        #: the sizes of the terms of derivatives (:func:`~dirac.analysis.core.rank_loci.magnitude`), shared by the stages
        self._magnitudes: dict[sympy.Expr, sympy.Expr] = {}
        self._hessian: EntryBlock | None = None
        self._minors_of: dict[tuple[tuple[sympy.Expr, ...], bool], list[BracketBlocks | EntryBlock | DivisorLocus]] = {}
        self._row_support: dict = {}  # constraint -> the k with a non-zero {Phi, phi_k}
        self._varying: dict[int, bool] = {}  # row -> whether its coefficients in the pivot rows vary between points
        self._legendre_divisors: list[sympy.Expr] | None = None  # the factors of the denominator of H_c (found on first use)
        self._divisor_locus: DivisorLocus | None = None  # their zero sets, kept away from by the sample points
        #: divisor -> whether it is a branch (None: it does not vanish on the surface), decided once per chain
        self._judged: dict[tuple[sympy.Expr, int], bool | None] = {}
        primary = [tidy(p, self.phase_space.variables, sign=True, rational=prints_shorter(p, 4000)) for p in self.primary]
        self.primary = primary
        points = self._stage_points(primary, []) if primary else []
        base_grads = self._independent(primary, [], points) if primary else []
        self.stages = [[primary[i] for i in base_grads]] if primary else []
        self.stage_pivots = []
        if primary and len(base_grads) < len(primary):
            raise AnalysisError("the primary constraints are not independent; the analysis cannot proceed")
        limit = max_stages or (self.phase_space.dimension + 2)
        if self.imposed:
            points = self._impose(points, limit)
        K = len(self.primary)
        pivots_rows: list[int] = []
        pivot_cols: list[int] = []
        settled = False  # the points of the last stage were sampled away from where the rank of C drops
        while True:
            constraints = self.constraints
            if not constraints:
                break
            _, A_num = self._numeric_rows(constraints, points)
            exprs_b = [self._rows(c)[0] for c in constraints]
            b_zero = self.numerics.weakly_zero(exprs_b, points)
            a_row_zero = np.all(np.abs(A_num) <= 1e-9 * (1 + np.max(np.abs(A_num), axis=(1, 2), keepdims=True)), axis=(0, 2)) if K else np.ones(len(constraints), bool)
            order = [i for i in range(len(constraints)) if b_zero[i] and not a_row_zero[i]]
            order += [i for i in range(len(constraints)) if not b_zero[i] and not a_row_zero[i]]
            pivots_rows = independent_rows(list(A_num), order) if K else []
            pivot_cols = independent_rows([m[pivots_rows].T for m in A_num], list(range(K))) if pivots_rows else []
            if len(pivot_cols) != len(pivots_rows):  # row and column ranks differ: not one rank at every point
                self._check_consistent_rank(A_num, pivots_rows)
                pivot_cols = columns_invertible_everywhere(list(A_num), pivots_rows)
            if len(pivot_cols) != len(pivots_rows):
                raise AnalysisError(
                    f"the consistency matrix {{Phi_a, phi_k}} has {len(pivots_rows)} independent rows but "
                    f"{len(pivot_cols)} independent multiplier columns at the sample points (stage {len(self.stages) + 1}): "
                    "its rank is not decided cleanly on this surface; analyse its parts as systems of their own"
                )
            direct: list[sympy.Expr] = []
            deferred: list[tuple[int, list[int]]] = []  # (row, pivot positions it must be reduced by)
            pivot_set = set(pivots_rows)
            for i in range(len(constraints)):
                if i in pivot_set or (b_zero[i] and a_row_zero[i]):
                    continue
                needed, used = ([], []) if a_row_zero[i] else self._needed(i, pivots_rows, pivot_cols, A_num, b_zero)
                if needed:
                    deferred.append((i, needed))
                else:
                    direct.append(self._cleared(exprs_b[i], i, used, constraints, pivots_rows, pivot_cols, A_num, b_zero))
            candidates, chosen = self._settle(self._nonzero(direct, points), constraints, limit) if direct else ([], [])
            if not chosen and deferred:
                # nothing new without them: build the conditions that need multipliers eliminated
                try:
                    eliminated = [self._eliminate(i, needed, constraints, pivots_rows, pivot_cols, A_num, b_zero) for i, needed in deferred]
                except SingularAtSamplePoint as error:
                    # the pivot block {Phi_P, phi_Q} is singular at some points only: a rank that
                    # differs between parts of the surface, which the components road separates
                    ranks = [int(np.linalg.matrix_rank(A[np.ix_(pivots_rows, pivot_cols)])) for A in A_num]
                    raise SeparableParts(
                        f"stage {len(self.stages) + 1}: {error}", points=list(points), ranks=ranks,
                        variables=list(self.phase_space.variables),
                    ) from None
                candidates, chosen = self._settle(self._nonzero(eliminated, points), constraints, limit)
            elif deferred:
                self.notes.append(
                    f"stage {len(self.stages) + 1}: {len(deferred)} consistency condition(s) that need multipliers "
                    "eliminated were deferred to the next stage and re-examined there on the smaller surface"
                )
            if not chosen and not settled and self._near_locus(points):
                # the last stage: its points must also keep away from where the rank of C drops; decide again at new ones
                settled = True
                points = self._stage_points(whole=True)
                continue
            if not chosen:
                break
            self.stage_pivots.append((len(self.stages), len(constraints), list(pivots_rows), list(pivot_cols)))
            self.stages.append([candidates[i] for i in chosen])
            self._keep_reducible(candidates, chosen)
            points = self._stage_points()
            settled = False
        self.points = points
        self._check_legendre_divisors(points)  # the final surface (the primary one may hold such points: 228)
        self.pivots = (pivots_rows, pivot_cols)
        if pivots_rows:
            self._check_consistent_rank(A_num, pivots_rows)
        self._solve_multipliers(points, pivots_rows, pivot_cols)
        return self

    def _impose(self, points: list[np.ndarray], limit: int) -> list[np.ndarray]:
        """Add the :attr:`imposed` functions as the next stage; the points of the smaller surface.

        An imposed function that vanishes on the surface already (or depends on the others)
        adds nothing; one that cannot vanish there is refused.
        """
        imposed = [tidy(c, self.phase_space.variables, sign=True) for c in self.imposed]
        try:
            candidates, chosen = self._settle(self._nonzero(imposed, points), self.constraints, limit)
        except InconsistentSystemError:
            shown = ", ".join(f"{c} = 0" for c in imposed)
            raise InconsistentSystemError(
                f"the assumption(s) {shown} cannot hold on the primary constraint surface: no part of the phase space "
                "satisfies them"
            ) from None
        if not chosen:
            return points
        self.stages.append([candidates[i] for i in chosen])
        self._keep_reducible(candidates, chosen)
        return self._stage_points()

    def _stage_points(
        self, constraints: list[sympy.Expr] | None = None, reducible: list[sympy.Expr] | None = None, whole: bool = False
    ) -> list[np.ndarray]:
        """Regular points of the surface of the constraints found so far, away from loci where a used rank drops.

        The chain reads the rank of ``{Phi_a, phi_k}`` at these points (which multipliers
        are fixed); points next to a locus where it drops are set aside
        (:func:`~dirac.analysis.core.rank_loci.near_rank_drop`). With ``whole``, so is
        ``C_ab = {Phi_a, Phi_b}`` of all the constraints, whose rank the classification
        reads at the last stage's points (:meth:`_near_locus` decides when that is needed).
        ``constraints`` and ``reducible`` default to the chain's own.
        """
        constraints = self.constraints if constraints is None else constraints
        reducible = self.reducible if reducible is None else reducible
        points = self.numerics.surface_points(
            constraints + reducible, SAMPLE_POINTS, regular=len(constraints), minors=self._minors(constraints, whole)
        )
        self._check_hessian_rank(points)
        return points

    def _check_legendre_divisors(self, points: list[np.ndarray]) -> None:
        """Refuse a surface with sample points where ``H_c`` divides by zero (a divisor of the Legendre map).

        The Legendre transform solves the velocities where a block of ``W`` is invertible;
        its determinant, a denominator of ``H_c``, may vanish on a whole part of the
        surface without ``W`` dropping rank (``L = -q1' q2' - q2'^2 - q1 q2' q3' - 2 q3' +
        2 q1^2 - q1`` with ``q2 = -1``: ``H_c`` divides by ``4 p1^2 - p1 p2 - 8 q1^2 + q1``,
        which vanishes on the branch ``q1 = 0`` of ``p1 = 0, 4 q1^2 - q1 = 0``). There ``H_c``
        and every consistency condition are undefined; points on it are refused, naming the
        divisor and the assumption that sets that part aside.
        """
        if not points:
            return
        divisors = self._divisors_of_hamiltonian()
        if not divisors:
            return
        scales = self.numerics.term_scale(divisors, points)  # first: the values below come with the sizes
        values = np.abs(self.numerics.evaluate(divisors, points))
        for k, f in enumerate(divisors):
            hit = values[:, k] <= ROUND_OFF * scales[:, k]  # NaN (undefined) is left to the rank checks
            if np.any(hit):
                raise AnalysisError(
                    f"the constraint surface has a part where the Legendre map divides "
                    f"by zero ({f} = 0 at {int(np.sum(hit))} of {len(points)} sample points): the canonical Hamiltonian and "
                    f"the consistency conditions are singular there, so that part cannot be analysed with the rest; set it "
                    f"aside with --assume \"{f} != 0\" (in Python assume=[\"{f} != 0\"]) or analyse it as a system of its own"
                )

    def _divisors_of_hamiltonian(self) -> list[sympy.Expr]:
        """The factors of the denominators of ``H_c`` (found on first use)."""
        if self._legendre_divisors is None:
            self._legendre_divisors = [d.divisor for d in divisions_of([self.canonical_hamiltonian], 1, "", self.phase_space.variables)]
        return self._legendre_divisors

    def _near_locus(self, points: list[np.ndarray]) -> bool:
        """Whether a point of the last stage lies next to a locus where ``C_ab = {Phi_a, Phi_b}`` drops rank."""
        minors = self._minors(self.constraints, whole=True)
        return any(self.numerics.near_rank_drop(minors, z) is not None for z in points)

    def _minors(self, constraints: list[sympy.Expr], whole: bool) -> list[BracketBlocks | EntryBlock | DivisorLocus]:
        """The blocks whose ranks are read at the points of ``constraints``' surface (see :meth:`_stage_points`).

        ``{Phi_a, phi_k}``, with ``whole`` also ``C_ab`` over all the constraints, and the
        Hessian ``W`` (:meth:`_hessian_block`). None
        for large systems (from ``LARGE_ROWS`` constraints or ``LARGE_SYSTEM`` phase-space
        variables): their ranks are read block by block, sparsely, without this test.
        """
        if len(constraints) >= LARGE_ROWS or self.phase_space.dimension >= LARGE_SYSTEM:
            return []
        key = (tuple(constraints), whole)
        if key not in self._minors_of:  # _near_locus and the resampling after it ask for the same blocks
            self._minors_of[key] = self._new_minors(constraints, whole)
        return self._minors_of[key]

    def _new_minors(self, constraints: list[sympy.Expr], whole: bool) -> list[BracketBlocks | EntryBlock | DivisorLocus]:
        """The blocks of :meth:`_minors`, built."""
        hessian = self._hessian_block()
        divisors = self._divisors_of_hamiltonian()
        tests: list[BracketBlocks | EntryBlock | DivisorLocus] = [hessian] if hessian is not None else []
        if divisors:  # points on a pole of H_c are set aside too (their ranks are meaningless)
            if self._divisor_locus is None:
                self._divisor_locus = DivisorLocus(self.numerics, divisors)
            tests.append(self._divisor_locus)
        if not self.primary:
            return tests
        rows = list(constraints) + [p for p in self.primary if p not in set(constraints)]
        position = {c: a for a, c in enumerate(rows)}
        own = list(range(len(constraints)))
        blocks = {"{Phi_a, phi_k}": (own, [position[p] for p in self.primary])}
        if whole:
            blocks["C_ab = {Phi_a, Phi_b}"] = (own, own)
        return [BracketBlocks(self.numerics, rows, blocks, self._magnitudes), *tests]

    def _hessian_block(self) -> EntryBlock | None:
        """The Hessian as a block whose rank is read (compiled once), when it has rank > 0 and no velocities in it."""
        if self.hessian is None or not self.hessian_rank or self.hessian.shape[0] >= LARGE_ROWS:
            return None
        known = {*self.phase_space.variables, *self.phase_space.parameters, *([self.time] if self.time is not None else [])}
        if not self.hessian.free_symbols <= known:  # W of velocities (L not quadratic in them): no function of the point
            return None
        if self._hessian is None:
            self._hessian = EntryBlock(self.numerics, self.hessian, "the Hessian W = d^2 L / dq_dot^2")
        return self._hessian

    def _check_hessian_rank(self, points: list[np.ndarray]) -> None:
        """Refuse a surface on which the Hessian has a lower rank than at generic configurations.

        The Legendre transform solves the velocities where ``W`` has its generic rank
        (Henneaux–Teitelboim, Sect. 1.1.2: the rank of ``W`` is assumed constant); when
        the constraints confine the motion to where that rank drops (``L = -q1' q2' - q2
        q1' q3' - q2' q3'``, ``det W = -2 q2``, under ``q2 = 0``), ``H_c`` and every
        consistency condition divide by zero on the surface.
        """
        block = self._hessian_block()
        if block is None or not points:
            return
        ranks = [block.rank(z) for z in points]
        if min(ranks) < self.hessian_rank:
            raise AnalysisError(
                f"the Hessian W = d^2 L / dq_dot^2 has rank {self.hessian_rank} at generic configurations, but rank "
                f"{min(ranks)} on the constraint surface found (at {sum(r < self.hessian_rank for r in ranks)} of "
                f"{len(ranks)} sample points): the velocities solved from W divide by zero there, so the canonical "
                "Hamiltonian and the consistency conditions are singular on the surface; substitute the holonomic "
                "constraints into L (eliminate the coordinates they fix) or choose coordinates in which W has one rank "
                "on the constraint surface"
            )

    def _nonzero(self, candidates: list[sympy.Expr], points: list[np.ndarray]) -> list[sympy.Expr]:
        """The candidates that are not weakly zero, tidied (constraints: the sign is free)."""
        if not candidates:
            return []
        keep = ~self.numerics.weakly_zero(candidates, points)
        for c, k in zip(candidates, keep):
            if k:  # a product as written: its branches must not meet (read before expanding)
                self._refuse_crossing(c, self.constraints)
        kept = [tidy(c, self.phase_space.variables, sign=True, rational=prints_shorter(c, 4000)) for c, k in zip(candidates, keep) if k]
        # a product, written (a holonomic constraint) or expanded (x**2 - y**2, z x + z): sample
        # points may all fall on one branch or on the crossing, so its branches are found here,
        # by factorisation, not left to chance
        fixed = self._fixed_variables(self.constraints + kept)
        followed = []
        for c in kept:
            parts = self._parts(c)
            if len(parts) < 2:
                c, parts = self._factored_on_the_surface(c, fixed)
            followed.append(self._branch(c, parts))
        return followed

    def _fixed_variables(self, constraints: list[sympy.Expr]) -> list[tuple[sympy.Expr, sympy.Symbol, sympy.Expr]]:
        """``(constraint, v, value)`` for each constraint ``a v + b`` (numbers ``a != 0``, ``b``): it fixes ``v = -b / a``."""
        variables = set(self.phase_space.variables)
        fixed = []
        for c in constraints:
            if not (c.is_Symbol or ((c.is_Add or c.is_Mul) and len(c.args) == 2)):
                continue  # a v + b has at most two terms: no walk of larger trees
            free = c.free_symbols & variables
            if len(free) == 1:
                (v,) = free
                poly = sympy.Poly(c, v) if c.is_polynomial(v) else None
                if poly is not None and poly.degree() == 1 and all(k.is_number for k in poly.all_coeffs()):
                    a, b = poly.all_coeffs()
                    fixed.append((c, v, -b / a))
        return fixed

    def _factored_on_the_surface(
        self, constraint: sympy.Expr, fixed: list[tuple[sympy.Expr, sympy.Symbol, sympy.Expr]]
    ) -> tuple[sympy.Expr, list[sympy.Expr]]:
        """``constraint`` with the variables that other constraints fix put in, when that makes it a product.

        ``N`` may be irreducible while ``N`` on ``q1 = 0`` is a product of branches: with
        ``q1 = 0`` found at the same stage, ``-p1 p2 - 2 p1 + p2^2 - 2 p2 q1 + 4 p2 + 2 q1 q3^2
        - 4 q1 + 4`` is ``(p2 + 2)(p2 + 2 - p1)`` there. The two differ by a multiple of
        ``q1``, so on the surface either is the same constraint (with the same regularity);
        the product form is followed, so that its branches are not left to chance.
        Returns ``(constraint, [constraint])`` when nothing changes.
        """
        if not fixed:
            return constraint, [constraint]
        free = constraint.free_symbols  # one walk of the tree
        values = {v: value for c, v, value in fixed if c is not constraint and v in free}
        if not values:
            return constraint, [constraint]
        reduced = constraint.xreplace(values)
        if (reduced == constraint or reduced.has(sympy.zoo, sympy.nan, sympy.oo, -sympy.oo)
                or not (reduced.free_symbols & set(self.phase_space.variables))):
            return constraint, [constraint]  # unchanged, undefined there (a fixed variable in a denominator), or a number
        reduced = tidy(reduced, self.phase_space.variables, sign=True)
        parts = self._parts(reduced)
        return (reduced, parts) if len(parts) >= 2 else (constraint, [constraint])

    def _parts(self, constraint: sympy.Expr) -> list[sympy.Expr]:
        """The branches of a new constraint: the factors that can vanish (``[constraint]`` if none)."""
        if constraint in self.written:
            return branches(self.written[constraint], self.phase_space.variables)
        limit = MAX_FACTOR_TERMS if constraint in self.holonomic else FACTOR_TERMS
        return factors(constraint, self.phase_space.variables, limit)

    def _branch(self, constraint: sympy.Expr, parts: list[sympy.Expr]) -> sympy.Expr:
        """The constraint this chain follows for a union of ``parts``: refused if they meet, else split.

        Branches that meet are refused (:meth:`_refuse_crossing`); disjoint ones raise
        :class:`_Split` unless :attr:`choices` already says which branch (or the union)
        this chain follows.
        """
        if len(parts) < 2:
            return constraint
        parts = [f for f in parts if self._vanishes_somewhere(f)]  # x for 2 p_x x on x**2 = 1: no branch
        if len(parts) < 2:
            return constraint
        self._refuse_crossing(sympy.Mul(*parts), self.constraints, constraint)
        if constraint in self.choices:
            return tidy(self.choices[constraint], self.phase_space.variables, sign=True)
        raise _Split(constraint, parts, len(self.stages) + 1)

    def _vanishes_somewhere(self, factor: sympy.Expr) -> bool:
        """Whether ``factor = 0`` has real points on the surface found so far (a branch there)."""
        try:
            self.numerics.surface_points(self.constraints + self.reducible + [factor], 1, attempts=8)
        except AnalysisError:
            return False
        return True

    def _follow_branches(self, split: _Split, max_stages: int | None) -> ConstraintChain:
        """Run the chain once per branch of ``split``; keep the branches with consistent motion.

        On the union ``f g = 0`` of branches that do not meet the motion is that of
        ``f = 0`` or that of ``g = 0`` (each regular where it holds): a branch whose chain
        becomes inconsistent has no motion and is dropped with a note (its points are
        never sampled). One surviving branch is adopted; several with the same structure
        (stage sizes, reducible constraints, free multipliers, rank of the bracket matrix)
        are analysed as the union; several of different structure are refused, naming them.
        """
        c = split.constraint
        shown = " and ".join(f"{f} = 0" for f in split.parts)
        notes = [
            f"stage {split.stage}: the zero set of the constraint {c} = 0 is the union of the branches {shown} "
            "(repeated factors taken once), which do not meet; each was followed through the next stages"
        ]
        survivors: list[tuple[sympy.Expr, ConstraintChain]] = []
        reasons = []
        for part in split.parts:
            child = self._child({**self.choices, c: part})
            try:
                child.run(max_stages)
            except InconsistentSystemError as error:
                why = str(error).removesuffix(": the Lagrangian has no consistent motion")
                reasons.append(f"on {part} = 0 {why}")
                notes.append(f"stage {split.stage}: the branch {part} = 0 of {c} = 0 was dropped, it has no consistent motion: {why}")
                continue
            survivors.append((part, child))
        if not survivors:
            raise InconsistentSystemError(f"the stage-{split.stage} constraint {c} = 0 is the union of the branches {shown}, and none has consistent motion: " + "; ".join(reasons))
        if len(survivors) > 1:
            structures = {part: child._structure() for part, child in survivors}
            if len(set(structures.values())) > 1:
                described = "; ".join(
                    f"{part} = 0: stages of sizes {', '.join(map(str, s[0]))}, bracket-matrix rank {s[3]}, free multipliers {', '.join(s[2]) or 'none'}"
                    for part, s in structures.items()
                )
                raise AnalysisError(
                    f"the stage-{split.stage} constraint {c} = 0 is the union of the branches {shown}, which do not meet but "
                    f"on which the motion has different structure ({described}); analyse the branches separately "
                    "(one system each, with the branch as its constraint)"
                )
            child = self._child({**self.choices, c: c})
            child.run(max_stages)
            notes.append(f"stage {split.stage}: the branches {shown} have the same structure; the union {c} = 0 is analysed as one surface")
            survivors = [(c, child)]
        adopted = survivors[0][1]
        for f in fields(self):
            setattr(self, f.name, getattr(adopted, f.name))
        self._row_cache = adopted._row_cache
        self._row_support = adopted._row_support
        self.pivots = adopted.pivots
        self.regularity_notes = [*adopted.regularity_notes, *notes]
        return self

    def _child(self, choices: dict[sympy.Expr, sympy.Expr]) -> ConstraintChain:
        """A fresh chain on the same system that follows the given branches."""
        return ConstraintChain(
            self.phase_space, self.numerics, self.canonical_hamiltonian, list(self.primary), self.multipliers,
            time=self.time, written=dict(self.written), holonomic=dict(self.holonomic), choices=choices,
            forces=dict(self.forces), imposed=list(self.imposed), hessian=self.hessian, hessian_rank=self.hessian_rank,
        )

    def _structure(self) -> tuple[tuple[int, ...], int, tuple[str, ...], int]:
        """Stage sizes, reducible count, free multipliers and bracket-matrix rank (to compare branches)."""
        pb = self.phase_space.poisson_bracket
        cs = self.constraints
        C = self.numerics.evaluate([pb(a, b) for a in cs for b in cs], self.points).reshape(len(self.points), len(cs), len(cs)) if cs else np.zeros((1, 0, 0))
        rank = max(numeric_rank(m) for m in C)
        return tuple(len(s) for s in self.stages), len(self.reducible), tuple(sorted(u.name for u in self.undetermined)), rank

    def _settle(self, candidates: list[sympy.Expr], constraints: list[sympy.Expr], limit: int) -> tuple[list[sympy.Expr], list[int]]:
        """Check new conditions for inconsistency and keep the independent ones (indices into ``candidates``)."""
        if not candidates:
            return [], []
        nsym = set(self.phase_space.variables)
        for c in candidates:
            if not (c.free_symbols & nsym):
                raise InconsistentSystemError(
                    f"the consistency conditions of the constraints demand {c} = 0, which cannot hold "
                    f"(stage {len(self.stages) + 1}): the Lagrangian has no consistent motion"
                )
        if len(self.stages) >= limit:
            raise AnalysisError(f"the constraint chain did not terminate after {limit} stages")
        for _ in range(2):
            new_points = self._new_points(constraints, candidates)
            chosen = self._independent(candidates, constraints, new_points)
            irregular = self._irregular(candidates, chosen, constraints, new_points)
            if irregular and not self.numerics.hold and self._off_singular_locus(candidates, constraints, irregular, new_points):
                return self._settle(candidates, constraints, limit)
            if not irregular:
                return candidates, chosen
            candidates = [self._regularised(c) if i in irregular else c for i, c in enumerate(candidates)]
        raise AnalysisError("the constraint chain could not regularise its new constraints")  # pragma: no cover

    def _off_singular_locus(
        self, candidates: list[sympy.Expr], constraints: list[sympy.Expr], irregular: list[int], points: list[np.ndarray]
    ) -> bool:
        """Whether the candidates found irregular are regular at points that hold some of their variables.

        Projections onto homogeneous conditions (``A_2 x (A_1 x A_2) = 0`` among others) fall
        onto the origin of their variables, where such conditions and their gradients
        vanish: irregular there, regular on the rest of the surface. The variables of those
        candidates that are near zero at every one of their ``points`` span the suspected
        locus; projections that hold two of them at random start values avoid it
        (:meth:`~dirac.analysis.core.numeric.Numerics._held_variables`). When the candidates
        are regular at such points, every later projection of this analysis holds them
        and a note says so; otherwise nothing changes.
        """
        involved = set().union(*(candidates[i].free_symbols for i in irregular)) & set(self.phase_space.variables)
        variables = list(self.phase_space.variables)
        indices = sorted(variables.index(v) for v in involved)
        values = np.abs(np.asarray(points)[:, indices]) if points else np.ones((1, len(indices)))
        small = [i for i, column in zip(indices, values.T) if np.all(column <= LOCUS_SIZE)]
        self.numerics.hold = tuple(small if len(small) >= 3 else indices)
        try:
            points = self._new_points(constraints, candidates)
            chosen = self._independent(candidates, constraints, points)
            still = self._irregular(candidates, chosen, constraints, points)
        except AnalysisError:
            still = irregular
        if not self.numerics.hold or set(still) & set(irregular):
            self.numerics.hold = ()
            return False
        shown = ", ".join(f"{candidates[i]} = 0" for i in irregular[:2]) + (" ..." if len(irregular) > 2 else "")
        self.regularity_notes.append(
            f"stage {len(self.stages) + 1}: the sample points first fell where the gradients of new constraints "
            f"vanish ({shown}); every later point was found holding two of their variables at random values, "
            "which keeps the points on the regular part of the surface"
        )
        return True

    def _new_points(self, constraints: list[sympy.Expr], candidates: list[sympy.Expr]) -> list[np.ndarray]:
        """Regular points of the old surface on which the candidates vanish too."""
        try:
            return self.numerics.surface_points(constraints + self.reducible + candidates, SAMPLE_POINTS, regular=len(constraints))
        except SingularSurface:
            raise
        except AnalysisError:
            shown = "; ".join(f"{c} = 0" for c in candidates[:4])
            raise InconsistentSystemError(
                f"the stage-{len(self.stages) + 1} conditions {shown} have no real solution together with "
                "the earlier constraints: the Lagrangian has no consistent motion"
            ) from None

    # ------------------------------------------------------------------ regularity
    def _regularised(self, constraint: sympy.Expr) -> sympy.Expr:
        """``f`` for a constraint ``f^k`` (``k > 1``): the same surface, with a gradient that does not vanish on it.

        Henneaux–Teitelboim, Sect. 1.1.2 (regularity conditions) and Sect. 1.2.2 (Cawley's
        ``z^2 = 0``, regular as ``z = 0``). The replacement is recorded in
        :attr:`regularity_notes`. Called for a constraint found irregular at surface points.

        Raises
        ------
        AnalysisError
            When the constraint has no repeated factor (e.g. ``x^2 + y^2 = 0``): no
            regular form is known, the analysis is refused.
        """
        part = square_free_part(constraint, self.phase_space.variables)
        if part is None:
            raise AnalysisError(
                f"the stage-{len(self.stages) + 1} constraint {constraint} = 0 is irregular: its gradient vanishes "
                "at every point found where it holds (independent of the earlier constraints only by round-off), and "
                "it is not a power of a simpler polynomial (the points may also lie on a singular part of a surface "
                "that is regular elsewhere); write the surface with constraints whose gradients are independent on it "
                "(e.g. x = 0 and y = 0 instead of x**2 + y**2 = 0)" + branch_hint(self.constraints, self.phase_space.variables)
            )
        self._refuse_crossing(part, self.constraints)
        regular = tidy(part, self.phase_space.variables, sign=True)
        parts = factors(regular, self.phase_space.variables, MAX_FACTOR_TERMS)
        if constraint in self.holonomic:
            raise AnalysisError(
                f"constraint {self.holonomic[constraint]} ({constraint} = 0) is irregular: its gradient vanishes where it "
                f"holds, so its multiplier cannot enforce it; write it as its square-free part {regular} = 0 (the same "
                "surface, described regularly)"
            )
        self.regularity_notes.append(
            f"stage {len(self.stages) + 1}: the constraint {constraint} = 0 is irregular (its gradient vanishes where it "
            f"holds); it was replaced by its square-free part {regular} = 0, the same surface described regularly; "
            "the classes and counts below refer to this regular form (with the irregular form, first-class "
            "constraints need not all generate gauge transformations, as in Cawley's example)"
        )
        return self._branch(regular, parts)

    def _refuse_crossing(self, constraint: sympy.Expr, constraints: list[sympy.Expr], shown_as: sympy.Expr | None = None) -> None:
        """Refuse a product ``f g = 0`` whose branches meet on the surface (no single regular surface there).

        ``shown_as`` is the constraint as the chain met it (expanded), when ``constraint`` is its product form.
        """
        parts = branches(constraint, self.phase_space.variables)
        name = constraint if shown_as is None else shown_as
        if len(parts) < 2:
            return
        holonomic = self.holonomic.get(name) or self.holonomic.get(tidy(name, self.phase_space.variables, sign=True))
        for i in range(len(parts)):
            for j in range(i + 1, len(parts)):
                try:
                    self.numerics.surface_points(constraints + self.reducible + [parts[i], parts[j]], 1, attempts=8)
                except AnalysisError:
                    continue  # these branches do not meet: the product is regular where it holds
                shown = " and ".join(f"{f} = 0" for f in parts)
                where = f"constraint {holonomic} ({name} = 0)" if holonomic else f"the stage-{len(self.stages) + 1} constraint {name} = 0"
                raise SeparableParts(
                    f"{where} is irregular: it is the union of the "
                    f"branches {shown}, which meet (where {parts[i]} = {parts[j]} = 0 its gradient vanishes), so there "
                    f"is no single regular constraint surface; analyse the branches {shown} separately "
                    + ("(one system each, with the branch as its constraint)" if holonomic
                       else f"(one system each, or one part of this one with --assume \"{parts[0]} = 0\", in Python "
                            f"assume=[\"{parts[0]} = 0\"])"),
                    holonomic=holonomic,
                    branches=list(parts),
                )

    def _irregular(self, candidates: list[sympy.Expr], chosen: list[int], old: list[sympy.Expr], points: list[np.ndarray]) -> list[int]:
        """New constraints whose gradient is numerically zero where they hold (normal to the others' gradients).

        A kept constraint is compared with the old ones, a dropped one with the old and the
        kept ones. A component below ``IRREGULAR_GRADIENT`` (relative to the size of the
        gradient's terms) at every point, yet above round-off, marks a gradient that
        vanishes on the surface: ``f^2 = 0`` or ``x^2 + y^2 = 0``.
        """
        n = len(self.phase_space.variables)
        if n >= LARGE_SYSTEM:  # one factorisation per point instead of one per candidate
            return irregular_candidates(self.phase_space, self.numerics, candidates, chosen, old, self.reducible, points)
        everything = old + self.reducible + [candidates[i] for i in chosen]
        grads = [g for c in everything for g in self.phase_space.gradient(c)]
        stacked = self.numerics.evaluate(grads, points).reshape(len(points), len(everything), n)
        n_old = len(old) + len(self.reducible)
        found = []
        for i, c in enumerate(candidates):
            grad = self.phase_space.gradient(c)
            rows = self.numerics.evaluate(grad, points)
            base = stacked[:, :n_old] if i in chosen else stacked
            rough = [normal_components(rows[p : p + 1], base[p], np.ones(1) + np.max(np.abs(base[p]), initial=0.0))[0] for p in range(len(points))]
            if max(rough) > 1e-2:  # clearly regular: skip the finer test
                continue
            scales = self.numerics.term_scale(grad, points).sum(axis=1) - (n - 1)  # 1 + sum of |terms| of the gradient
            sizes = np.array([normal_components(rows[p : p + 1], base[p], scales[p : p + 1])[0] for p in range(len(points))])
            if np.all(sizes < IRREGULAR_GRADIENT) and np.any(sizes > ROUND_OFF):
                found.append(i)
        return found

    def _check_consistent_rank(self, A_num: np.ndarray, rows: list[int]) -> None:
        """The pivot rows of ``A_ak = {Phi_a, phi_k}`` must be independent at every sample point.

        They were chosen by majority; a point where their rank is lower lies on a part of
        the surface with another structure (the rank is never taken from some points
        only). Refused, naming a constraint that factors into branches when there is one.
        """
        ranks = []
        for A in A_num:
            block = A[rows]
            scale = np.max(np.abs(block)) or 1.0
            ranks.append(numeric_rank(block / scale))
        if len(set(ranks)) == 1 and ranks[0] == len(rows):
            return
        cause = branch_hint(self.constraints, self.phase_space.variables)
        raise AnalysisError(
            "the rank of the consistency matrix {Phi_a, phi_k} that fixes the multipliers differs between regular "
            f"points of the constraint surface ({', '.join(map(str, ranks))} for {len(rows)} pivot rows): the surface "
            f"has parts of different structure{cause or '; analyse each part as a system of its own'}"
        )

    def _keep_reducible(self, candidates: list[sympy.Expr], chosen: list[int]) -> None:
        """Keep the new constraints left out as dependent: they still define the surface (reducible set)."""
        dropped = [c for i, c in enumerate(candidates) if i not in chosen]
        if not dropped:
            return
        self.reducible.extend(dropped)
        note = (
            f"stage {len(self.stages)}: the constraints {', '.join(str(c) for c in candidates)} are reducible: on the "
            f"regular part of their surface {', '.join(str(c) for c in dropped)} depend(s) on the others "
            f"(independent set kept: {', '.join(str(candidates[i]) for i in chosen)}); the dependent ones still "
            "define the surface and every sample point satisfies them"
        )
        self.regularity_notes.append(note if len(note) <= LONG_NOTE else self._brief_reducible_note(candidates, chosen, dropped))

    def _brief_reducible_note(self, candidates: list[sympy.Expr], chosen: list[int], dropped: list[sympy.Expr]) -> str:
        """The reducibility note of a large stage: counts, the relation when it is the plain sum, a few constraints."""
        shown = ", ".join(str(c) for c in candidates[:REDUCIBLE_SHOWN])
        relation = self._exact_relation(candidates, chosen, dropped) or f"{len(dropped)} relation(s) among them"
        return (
            f"stage {len(self.stages)}: the {len(candidates)} constraints {shown}, ... are reducible ({relation}); on the "
            f"regular part of their surface {len(dropped)} of them ({', '.join(str(c) for c in dropped[:REDUCIBLE_SHOWN])}"
            f"{', ...' if len(dropped) > REDUCIBLE_SHOWN else ''}) depend(s) on the {len(chosen)} others, which are kept; "
            "the dependent ones still define the surface and every sample point satisfies them "
            "(all of them: the analysis' reducible_constraints)"
        )

    def _exact_relation(self, candidates: list[sympy.Expr], chosen: list[int], dropped: list[sympy.Expr]) -> str:
        """``d + sum_i r_i c_i = 0`` for the one dependent constraint ``d`` of a stage, when it holds identically
        with rational ``r_i`` (linear constraints with constant coefficients, such as Gauss laws); else ``""``.

        The ``r_i`` are read off the gradients at one random point (least squares over the kept
        constraints' sparse gradients), rounded to small rationals and then verified exactly by
        expansion: a relation is stated only when ``sympy.expand`` proves it.
        """
        if len(dropped) != 1 or not chosen:
            return ""
        from scipy.sparse.linalg import lsqr

        kept = [candidates[i] for i in chosen]
        point = [self.numerics.random_point()]
        [rows] = self.numerics.sparse_gradients(kept, point)
        [row] = self.numerics.sparse_gradients(dropped, point)
        coefficients = lsqr(rows.T.tocsr(), -row.toarray().ravel(), atol=1e-14, btol=1e-14)[0]
        r = [sympy.Rational(round(float(c) * 12), 12) for c in coefficients]
        if sympy.expand(dropped[0] + sympy.Add(*(ri * c for ri, c in zip(r, kept)))) != 0:
            return ""
        used = sum(1 for ri in r if ri != 0) + 1
        which = f"all {used}" if used == len(candidates) else f"{used} of them"
        if all(ri in (0, 1, -1) for ri in r):
            return f"one relation, proved exactly: a signed sum (coefficients +1 or -1) of {which} vanishes identically"
        values = sorted({abs(ri) for ri in r if ri != 0} | {sympy.S.One}, key=float)
        return f"one relation, proved exactly: a combination of {which} with coefficients of size {', '.join(map(str, values))} vanishes identically"

    def _needed(self, row: int, P: list[int], Q: list[int], A_num: np.ndarray, b_zero: np.ndarray) -> tuple[list[int], list[int]]:
        """Pivot rows (positions in ``P``) with a non-zero ``b`` that row ``row`` must be reduced by, and all it uses.

        ``A_row = c . A_P`` at the points; the second list has every ``k`` with ``c_k != 0``
        (also those whose ``b`` vanishes: their coefficients divide, :meth:`_cleared`).
        """
        if not P:
            return [], []
        coeff = np.array([np.linalg.lstsq(A[np.ix_(P, Q)].T, A[row, Q], rcond=None)[0] for A in A_num])
        scale = 1 + np.max(np.abs(coeff), axis=1, keepdims=True)
        used = [k for k in range(len(P)) if not np.all(np.abs(coeff[:, k]) <= 1e-9 * scale[:, 0])]
        # coefficients equal at every point are numbers: no division by a function to check (:meth:`_cleared`)
        varying = [k for k in used if np.ptp(coeff[:, k]) > 1e-9 * (1 + np.max(np.abs(coeff[:, k])))]
        self._varying[row] = bool(varying)
        return [k for k in used if not b_zero[P[k]]], used

    def _coefficients(self, row: int, used: list[int], constraints: list[sympy.Expr], P: list[int], Q: list[int], A_num: np.ndarray) -> list[sympy.Expr]:
        """The exact ``c_k`` (``k`` in ``used``) of ``A_row = sum_k c_k A_{P_k}`` on the surface.

        A square block of ``|used|`` columns of ``Q`` independent at the points is solved
        (:func:`weak_solve`); ``[]`` when every entry involved is a number (no division by a
        function) or no such block is found.
        """
        if len(used) > MAX_CLEARED_BLOCK:
            return []  # a symbolic solve of a larger block costs more than the stage (the rigid body (228): 2x)
        rows = [P[k] for k in used]
        entries = [[self._rows(constraints[p])[1][q] for q in Q] for p in rows]
        target = [self._rows(constraints[row])[1][q] for q in Q]
        if all(e.is_number for line in entries for e in line) and all(e.is_number for e in target):
            return []
        cols = independent_rows([A[np.ix_(rows, Q)].T for A in A_num], list(range(len(Q))))
        if len(cols) != len(rows):
            return []
        Qc = [Q[j] for j in cols]
        sub = sympy.Matrix([[entries[r][j] for j in cols] for r in range(len(rows))])
        rhs = sympy.Matrix([target[j] for j in cols])
        if sub.shape == (1, 1):
            return [sympy.cancel(rhs[0, 0] / sub[0, 0])] if sub[0, 0] != 0 else []
        c = weak_solve(sub.T, rhs, [A[np.ix_(rows, Qc)].T for A in A_num], [A[row, Qc].reshape(-1, 1) for A in A_num], variables=self.phase_space.variables)
        return list(c)

    def _cleared(
        self, psi: sympy.Expr, row: int, used: list[int], constraints: list[sympy.Expr], P: list[int], Q: list[int],
        A_num: np.ndarray, b_zero: np.ndarray, coefficients: list[sympy.Expr] | None = None,
    ) -> sympy.Expr:
        """The condition ``psi`` of row ``row`` with the factors the elimination divided by kept where they are branches.

        ``psi = b_row - c . b_P`` holds where the coefficients ``c`` of ``A_row = c . A_P`` are
        defined; fraction-free, the condition is ``D psi = 0`` with ``D`` the common
        denominator of ``c`` (Bareiss-style elimination keeps every factor it would divide
        away). An irreducible factor ``f`` of ``D`` is a branch of the next stage when the
        consistency conditions can be solved at points of the surface where ``f = 0``
        (:meth:`_solvable_where`): then the new constraint is ``f psi``, a product that is
        followed or refused branch by branch (:meth:`_branch`). A factor on whose zeros they
        cannot be solved only marks where the elimination divides by zero; it is recorded
        in :attr:`divisions`. ``L = x x' z + x z - 2 x' z^2/3 + 2 y y' z + y z'``: the row of
        ``p_x`` is ``(4z/3 - x)/(1 - 2y)`` times that of ``p_y`` (whose ``b`` is 0), so its
        condition ``z = 0`` held only where ``1 - 2y != 0``; ``z (1 - 2y) = 0`` keeps the
        branch ``y = 1/2``.
        """
        if coefficients is None:
            coefficients = self._coefficients(row, used, constraints, P, Q, A_num) if used and self._varying.get(row) else []
        stage = len(self.stages) + 1
        branches = []
        for division in divisions_of(coefficients, stage, "the elimination of multipliers divides by zero", self.phase_space.variables,
                                     unsearched=self.unsearched):
            f = division.divisor
            key = (f, len(constraints))  # one verdict per divisor and surface
            if key not in self._judged:
                self._judged[key] = self._solvable_where(f, constraints)
            genuine = self._judged[key]
            if genuine:
                branches.append(f)
            elif genuine is not None:
                self.divisions.append(division)
        return sympy.Mul(*branches, psi) if branches else psi

    def _solvable_where(self, f: sympy.Expr, constraints: list[sympy.Expr]) -> bool | None:
        """Whether ``b + A u = 0`` can be solved at points of the surface where ``f = 0`` too (``None``: no such point).

        At each point (up to ``SAMPLE_POINTS``), ``rank [A | b] == rank A``, relative to the
        size of the entries.
        """
        try:
            points = self.numerics.surface_points(constraints + self.reducible + [f], SAMPLE_POINTS, attempts=4 * SAMPLE_POINTS)
        except AnalysisError:
            return None
        b_num, A_num = self._numeric_rows(constraints, points)
        for b, A in zip(b_num, A_num):
            augmented = np.hstack([A, b[:, None]])
            scale = np.max(np.abs(augmented)) or 1.0
            if numeric_rank(augmented / scale, scale=1.0) != numeric_rank(A / scale, scale=1.0):  # one scale: round-off is no rank
                return False
        return True

    def _independent(self, candidates: list[sympy.Expr], old: list[sympy.Expr], points: list[np.ndarray]) -> list[int]:
        n = len(self.phase_space.variables)
        if n >= LARGE_SYSTEM:  # sparse gradients, independence by sparse elimination
            cand_sparse = self.numerics.sparse_gradients(candidates, points)
            base_sparse = self.numerics.sparse_gradients(old, points) if old else None
            return independent_rows(cand_sparse, list(range(len(candidates))), base=base_sparse, notes=self.regularity_notes)
        cand = gradient_values(self.phase_space, self.numerics, candidates, points)
        base = list(gradient_values(self.phase_space, self.numerics, old, points)) if old else None
        return independent_rows(list(cand), list(range(len(candidates))), base=base, equilibrate=True)

    def _eliminate(self, row, needed, constraints, P, Q, A_num, b_zero):
        """``psi_a = b_a - c_a . b_P`` for a row that shares multipliers with the pivot rows ``needed``.

        Factors of the denominators of ``c_a`` that are branches are kept (:meth:`_cleared`).
        """
        b_row = self._rows(constraints[row])[0]
        A_sym = sympy.Matrix([[self._rows(constraints[p])[1][k] for k in Q] for p in P])
        rhs = sympy.Matrix([self._rows(constraints[row])[1][k] for k in Q])
        c = weak_solve(A_sym.T, rhs, [A[np.ix_(P, Q)].T for A in A_num], [A[row, Q].reshape(-1, 1) for A in A_num], variables=self.phase_space.variables)
        psi = b_row - sum((c[k, 0] * self._rows(constraints[P[k]])[0] for k in needed), sympy.S.Zero)
        return self._cleared(psi, row, [], constraints, P, Q, A_num, b_zero, coefficients=[e for e in c if e != 0])

    @staticmethod
    def _fixed_alone_at_point(M: np.ndarray) -> np.ndarray:
        """Which ``u_k`` the rows ``M = A_P`` fix alone at one point: ``e_k`` in their row space.

        ``rank [M; e_k] == rank M`` (numerically, relative to ``max |M|``). When ``M`` has full
        column rank ``K`` with its smallest singular value above the cut of every
        ``[M; e_k]`` — adding a row does not lower a singular value (Cauchy interlacing,
        Golub & Van Loan, Sect. 8.1.2) and raises the largest at most to
        ``sqrt(s_1^2 + 1)`` — every ``u_k`` is fixed, with one SVD instead of one per ``k``.
        """
        K = M.shape[1]
        s = np.max(np.abs(M)) or 1.0
        scaled = M / s
        rank = numeric_rank(scaled)
        if rank == K:
            sv = np.linalg.svd(scaled, compute_uv=False)
            if sv[K - 1] > 1e-8 * np.sqrt(sv[0] ** 2 + 1.0):
                return np.ones(K, dtype=int)
        fixed = np.zeros(K, dtype=int)
        for k in range(K):
            e = np.zeros(K)
            e[k] = 1.0
            fixed[k] = numeric_rank(np.vstack([M, e * s]) / s) == rank
        return fixed

    def _solve_multipliers(self, points, P, Q) -> None:
        """Solve ``b_P + A_PQ u_Q = 0`` for the determined multipliers ((214)-(215) ff.).

        Also the general solution ``u = U + v_a V_a`` (:attr:`multiplier_solution`, see
        :mod:`dirac.analysis.classes.multiplier_solution`); a multiplier counts as determined when
        it is fixed alone.
        """
        K = len(self.primary)
        self.fixed_alone = []
        constraints = self.constraints
        taken = [s.name for s in (*self.phase_space.variables, *self.phase_space.parameters)]
        self.multiplier_solution = unsolved_multipliers(self.multipliers, self.primary, self.canonical_hamiltonian, taken)
        if not K:
            return
        if not constraints or not P:
            self.undetermined = list(self.multipliers)
            return
        b_num, A_num = self._numeric_rows(constraints, points)
        votes = np.zeros(K, dtype=int)
        for A in A_num:
            votes += self._fixed_alone_at_point(A[P])
        determined = [k for k in range(K) if 2 * votes[k] > len(A_num)]
        self.undetermined = [self.multipliers[k] for k in range(K) if k not in determined]
        order = determined + [k for k in range(K) if k not in determined]
        self.multiplier_solution = general_multiplier_solution(
            self.multipliers,
            self.primary,
            self.canonical_hamiltonian,
            sympy.Matrix([self._rows(constraints[p])[1] for p in P]),
            sympy.Matrix([self._rows(constraints[p])[0] for p in P]),
            [A[P] for A in A_num],
            [b[P] for b in b_num],
            order,
            self.phase_space.variables,
            taken,
        )
        self.fixed_alone = [self.multipliers[k].name for k in determined]
