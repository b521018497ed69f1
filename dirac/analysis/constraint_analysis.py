"""``analyze(lagrangian) -> ConstraintAnalysis``: the whole Dirac–Bergmann algorithm.

Legendre transform (primary constraints, ``H_c``, ``H_T``), the constraint chain, the
first/second-class split, the physical degrees of freedom and the Dirac bracket (240),
for a Lagrangian with holonomic constraints whose multipliers are coordinates (the
paper's (1); Sect. X for the rigid body (78), Sect. XI for (228)).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np
import sympy

from dirac.analysis.brackets.dirac_bracket import DiracBracket
from dirac.analysis.chain.assumptions import parse_assumptions
from dirac.analysis.chain.constraint_chain import ConstraintChain
from dirac.analysis.chain.special_values import RankUse, SpecialValue, special_parameter_values
from dirac.analysis.classes.classification import bracket_matrix, classify
from dirac.analysis.classes.multiplier_solution import MultiplierSolution, unsolved_multipliers
from dirac.analysis.core.algebra import rational_parts, tidy
from dirac.analysis.core.blas_threads import one_blas_thread
from dirac.analysis.core.budget import CpuBudget, OverBudget
from dirac.analysis.core.divisors import (
    LEGENDRE_SINGULAR,
    MULTIPLIERS_SINGULAR,
    Division,
    SingularLocus,
    Undecided,
    Unsearched,
    divisions,
    nonvanishing_on,
    pfaffian,
    singular_loci,
    sum_of_squares_on_surface,
)
from dirac.analysis.core.gram_proof import GramProver
from dirac.analysis.core.linear_solve import SolveTooLarge
from dirac.analysis.core.numeric import Numerics, independent_rows, numeric_rank
from dirac.analysis.core.phase_space import free_symbols_of
from dirac.analysis.core.sparse_surface import LARGE_SYSTEM
from dirac.analysis.legendre.numeric_map import LegendreMap, MomentumSymbols
from dirac.analysis.legendre.regularity import regular_holonomic
from dirac.analysis.legendre.transform import legendre_transform
from dirac.analysis.report import to_json, to_latex, to_text
from dirac.errors import AnalysisError, InputError, warn
from dirac.model.lagrangian import Lagrangian, momentum_name, velocity_name

if TYPE_CHECKING:  # imported where used: most analyses never ask for them (start-up time of the CLI)
    from dirac.analysis.brackets.vector_field import VectorField
    from dirac.analysis.gauge.generators import GaugeGenerator, GaugeStructure

__all__ = ["ConstraintAnalysis", "analyze"]

#: largest second-class set whose bracket matrix counts as small
SMALL_SECOND_CLASS = 8

#: largest second-class set whose ``det C`` is formed to find where the Dirac bracket divides by zero
SMALL_DETERMINANT = 4

#: seconds allowed for the exact solve of one component of equations_of_motion()
EXACT_BRACKET_SECONDS = 60.0


def _phase_space_forces(lagrangian: Lagrangian, velocities: Mapping[sympy.Symbol, sympy.Expr]) -> dict[str, sympy.Expr]:
    """The generalized forces ``Q_r(q, q_dot, t)`` as functions on phase space, by coordinate name.

    The velocities are replaced by their solution ``q_dot(q, p)`` of the Legendre transform.

    Raises
    ------
    AnalysisError
        A force depends on a velocity that the momenta do not determine (a singular
        Hessian): then ``Q`` is no function on phase space.
    """
    result: dict[str, sympy.Expr] = {}
    for q, Q in lagrangian.forces.items():
        used = Q.free_symbols & set(lagrangian.velocities)
        missing = sorted(v.name for v in used if v not in velocities)
        if missing:
            raise AnalysisError(
                f"the force on {q.name!r} depends on {', '.join(missing)}, which the momenta do not determine (the "
                "Hessian of L is singular): such a force is no function on phase space; write it without those "
                "velocities"
            )
        result[q.name] = Q.xreplace({v: velocities[v] for v in used}) if used else Q
    return result


def _generic_parameter_values(lagrangian: Lagrangian, rng: np.random.Generator) -> dict:
    """Random positive values (0.7-1.9) for the parameters: decisions hold generically."""
    return {p: float(rng.uniform(0.7, 1.9)) for p in lagrangian.parameters}


class ConstraintAnalysis:
    """Result of the Dirac–Bergmann algorithm on one Lagrangian (use :func:`analyze`).

    Attributes
    ----------
    lagrangian, name
        The input and its name.
    coordinates, momenta, phase_space
        ``q`` then ``lambda_1, ...``; ``p_q`` then ``p_lambda_...``; both concatenated.
    symbols
        Name -> symbol of every phase-space variable (names: docs/conventions.md).
    parameters
        Parameter symbols that are still symbolic.
    canonical_hamiltonian, total_hamiltonian
        ``H_c`` and ``H_T = H_c + u_k phi_k`` ((207), (234)).
    primary_multipliers
        The multipliers ``u_1, u_2, ...`` of the primary constraints in ``H_T``
        (:attr:`multipliers`: the expressions of those fixed alone).
    undetermined_multipliers
        The ``u_k`` not fixed alone (free, or fixed only in combinations).
    multiplier_solution
        The general solution ``u = U + v_a V_a`` of the consistency conditions: a
        :class:`~dirac.analysis.classes.multiplier_solution.MultiplierSolution` with
        ``.particular`` (name -> expression), ``.null_vectors`` (list of name ->
        expression), the free ``.free`` (``v_1, ...``), the first-class combinations
        ``.first_class_primary`` and ``.total_hamiltonian`` ``H' + v_a phi_a``. Its
        numeric decisions are taken during the analysis; the exact ``U`` and ``V_a`` (a
        symbolic elimination, long for a long chain) are computed the first time they are read.
    stages, constraints
        The chain stage by stage (stage 1 = primary) and flat: an independent set.
    reducible_constraints
        Constraints that hold on the surface but whose gradients depend on the kept ones
        there (a reducible set such as ``J = x × p``, with ``x . J = 0``); empty for an
        irreducible set.
    first_class, second_class
        The classes; ``physical_degrees_of_freedom = (2n - 2 #first - #second) / 2``.
    time
        The time symbol ``t`` when ``L`` or a constraint depends on it explicitly (a
        rheonomic system: the constraints, ``H_c`` and the multipliers may depend on
        ``t``), else ``None``.
    bracket_strategy
        How Dirac brackets are computed ("symbolic", "block" or "numeric", and why).
    special_parameter_values
        :class:`~dirac.analysis.chain.special_values.SpecialValue` list: parameter values at
        which a rank the analysis used drops (:mod:`dirac.analysis.chain.special_values`).
    notes
        How the decisions were made (for the report), including regularised and
        reducible constraints.
    """

    def __init__(
        self,
        lagrangian: Lagrangian,
        seed: int = 20240607,
        progress: Callable[[str], None] | None = None,
        assume: Sequence[str] = (),
    ) -> None:
        start = time.perf_counter()
        clock = [start]

        def done(message: str) -> None:
            """One line per stage of the algorithm, with its seconds, to ``progress``."""
            if progress is not None:
                now = time.perf_counter()
                progress(f"{message} ({now - clock[0]:.2f} s)")
                clock[0] = now

        nonzero_text = [str(a) for a in assume if "!=" in str(a)]
        equality_text = [str(a) for a in assume if "!=" not in str(a)]
        self.assumptions = tuple(str(a) for a in assume)
        lagrangian, regularised = regular_holonomic(lagrangian)
        self.lagrangian = lagrangian
        self.name = lagrangian.name
        rng = np.random.default_rng(seed)
        self._generic = _generic_parameter_values(lagrangian, rng)
        legendre = legendre_transform(lagrangian, rng, self._generic)
        self._legendre = legendre
        done(f"Legendre transform: Hessian rank {legendre.rank}, {_count(len(legendre.primary), 'primary constraint')}")
        space = legendre.phase_space
        self._space = space
        self.coordinates = space.coordinates
        self.momenta = MomentumSymbols(space.momenta, lambda q, q_dot, t: self._legendre_map().momenta(q, q_dot, t))
        self.phase_space = space.variables
        self.symbols = space.symbols
        self.parameters = tuple(lagrangian.parameters)
        self.hessian = legendre.hessian
        self.hessian_rank = legendre.rank
        self.canonical_hamiltonian = legendre.canonical_hamiltonian
        K = len(legendre.primary)
        self.primary_multipliers = tuple(sympy.Symbol(f"u_{k + 1}", real=True) for k in range(K))
        self.forces = _phase_space_forces(lagrangian, legendre.velocity_solution)
        forced_in_time = lagrangian.time is not None and any(lagrangian.time in e.free_symbols for e in self.forces.values())
        self.time = lagrangian.time if (lagrangian.is_time_dependent or forced_in_time) else None
        self._numerics = Numerics(space, self._generic, seed=seed, time=self.time)
        assumable = {**space.symbols, **{p.name: p for p in lagrangian.parameters}}
        if self.time is not None:
            assumable[self.time.name] = self.time
        nonzero = parse_assumptions(nonzero_text, assumable)
        equalities = parse_assumptions(equality_text, assumable)
        self._numerics.avoid = [a.expression for a in nonzero]
        chain = ConstraintChain(
            space, self._numerics, legendre.canonical_hamiltonian, legendre.primary, self.primary_multipliers, time=self.time
        )
        chain.forces = {space.symbols[momentum_name(name)]: Q for name, Q in self.forces.items()}
        expanded = [tidy(chi, space.variables, sign=True) for chi in lagrangian.constraints]
        chain.written = {e: chi for e, chi in zip(expanded, lagrangian.constraints) if isinstance(chi, sympy.Mul)}
        chain.holonomic = {e: k for k, e in enumerate(expanded, start=1)}
        chain.imposed = [e.expression for e in equalities]
        chain.hessian, chain.hessian_rank = legendre.hessian, legendre.rank
        chain.run()
        self._chain = chain
        done(f"constraint chain: {_count(len(chain.stages), 'stage')} "
             f"(sizes {', '.join(str(len(stage)) for stage in chain.stages) or '-'}), "
             f"{_count(len(chain.constraints), 'constraint')}")
        self.primary_constraints = list(chain.primary)
        self.total_hamiltonian = chain.total_hamiltonian
        self.stages = chain.stages
        self.constraints = chain.constraints
        self.reducible_constraints = list(chain.reducible)
        self._multipliers: Mapping[str, sympy.Expr] = chain.solved_multipliers  # names now, exact values on first read
        self.undetermined_multipliers = list(chain.undetermined)
        self.multiplier_solution: MultiplierSolution = chain.multiplier_solution or unsolved_multipliers((), [], self.canonical_hamiltonian, [])
        self._points = chain.points
        C = bracket_matrix(space, self.constraints)
        cls = classify(space, self._numerics, self.constraints, self._points, C)
        self.first_class = cls.first_class
        self.second_class = cls.second_class
        self.bracket_matrix_rank = cls.rank
        done(f"classification: {len(cls.first_class)} first-class, {len(cls.second_class)} second-class")
        dim = space.dimension
        self.physical_degrees_of_freedom = (dim - 2 * len(self.first_class) - len(self.second_class)) // 2
        if (dim - 2 * len(self.first_class) - len(self.second_class)) % 2:
            raise AnalysisError("odd number of physical phase-space dimensions: the classification is inconsistent")
        C2 = C[cls.second_indices, cls.second_indices] if cls.second_indices else sympy.zeros(0, 0)
        self._bracket = DiracBracket(space, self.second_class, C2, self._numerics, self._points, lagrangian.parameters)
        self._defaults_numerics: Numerics | None = None
        self._legendre_numeric: LegendreMap | None = None
        done("Dirac bracket set up")
        s = len(self.second_class)
        if s == 0:
            self.bracket_strategy = "symbolic: no second-class constraints, the Dirac bracket is the Poisson bracket"
        elif s <= SMALL_SECOND_CLASS:
            self.bracket_strategy = (
                f"symbolic: C is {s}x{s}; exact brackets solve C x = {{Phi, B}} exactly after dropping weakly "
                "zero entries; numeric brackets (at=) solve C at the point"
            )
        else:
            self.bracket_strategy = (
                f"block: C is {s}x{s}, too large to invert symbolically; exact brackets drop weakly zero terms, "
                "skip corrections that vanish weakly ((246) with (239)) and otherwise solve only the "
                "block-triangular pieces of C they need; numeric brackets (at=) solve C at the point"
            )
        self.notes = [
            f"Legendre transform: {legendre.method}",
            "weak zeros, independence and ranks decided numerically at "
            f"{len(self._points)} random points of each constraint surface"
            + (" (symbolic parameters at generic random values)" if self.parameters else ""),
            *regularised,
            *chain.regularity_notes,
            *dict.fromkeys(self._numerics.notes),
            *(f"assumed {a}: every point of the surface where ranks were decided is away from {a.expression} = 0" for a in nonzero),
            *(f"assumed {e}: imposed as a constraint of stage 2 (no multiplier of its own, the Lagrangian unchanged); "
              "the later stages keep only the part of the surface on which the motion keeps it" for e in equalities),
        ]
        if self.forces:
            self.notes.append(
                "generalized forces Q act (Lagrange's equations d/dt dL/dq_dot - dL/dq = Q + constraint forces): "
                "p_dot = -dH/dq + Q, so every consistency condition is d Phi/dt = {Phi, H_T} + sum_r dPhi/dp_r Q_r "
                "(+ d_t Phi), and the multipliers are solved with the forces; the Dirac bracket and the classes "
                "are those of H (forces are not Hamiltonian)"
            )
        if space.dimension >= LARGE_SYSTEM:
            self.notes.append(
                f"large system ({space.dimension} phase-space variables): surface points found with the sparse "
                "Jacobian (minimum-norm steps by sparse LU, LSQR where rows depend), regular points tested block by "
                "block (large blocks by their L D L^T factorisation), independence of constraint gradients decided by "
                "sparse elimination (by the dense orthogonalisation pass where a row is not clearly decided), brackets "
                "only between expressions that share a canonical pair, the rank of C over its connected blocks; weak "
                "zeros and the exact multiplier solve stay on the dense path (that solve runs the first time the "
                "multipliers are read: analysis.multipliers values, multiplier_solution, the report)"
            )
        if self.time is not None and lagrangian.is_time_dependent:
            self.notes.append(
                "time-dependent (rheonomic) system: the consistency conditions are d Phi/dt = {Phi, H_T} + "
                "d_t Phi with the partial time derivative; t is sampled at random like a variable in the "
                "numerical decisions, and the constraints may depend on t"
            )
        self.gauge_conditions: tuple[str, ...] = ()
        self._gauge: GaugeStructure | None = None
        self.special_parameter_values: list[SpecialValue] = []
        #: the parameter case tree (:mod:`dirac.analysis.cases`) when asked for: ``dirac.analyze(system, cases=True)``
        self.parameter_cases: list | None = None
        #: the parts of a surface with parts of different structure (:class:`dirac.analysis.components.Component`), else empty
        self.components: list = []
        self._generic_analysis: ConstraintAnalysis | None = None
        self._singular_loci: tuple[SingularLocus, ...] | None = None
        self._unsearched: tuple[Unsearched | Undecided, ...] = ()
        self._seed = seed
        if self.parameters:
            self.special_parameter_values, searched = self._special_values(chain, C, cls.second_indices, seed)
            self.notes.extend(searched)
        self.seconds = time.perf_counter() - start

    @property
    def singular_loci(self) -> tuple[SingularLocus, ...]:
        """Loci of the constraint surface where an expression of the analysis divides by zero.

        Every non-constant divisor (an irreducible factor of a denominator) of the Legendre
        map (the velocities and ``H_c``: ``det W``, a coordinate singularity such as
        ``sin(theta) = 0`` for Euler angles), of the elimination of multipliers at each
        stage (factors that are no branch), of the multiplier solution ``u = U + v_a V_a``
        and, for at most ``SMALL_DETERMINANT`` second-class constraints, of ``det C`` in the
        Dirac bracket (240), tested against the surface (:mod:`dirac.analysis.core.divisors`).
        Computed on first use (the exact multiplier solution is solved then); a tuple of
        :class:`~dirac.analysis.core.divisors.SingularLocus`, empty when none.
        """
        if self._singular_loci is None:
            self._singular_loci = self._find_singular_loci()
        return self._singular_loci

    @property
    def singular_loci_unsearched(self) -> tuple[Unsearched | Undecided, ...]:
        """What the search for divisions by zero left open: the expressions of the analysis too long to
        search (:class:`~dirac.analysis.core.divisors.Unsearched`, one record per place and stage, for
        the elimination of multipliers in the chain, or a tree too large to walk), and the divisors read
        off the trees of long expressions that are neither proven nonzero on the surface nor found to
        vanish there (:class:`~dirac.analysis.core.divisors.Undecided`, one per divisor, with the
        reason); empty when everything was decided. A division by zero there is neither among
        :attr:`singular_loci` nor ruled out, and the report says so."""
        _ = self.singular_loci
        return self._unsearched

    def _find_singular_loci(self) -> tuple[SingularLocus, ...]:
        """The divisions recorded and found in the results, tested against the surface (:attr:`singular_loci`)."""
        variables = self._space.variables
        legendre = self._legendre
        surface = [*self.constraints, *self.reducible_constraints]
        settled = nonvanishing_on(surface, variables)  # denominators proven nonzero on the surface are not factored
        unsearched: list[Unsearched | Undecided] = list(self._chain.unsearched)
        skipped: list[Unsearched] = []
        found: list[Division] = divisions(
            [*legendre.velocity_solution.values(), self.canonical_hamiltonian], 1, LEGENDRE_SINGULAR, variables, settled,
            unsearched=skipped, structural=True,
        )
        found += self._chain.divisions
        solution = self.multiplier_solution
        if self._chain.multiplier_solution is not None and self.constraints:
            exprs = [*solution.particular.values(), *(e for vec in solution.null_vectors for e in vec.values())]
            found += divisions(exprs, len(self.stages), MULTIPLIERS_SINGULAR, variables, settled, unsearched=skipped,
                               structural=True)
        if 0 < len(self.second_class) <= SMALL_DETERMINANT:
            C = bracket_matrix(self._space, self.second_class)
            # det C = Pf(C)^2 (C is antisymmetric, of even size): det C vanishes where the numerator of
            # Pf(C) in lowest terms does, and a Pfaffian proven nonzero on the surface leaves no division
            # by zero. Read off Pf(C), a sum of products of entries reduced in the fraction field:
            # sympy's det of even a 2 x 2 C with rational entries cancels their products as
            # expressions and ran for minutes (a random 3-coordinate Lagrangian)
            # (the second class is even in number: an odd count is refused when the analysis is made)
            pf = pfaffian(C)
            if not self._pfaffian_settled(pf, surface, settled):
                parts = rational_parts(pf)
                found += divisions([1 / (parts[0] if parts is not None else pf)], len(self.stages),
                                   "the Dirac bracket divides by zero (det C = 0: the bracket matrix of the second-class "
                                   "constraints drops rank)", variables, unsearched=skipped, structural=True)
        unsearched += skipped
        if not found:
            self._unsearched = tuple(unsearched)
            return ()
        # the analysis' compiled functions shared (the constraints' gradients are compiled already), fresh random points
        numerics = self._numerics.sharing_compiled(self._generic, seed=self._seed + 1)
        numerics.avoid = list(self._numerics.avoid)
        undecided: list[Undecided] = []
        gram = GramProver.on_first_use(self.canonical_hamiltonian, self._space.coordinates, self._space.momenta,
                                       surface, variables, partials=self._space.partials)  # Gram minors (Cauchy-Binet)
        loci = singular_loci(found, surface, numerics, variables, undecided=undecided,
                             regular_at=self._solved_block_regular(numerics), gram=gram)
        self._unsearched = (*unsearched, *undecided)
        return loci

    def _pfaffian_settled(self, pf: sympy.Expr, surface: list, settled: Callable[[sympy.Expr], bool]) -> bool:
        """Whether ``det C = Pf(C)^2`` is proven nonzero on the surface from ``pf = Pf(C)``: a nonzero
        constant there, or, factored, a product of such constants and sums of squares
        (:func:`~dirac.analysis.core.divisors.sum_of_squares_on_surface`; a pendulum's
        ``Pf(C) = -16 (x^2 + y^2)^2 / m^2``)."""
        return settled(pf) or sum_of_squares_on_surface(sympy.factor(pf), surface, self._space.variables)

    def _solved_block_regular(self, numerics: Numerics) -> Callable[[np.ndarray], bool] | None:
        """``z -> bool``: whether the block ``A_PQ`` the exact multiplier solution inverts has full rank at the
        point ``z`` (finite values, rank by SVD); ``None`` when there is no such block.

        The rank is cut relative to the block's size at the analysis' generic points of the
        surface (its largest singular value there), not to its size at ``z``: on a locus where
        the block vanishes, ``z`` is found to rounding (``[[0, y], [-y, 0]]`` at ``y = 1e-18``),
        and singular values of pure rounding, compared with each other, would count as full rank.
        """
        chain_solution = self._chain.multiplier_solution
        block = getattr(chain_solution, "matrix", None)
        if block is None or block.shape[0] == 0:
            return None
        scale: float | None = None
        if self._points:
            generic = numerics.evaluate(list(block), list(self._points)).reshape(len(self._points), *block.shape)
            sizes = [float(np.linalg.norm(values, 2)) for values in generic if np.all(np.isfinite(values))]
            scale = max(sizes) if sizes else None

        def regular(z: np.ndarray) -> bool:
            values = numerics.evaluate(list(block), [z]).reshape(block.shape)
            return bool(np.all(np.isfinite(values))) and numeric_rank(values, scale=scale) == block.shape[0]

        return regular

    @property
    def multipliers(self) -> Mapping[str, sympy.Expr]:
        """Name -> exact expression of each multiplier fixed alone (``u_k`` of ``H_T``), weakly
        simplified. The names are known after the analysis; the expressions are read from
        :attr:`multiplier_solution`, whose exact solve runs the first time one is read."""
        return self._multipliers

    @multipliers.setter
    def multipliers(self, value: Mapping[str, sympy.Expr]) -> None:
        self._multipliers = value

    # ------------------------------------------------------------------ gauge
    @property
    def gauge_structure(self) -> GaugeStructure:
        """Castellani's gauge generators and the first-class constraints without one
        (:mod:`dirac.analysis.gauge.generators`); computed on first use."""
        if self._gauge is None:
            from dirac.analysis.gauge.generators import gauge_structure

            self._gauge = gauge_structure(self)
        return self._gauge

    @property
    def gauge_generators(self) -> list[GaugeGenerator]:
        """One generator ``G = sum_k eps^(k) G_k`` per independent gauge parameter (empty
        without gauge freedom); see :mod:`dirac.analysis.gauge.generators`."""
        return self.gauge_structure.generators

    def fix_gauge(self, conditions: Sequence[sympy.Expr | str]) -> ConstraintAnalysis:
        """The analysis with gauge conditions ``chi_i = 0`` added (:mod:`dirac.analysis.gauge.fixing`).

        Raises
        ------
        InputError
            For conditions that are not admissible; the message names the condition.
        """
        from dirac.analysis.gauge.fixing import fix_gauge

        return fix_gauge(self, conditions)

    def _special_values(self, chain: ConstraintChain, C: sympy.Matrix, second: list[int], seed: int) -> tuple[list[SpecialValue], list[str]]:
        """Parameter values where a rank the analysis used drops (:mod:`dirac.analysis.chain.special_values`).

        The ranks searched: the Hessian's, that of the consistency matrix ``A_PQ`` of every
        stage (the earlier stages' too: at ``m = 0`` Fierz-Pauli's stage-2 block, which fixes
        the multipliers of ``h0i`` through the mass term, vanishes and the chain stops there,
        although the last stage's matrix still has the generic rank on the generic surface)
        and that of the second-class block of ``C``. Blocks larger than ``MAX_BLOCK`` are
        scanned numerically (with a note).
        """
        space = self._space
        uses = []
        unsearched: list[str] = []
        params = set(self.parameters)
        W = self.hessian
        everything = self.constraints + self.reducible_constraints
        K = len(chain.primary)

        def consistency(n: int) -> sympy.Matrix:
            return sympy.Matrix([[chain._rows(c)[1][k] for k in range(K)] for c in chain.constraints[:n]])

        memo: dict = {}  # free symbols of shared sub-trees, walked once (free_symbols_of)

        def involves(M: sympy.Matrix) -> frozenset:
            return free_symbols_of(M, memo) & params

        if self.hessian_rank and involves(W):
            if W.free_symbols & set(self.lagrangian.velocities):
                unsearched.append(
                    "special parameter values: not searched in the Hessian, which depends on the velocities "
                    "(L is not quadratic in them)"
                )
            else:
                points = [self._numerics.random_point() for _ in range(3)]
                values = self._numerics.evaluate(list(W), points).reshape(len(points), *W.shape)
                S = independent_rows(list(values), list(range(W.shape[0])))
                uses.append(RankUse("Hessian", W[S, S], W, len(S), on_surface=False))
        # the earlier stages: each on the surface of the constraints it knew
        for stage, n, rows, cols in getattr(chain, "stage_pivots", []):
            if not rows:
                continue
            A = consistency(n)
            if not involves(A[rows, cols]):
                continue
            uses.append(RankUse(f"consistency matrix {{Phi_a, phi_k}} of stage {stage}", A[rows, cols], A, len(rows),
                                on_surface=True, surface=chain.constraints[:n], symbols=free_symbols_of(A[rows, cols], memo)))
        P, Q = chain.pivots
        if P:
            A = consistency(len(chain.constraints))
            if involves(A[P, Q]):
                uses.append(RankUse("consistency matrix {Phi_a, phi_k}", A[P, Q], A, len(P), on_surface=True,
                                    symbols=free_symbols_of(A[P, Q], memo)))
        if second and involves(C[second, second]):
            uses.append(RankUse("bracket matrix C", C[second, second], C, len(second), on_surface=True,
                                symbols=free_symbols_of(C[second, second], memo), antisymmetric=True))
        found, skipped = special_parameter_values(
            space, self._generic, uses, lambda sub: [c.subs(sub) for c in everything], seed, time=self.time,
            compiled=self._numerics, starts=chain.points,
        )
        return found, unsearched + skipped

    # ------------------------------------------------------------------ brackets
    def poisson_bracket(self, f: sympy.Expr | str, g: sympy.Expr | str) -> sympy.Expr:
        """Canonical Poisson bracket ``{f, g}`` (``{q, p} = 1``; Sect. X)."""
        return self._space.poisson_bracket(self._bracket._sympify(f), self._bracket._sympify(g))

    def dirac_bracket(self, f: sympy.Expr | str, g: sympy.Expr | str, at: Mapping[str, float] | None = None,
                      time_limit: float | None = EXACT_BRACKET_SECONDS):
        """Dirac bracket (240) over the second-class constraints.

        Parameters
        ----------
        f, g
            Phase-space functions (sympy expressions in :attr:`symbols`, or names).
        at
            Optional numeric point ``{name: value}``; then a float is returned, computed
            without any symbolic inverse of ``C`` (compiled once per pair ``f, g``).
        time_limit
            CPU seconds the exact bracket may take (``None``: no limit); the numeric one has none.

        Returns
        -------
        sympy.Expr or float
            Exact bracket, weakly simplified on the constraint surface; or its value.

        Raises
        ------
        AnalysisError
            When the exact bracket takes longer than ``time_limit`` (the message names ``at=point``).
        """
        if at is not None:
            return self._bracket.at(f, g, at)
        f_expr, g_expr = self._bracket._sympify(f), self._bracket._sympify(g)
        if time_limit is None:
            return self._bracket.exact(f_expr, g_expr)
        clock = CpuBudget(time_limit)
        try:
            with clock.interrupting():
                return self._bracket.exact(f_expr, g_expr)
        except OverBudget:
            raise AnalysisError(
                f"the exact Dirac bracket {{{f_expr}, {g_expr}}}_D of {self.name!r} took more than {time_limit:g} s of "
                "CPU time (its solve of C x = {Phi, g} grows with the second-class constraints); evaluate it at a point "
                "with dirac_bracket(f, g, at=point), or give a larger time_limit (None: no limit)"
            ) from None

    def equations_of_motion(
        self,
        variables: Sequence[sympy.Expr | str] | None = None,
        at: Mapping[str, float] | None = None,
        time_limit: float = EXACT_BRACKET_SECONDS,
    ) -> dict:
        """Reduced Hamiltonian vector field ``z_dot = {z, H}_D`` on the constraint surface.

        ``H = H_c + u_k phi_k`` over the primary constraints whose multipliers stay free
        (first class); those ``u_k`` stay as symbols. Second-class terms of ``H_T`` drop
        out of Dirac brackets ((240); for the rigid body (250)-(251) follow). When
        second-class constraints depend explicitly on the time ``t``,
        ``z_dot = {z, H}_D - {z, Phi_a} (C^{-1})^{ab} d_t Phi_b`` (Gitman–Tyutin), so that
        the motion stays on the moving surface; ``at`` then needs ``t`` too.

        Parameters
        ----------
        variables
            The phase-space functions ``z`` to compute ``z_dot`` of: symbols, names of
            phase-space variables, or expressions (e.g. ``M_k = -eps_kij (R^T p)_ij``,
            (233)). Default: every phase-space variable.
        at
            Optional numeric point ``{name: value}``: then each ``z_dot`` is a float
            computed there (no symbolic solve).
        time_limit
            Seconds allowed for the exact solve of each component.

        Returns
        -------
        dict
            ``z -> z_dot`` (keys are the sympy expressions of ``variables``).

        Raises
        ------
        AnalysisError
            If a component's exact Dirac bracket is too large to solve symbolically
            (bracket matrix block or time over its limit); the message names it.
        InputError
            For a name that is not a phase-space variable.
        """
        H = self.__dict__.get("_motion_hamiltonian")
        if H is None:
            free = set(self.undetermined_multipliers)
            H = self.canonical_hamiltonian + sum(
                (u * phi for u, phi in zip(self.primary_multipliers, self.primary_constraints) if u in free),
                sympy.S.Zero)
            self.__dict__["_motion_hamiltonian"] = H
        items = list(self.phase_space) if variables is None else [self._bracket._sympify(z) for z in variables]
        result: dict = {}
        if at is not None:  # the whole vector z_dot at the point from one solve; each z reads it off
            motion = self._bracket.field_at(H, at)
            if motion is not None:
                z_dot, args = motion
                if variables is None:
                    return dict(zip(items, z_dot.tolist()))
                position = self._bracket.positions
                for z in items:
                    k = position.get(z)
                    result[z] = float(z_dot[k]) if k is not None else float(self._bracket.gradient_at(z, args) @ z_dot)
                return result
        for z in items:
            if at is not None:
                result[z] = self._bracket.at(z, H, at) + self._bracket.explicit_time_term(z, at)
                continue
            try:
                result[z] = self._bracket.exact(z, H, time_limit=time_limit)
                if self.time is not None:  # second-class constraints with explicit t
                    result[z] = result[z] + self._bracket.explicit_time_term(z, time_limit=time_limit)
            except SolveTooLarge as exc:
                raise AnalysisError(
                    f"the exact Dirac bracket {{{z}, H}}_D of {self.name!r} cannot be found symbolically: {exc}; "
                    "evaluate it at a point with equations_of_motion(..., at=point), or ask only for the "
                    "components you need with equations_of_motion(variables=[...])"
                ) from None
        return result

    def vector_field(self, parameters: Mapping[str, float] | None = None,
                     multipliers: Mapping[str, float] | None = None) -> VectorField:
        """The compiled Dirac vector field ``f(t, y)`` for ``scipy.integrate.solve_ivp``.

        ``f(t, y)`` is ``z_dot = {z, H}_D`` (240) at the state ``y`` (the variables
        ``f.names``, in the order of :attr:`symbols`), ``H`` as in
        :meth:`equations_of_motion` with the free multipliers ``u_k`` given (default 0);
        ``f.batch(Y)`` evaluates many states, ``f.residual(y)`` the constraints.
        See :class:`dirac.analysis.brackets.vector_field.VectorField`.

        Parameters
        ----------
        parameters
            Values of the symbolic parameters (default: the Lagrangian's defaults).
        multipliers
            Values of the free multipliers of first-class primary constraints.

        Raises
        ------
        InputError
            Unknown names, parameters without a value, values that are not finite.
        """
        from dirac.analysis.brackets.vector_field import vector_field

        return vector_field(self, parameters, multipliers)

    # ------------------------------------------------------------------ points
    def _legendre_map(self) -> LegendreMap:
        """``p = dL/dq_dot`` and its inverse at the default parameter values (generated once)."""
        if self._legendre_numeric is None:
            self._legendre_numeric = LegendreMap(self.lagrangian, tuple(self.momenta), self.time)
        return self._legendre_numeric

    def velocities(self, point: Mapping[str, float], t: float | None = None) -> dict[str, float]:
        """The velocities ``q_dot`` (names ``x_dot``) at a phase-space point: ``p = dL/dq_dot`` solved.

        ``point`` holds the coordinates and their momenta (e.g. a :meth:`surface_point`;
        for a system whose momenta depend on the time, ``t`` is read from it unless
        given). Parameters at their defaults. Inverse of ``analysis.momenta(q, q_dot)``;
        see :mod:`dirac.analysis.legendre.numeric_map`.

        Raises
        ------
        InputError
            Missing values, or a singular ``d^2 L/dq_dot^2`` at the point (the momenta do
            not determine every velocity).
        """
        return self._legendre_map().velocities(point, t)

    def surface_point(self, values: Mapping[str, float] | None = None, seed: int | None = None) -> dict[str, float]:
        """A numeric point on the full constraint surface, completing the given values.

        Parameters are at their defaults (symbolic parameters without a default make this
        fail). Variables given in ``values`` are held fixed; the others are solved for
        (Gauss–Newton from a random start), e.g. given ``q`` and ``p`` this finds the
        multipliers ``lambda`` (the fourth stage) and ``p_lambda = 0``. Velocities may be
        given instead of momenta (``x_dot``: then every coordinate is needed, velocities
        not given are 0, and ``p = dL/dq_dot`` (205), :attr:`momenta`). For a
        time-dependent system the point is on the surface at the time ``t`` (given in
        ``values``, else 0), which the returned point includes.

        Raises
        ------
        InputError
            Unknown names, parameters without default, a velocity and its momentum both
            given, or values that no point of the surface has.
        """
        values = dict(values or {})
        values = self._momenta_from_velocities(values)
        self._space.check_names({k: v for k, v in values.items() if self.time is None or k != self.time.name}, "surface_point")
        missing = [p.name for p, v in self.lagrangian.parameters.items() if v is None]
        if missing:
            raise InputError(f"parameters {', '.join(missing)} have no default value: fix them (Lagrangian.fix) first")
        if self._defaults_numerics is None:
            self._defaults_numerics = Numerics(self._space, dict(self.lagrangian.parameters), time=self.time)
        numerics = self._defaults_numerics
        numerics.rng = np.random.default_rng(seed)
        index = {s.name: i for i, s in enumerate(self.phase_space)}
        if self.time is not None:  # the time is the last component of a point (0 unless given)
            index[self.time.name] = len(self.phase_space)
            values.setdefault(self.time.name, 0.0)
        fixed = {index[k]: float(v) for k, v in values.items()}
        try:
            if self.gauge_conditions:
                from dirac.analysis.gauge.fixing import regular_gauge_point

                point = regular_gauge_point(self, numerics, fixed)
            else:
                point = numerics.surface_points(self.constraints + self.reducible_constraints, 1, fixed=fixed)[0]
        except AnalysisError:
            if fixed:
                raise InputError(
                    f"no point of the constraint surface of {self.name!r} has the given values "
                    f"({', '.join(f'{k}={v}' for k, v in values.items())}): give values that satisfy the constraints"
                ) from None
            raise
        named = (*self.phase_space, self.time) if self.time is not None else self.phase_space
        return {s.name: float(x) for s, x in zip(named, point)}

    def _momenta_from_velocities(self, values: dict[str, float]) -> dict[str, float]:
        """``values`` with the velocities (``x_dot``) given in it replaced by the momenta ``p = dL/dq_dot``."""
        coordinates = [q.name for q in self.lagrangian.coordinates]
        rates = {name: values.pop(name) for name in [velocity_name(c) for c in coordinates] if name in values}
        if not rates:
            return values
        twice = [momentum_name(name[:-4]) for name in rates if momentum_name(name[:-4]) in values]
        if twice:
            raise InputError(f"surface_point: give a velocity or its momentum, not both ({', '.join(twice)} and its velocity)")
        t = values.get(self.time.name, 0.0) if self.time is not None else None
        momenta = self._legendre_map().momenta({c: values[c] for c in coordinates if c in values}, rates, t,
                                               what="surface_point with velocities")
        return {**values, **momenta}

    # ------------------------------------------------------------------ reports
    def to_json(self) -> dict:
        """The ``dirac analyze --json`` object of docs/file_formats.md (plus extra keys).

        With parts of different structure, ``"components"`` lists each (:mod:`dirac.analysis.components`);
        with assumptions, ``"assumptions"`` lists them.
        """
        data = to_json(self)
        if self.assumptions:
            data["assumptions"] = list(self.assumptions)
        if self.components:
            data["components"] = [c.to_json() for c in self.components]
        return data

    def to_text(self) -> str:
        """The chain stage by stage, classes, multipliers, counts: readable text (and each part, with components)."""
        text = to_text(self)
        if self.components:
            text += "\n\ncomponents of the constraint surface:"
            text += "".join(f"\n  - {c.condition}: {c.summary()}" for c in self.components)
        return text

    def to_latex(self) -> str:
        """The analysis as a LaTeX fragment (align environments)."""
        return to_latex(self)

    def _repr_latex_(self) -> str:
        return to_latex(self, display=True)

    def __repr__(self) -> str:
        counts = "+".join(str(len(s)) for s in self.stages) or "0"
        return (
            f"<ConstraintAnalysis {self.name!r}: stages {counts}, {len(self.first_class)} first class, "
            f"{len(self.second_class)} second class, {self.physical_degrees_of_freedom} degrees of freedom>"
        )


def _count(number: int, noun: str) -> str:
    """``1 stage``, ``4 stages``."""
    return f"{number} {noun}{'' if number == 1 else 's'}"


def analyze(
    lagrangian: Lagrangian, progress: Callable[[str], None] | None = None, assume: Sequence[str] = ()
) -> ConstraintAnalysis:
    """Run the Dirac–Bergmann algorithm on ``lagrangian``.

    Parameters
    ----------
    lagrangian
        A :class:`~dirac.model.lagrangian.Lagrangian` (quadratic in the velocities) with
        holonomic constraints; their multipliers become coordinates (the paper's (1)).
    progress
        Called with one line as each stage of the algorithm finishes (the Legendre
        transform, the constraint chain, the classification, the Dirac bracket), each
        with its seconds; ``None`` (the default) reports nothing.
    assume
        Assumptions that pick a part of the phase space: ``"EXPR != 0"`` keeps every point
        where a rank is decided away from ``EXPR = 0``; ``"EXPR = 0"`` adds ``EXPR`` (a
        function of the coordinates) as a holonomic constraint
        (:mod:`dirac.analysis.chain.assumptions`).

    Returns
    -------
    ConstraintAnalysis

    Raises
    ------
    InconsistentSystemError
        If the consistency conditions demand something like ``1 = 0``.
    AnalysisError
        If the Lagrangian is not quadratic in the velocities, the chain cannot be
        carried out, or a constraint is irregular with no regular form (branches that
        cross, a gradient that vanishes where the constraint holds).

    Warns
    -----
    DiracWarning
        When a parameter's value in the system lies on a special parameter value: the
        analysis is then at that value (see :func:`at_given_values`).

    Examples
    --------
    >>> import dirac
    >>> analysis = dirac.analyze(dirac.load_system("pendulum"))
    >>> [len(stage) for stage in analysis.stages], analysis.physical_degrees_of_freedom
    ([1, 1, 1, 1], 1)
    """
    if not isinstance(lagrangian, Lagrangian):
        raise InputError(f"analyze() needs a dirac.Lagrangian, not {type(lagrangian).__name__}")
    if isinstance(assume, str):
        assume = [assume]
    with one_blas_thread():  # small dense matrices: threads only wait (dirac.analysis.core.blas_threads)
        return at_given_values(ConstraintAnalysis(lagrangian, progress=progress, assume=assume), progress)


def at_given_values(analysis: ConstraintAnalysis, progress: Callable[[str], None] | None = None) -> ConstraintAnalysis:
    """The analysis at the parameter values written in the system, when they are special.

    The analysis is symbolic in its parameters (generic structure). When the value a
    parameter has in the system (its default: the system file, or ``--param``) lies on a
    special parameter value (:mod:`dirac.analysis.chain.special_values`), the structure there
    differs from the generic one: the analysis is done again with those parameters fixed
    to their values (what the user wrote), with a note and a :class:`~dirac.errors.DiracWarning`
    saying that generic values give another structure.
    """
    values = {p.name: v for p, v in analysis.lagrangian.parameters.items()}
    hits = [s for s in analysis.special_parameter_values if s.holds_at(values)]
    if not hits:
        return analysis
    names = {h.parameter for h in hits} | {sym.name for h in hits for sym in h.value.free_symbols}
    names |= {sym.name for h in hits if h.factor is not None for sym in h.factor.free_symbols}
    given = {n: v for n in sorted(names) if (v := values.get(n)) is not None}
    fixed = analysis.lagrangian.fix(**given)
    at = ConstraintAnalysis(fixed, progress=progress, assume=analysis.assumptions)
    shown = ", ".join(f"{h.parameter} = {h.value}" for h in hits if not h.is_curve)
    curves = "; ".join(h.equation for h in hits if h.is_curve)
    if curves:  # name the values given and the curve they lie on
        values_text = ", ".join(f"{n} = {float(v):g}" for n, v in given.items())
        opening = f"{values_text}, the values given for {analysis.name!r}, lie on the special parameter curve {curves}"
        opening += f" (special parameter value {shown})" if shown else ""
    else:
        opening = f"{shown}, the value given for {analysis.name!r}, is a special parameter value"
    generic = (
        f"{len(analysis.first_class)} first class, {len(analysis.second_class)} second class, "
        f"physical degrees of freedom {analysis.physical_degrees_of_freedom}"
    )
    here = (
        f"{len(at.first_class)} first class, {len(at.second_class)} second class, "
        f"physical degrees of freedom {at.physical_degrees_of_freedom}"
    )
    message = (
        f"{opening} "
        f"({'; '.join(h.where for h in hits)}): the analysis is at {'those values' if curves else 'that value'} "
        f"({here}); for generic values "
        f"the structure differs ({generic})"
    )
    at.notes.append(message)
    at.special_parameter_values = analysis.special_parameter_values
    at._generic_analysis = analysis
    warn(message)
    return at
