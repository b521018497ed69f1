"""Gauge generators of an analysed system by Castellani's algorithm.

For each primary first-class combination ``gamma`` (one per free multiplier ``v``), the
generator of the gauge transformations with parameter ``eps(t)`` is

    G = sum_{k=0}^{N} eps^(k) G_k,     delta z = {z, G},

with the chain (L. Castellani, Ann. Phys. 143 (1982) 357; Henneaux–Teitelboim, ch. 3)

    G_N = gamma                       (primary first class),
    G_{k-1} + {G_k, H'} = PFC         (k = N, ..., 1),
    {G_0, H'} = PFC,

where ``PFC`` is a combination of primary first-class constraints and ``H' = H_c + U_q phi_q``
the first-class Hamiltonian: ``H_T = H' + v_f gamma_f`` with ``U`` the particular solution
of the multiplier equations ``{Phi_i, H_c} + {Phi_i, phi_a} u_a ~ 0`` whose free components
vanish, and ``gamma_f = phi_f + V_fq phi_q`` spanning their homogeneous solutions
(Henneaux–Teitelboim, ch. 1; Gitman–Tyutin, ch. 2). The chain is built downwards,
``G_{k-1} = -{G_k, H'} + c_a gamma_a``, and closes at the first ``G_0`` whose bracket with
``H'`` is ``PFC``. The free coefficients ``c_a`` (functions) are chosen so that
``{G_{k-1}, H'} = -{R, H'} + c_a S_a + PFC`` (``R = {G_k, H'}``, ``S_a = {gamma_a, H'}``)
has no ``S_a``-components: ``c_a`` are the ``S_a``-coefficients of ``{R, H'}`` expanded
over the constraints (:func:`_expansion`). In abelian models ``c = 0``; in a
Yang–Mills-type model they give the covariant derivative ``delta A = eps_dot + [eps, A]``.
Second-class constraints vanish strongly in the Dirac bracket, so with second-class
constraints "PFC" is read modulo them (their gradients are allowed in the closing test;
Henneaux–Teitelboim, ch. 3). For a time-dependent analysis (constraints, ``H'`` or gauge
conditions with an explicit ``t``) every ``{X, H'}`` above is ``{X, H'} + d_t X``, since
``dG/dt = d_t G + {G, H_T}`` with ``d_t`` acting on the ``eps^(k)`` and on ``t`` alike.

The conditions are exactly ``dG/dt = dG/dt|_eps + {G, H_T} = PFC`` for every ``eps(t)``:
then ``delta z`` maps solutions of ``z_dot = {z, H_T}`` to solutions, with the free
multipliers transformed as well (Castellani; Henneaux–Teitelboim, ch. 3). Each term is checked
to be first class at points of the constraint surface.

First-class constraints outside the span of all the ``G_k`` generate no gauge
transformation of the equations of motion: Dirac's conjecture (every first-class
constraint generates one) does not hold for them, as in Cawley's example. They are
listed in :attr:`GaugeStructure.without_transformation`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import sympy

from dirac.analysis.core.algebra import prints_shorter, tidy
from dirac.analysis.core.linear_solve import TIDY_LIMIT, weak_solve
from dirac.analysis.core.numeric import independent_rows
from dirac.analysis.core.phase_space import PhaseSpace
from dirac.analysis.core.sparse_surface import LARGE_SYSTEM
from dirac.analysis.gauge.local_span import BlockBasis, gradient_sizes, in_span_by_blocks, sparse_gradients

__all__ = [
    "FirstClassHamiltonian",
    "GaugeGenerator",
    "GaugeStructure",
    "first_class_hamiltonian",
    "gauge_structure",
    "parameter_name",
    "transformation",
]

#: relative size below which a residual counts as zero in the span tests
SPAN_TOLERANCE = 1e-8

#: largest gradient of a generator term, at every surface point, that counts as vanishing:
#: an irregular constraint such as p^2 = 0 is met by the Gauss-Newton points only to
#: |p| ~ sqrt(residual), so its gradient there is ~1e-6, while a regular one's is O(1)
IRREGULAR_GRADIENT = 1e-4


def independent(matrices: Sequence[np.ndarray], order: Sequence[int]) -> list[int]:
    """:func:`~dirac.analysis.core.numeric.independent_rows`, and none of a matrix that is zero at every point."""
    if not len(matrices) or all(not m.size or not np.any(m) for m in matrices):
        return []
    return independent_rows(matrices, order)


def parameter_name(index: int, order: int) -> str:
    """Name of the ``order``-th time derivative of the gauge parameter ``eps_index``:
    ``eps_1``, ``eps_1_dot``, ``eps_1_ddot``, ``eps_1_d3``, ..."""
    base = f"eps_{index}"
    if order == 0:
        return base
    if order <= 2:
        return f"{base}_{'d' * order}ot"
    return f"{base}_d{order}"


@dataclass
class FirstClassHamiltonian:
    """``H_T = H' + v_f gamma_f``: the split of the total Hamiltonian by its free multipliers.

    Attributes
    ----------
    hamiltonian
        ``H' = H_c + U_q phi_q`` (first class).
    primary_first_class
        ``gamma_f = phi_f + V_fq phi_q``, one per free multiplier.
    free
        Index ``f`` (into the primary constraints) of each ``gamma_f``; its multiplier
        ``u_f`` is the free ``v_f``.
    determined
        Indices ``q`` of the primary constraints whose multipliers are solved.
    particular
        ``U_q`` (index ``q`` -> expression).
    null_vectors
        ``V_fq`` (``f`` -> ``{q: expression}``).
    """

    hamiltonian: sympy.Expr
    primary_first_class: list[sympy.Expr]
    free: list[int]
    determined: list[int]
    particular: dict[int, sympy.Expr]
    null_vectors: dict[int, dict[int, sympy.Expr]]


def first_class_hamiltonian(analysis: Any) -> FirstClassHamiltonian:
    """Solve ``{Phi_i, H_c} + d_t Phi_i + A_ia u_a ~ 0``, ``A_ia = {Phi_i, phi_a}``, as ``u = U + v_f V_f``.

    ``d_t Phi_i``, the partial time derivative, is there only for a time-dependent
    analysis (``analysis.time``; constraints or gauge conditions that name ``t``).

    Pivot rows ``P`` and columns ``Q`` of ``A`` (numeric rank at the surface points; the
    multipliers the analysis reports as determined come first among the columns) give
    ``U_Q = -A_PQ^{-1} b_P`` and, for each other column ``f``, ``V_fQ = -A_PQ^{-1} A_Pf``
    (Henneaux–Teitelboim, ch. 1). Solved exactly and weakly on the surface
    (:func:`~dirac.analysis.core.linear_solve.weak_solve`).
    """
    space: PhaseSpace = analysis._space
    numerics = analysis._numerics
    points = analysis._points
    primary = list(analysis.primary_constraints)
    constraints = list(analysis.constraints)
    H_c = analysis.canonical_hamiltonian
    K, m = len(primary), len(constraints)
    if K == 0:
        return FirstClassHamiltonian(H_c, [], [], [], {}, {})
    pb = space.poisson_bracket
    # {Phi_i, phi_a} only where the two share a canonical pair (every other bracket is identically 0)
    pairs = sharing_pairs(space, constraints, primary)
    brackets = {(i, a): pb(constraints[i], primary[a]) for i, a in pairs}
    brackets = {key: e for key, e in brackets.items() if e != 0}
    keys = list(brackets)
    zero = numerics.weakly_zero([brackets[key] for key in keys], points) if keys else []
    brackets = {key: e for key, e, z in zip(keys, brackets.values(), zero) if not z}
    if not brackets:  # A ~ 0: every multiplier is free, gamma_f = phi_f, H' = H_c
        return FirstClassHamiltonian(
            H_c, [tidy(phi, space.variables) for phi in primary], list(range(K)), [], {}, {f: {} for f in range(K)}
        )
    A = sympy.Matrix(m, K, lambda i, a: brackets.get((i, a), sympy.S.Zero))
    time = getattr(analysis, "time", None)  # d Phi/dt = {Phi, H_T} + d_t Phi for a time-dependent system
    b = sympy.Matrix([pb(c, H_c) + (sympy.diff(c, time) if time is not None else 0) for c in constraints])
    A_num = numerics.evaluate(list(A), points).reshape(len(points), m, K)
    b_num = numerics.evaluate(list(b), points).reshape(len(points), m)
    rows = independent(list(A_num), list(range(m)))
    solved = {u.name for u in analysis.primary_multipliers if u.name in analysis.multipliers}
    order = [a for a in range(K) if analysis.primary_multipliers[a].name in solved]
    order += [a for a in range(K) if a not in order]
    cols = independent([M[rows].T for M in A_num], order) if rows else []
    free = [a for a in range(K) if a not in cols]
    particular: dict[int, sympy.Expr] = {}
    null_vectors: dict[int, dict[int, sympy.Expr]] = {f: {} for f in free}
    if cols:
        A_PQ = A[rows, cols]
        sub = [M[np.ix_(rows, cols)] for M in A_num]
        rhs_sym = sympy.Matrix.hstack(-b[rows, :], *[-A[rows, [f]] for f in free])
        rhs_num = [np.column_stack([-bv[rows], *[-M[rows, f] for f in free]]) for bv, M in zip(b_num, A_num)]
        x = weak_solve(A_PQ, rhs_sym, sub, rhs_num, variables=space.variables)
        particular = {q: x[r, 0] for r, q in enumerate(cols)}
        for j, f in enumerate(free, start=1):
            null_vectors[f] = {q: x[r, j] for r, q in enumerate(cols) if x[r, j] != 0}
    H1 = H_c + sum((particular[q] * primary[q] for q in cols), sympy.S.Zero)
    gammas = [
        tidy(primary[f] + sum((v * primary[q] for q, v in null_vectors[f].items()), sympy.S.Zero), space.variables)
        for f in free
    ]
    return FirstClassHamiltonian(H1, gammas, free, cols, particular, null_vectors)


@dataclass
class GaugeGenerator:
    """One generator ``G = sum_k eps^(k) G_k`` (Castellani's chain; module docstring).

    Attributes
    ----------
    parameter
        Name of the gauge parameter, ``eps_1``, ``eps_2``, ...
    terms
        ``(G_0, G_1, ..., G_N)``: ``G_k`` multiplies the ``k``-th time derivative of
        the parameter; ``G_N`` is a primary first-class constraint.
    multiplier
        Name of the free multiplier ``v`` that goes with it (``u_f``).
    delta
        ``delta z = {z, G}`` for each phase-space variable it moves, in the parameter
        symbols of :meth:`parameter_symbols`.
    """

    parameter: str
    terms: tuple[sympy.Expr, ...]
    multiplier: str
    delta: dict[sympy.Symbol, sympy.Expr] = field(default_factory=dict)

    @property
    def order(self) -> int:
        """``N``: the highest derivative of the parameter in ``G``."""
        return len(self.terms) - 1

    def parameter_symbols(self) -> tuple[sympy.Symbol, ...]:
        """``eps, eps_dot, ...`` as real symbols (names by :func:`parameter_name`)."""
        index = int(self.parameter.rsplit("_", 1)[1])
        return tuple(sympy.Symbol(parameter_name(index, k), real=True) for k in range(len(self.terms)))

    def generator(self) -> sympy.Expr:
        """``G = sum_k eps^(k) G_k`` with the parameter derivatives as symbols."""
        return sum((e * g for e, g in zip(self.parameter_symbols(), self.terms)), sympy.S.Zero)


def touching_index(space: PhaseSpace, right: Sequence[sympy.Expr]) -> dict[sympy.Symbol, list[int]]:
    """Coordinate ``q_k`` -> indices of the expressions of ``right`` that contain ``q_k`` or ``p_k``
    (for :func:`sharing_pairs`; built once for a list met again and again)."""
    touching: dict[sympy.Symbol, list[int]] = {}
    for j, e in enumerate(right):
        dq, dp = space.partials(e)
        for q in set(dq) | set(dp):
            touching.setdefault(q, []).append(j)
    return touching


def sharing_pairs(space: PhaseSpace, left: Sequence[sympy.Expr], right: Sequence[sympy.Expr],
                  touching: dict[sympy.Symbol, list[int]] | None = None) -> list[tuple[int, int]]:
    """Index pairs ``(i, j)`` whose expressions share a canonical pair (a ``q_k`` or ``p_k`` each):
    every other bracket ``{left_i, right_j}`` vanishes identically. In the order ``i``, then ``j``.
    ``touching`` is :func:`touching_index` of ``right`` when the caller has it: each generator of a
    256-site lattice's gauge structure indexed all 768 constraints again (quadratic in the size)."""
    if touching is None:
        touching = touching_index(space, right)
    out: list[tuple[int, int]] = []
    for i, e in enumerate(left):
        dq, dp = space.partials(e)
        found = {j for q in set(dq) | set(dp) for j in touching.get(q, ())}
        out.extend((i, j) for j in sorted(found))
    return out


def transformation(space: PhaseSpace, G: sympy.Expr) -> dict[sympy.Symbol, sympy.Expr]:
    """``delta z = {z, G}`` for every phase-space variable ``z`` (zero ones left out; only the
    variables whose conjugate ``G`` contains can move)."""
    out = {}
    dq, dp = space.partials(G)
    moved = set(dq) | set(dp)
    variables = space.variables
    candidates = sorted({k for q in moved for k in space.pair_positions(q)})  # in the order of the variables
    for z in (variables[k] for k in candidates):
        d = sympy.expand(space.poisson_bracket(z, G))
        if d != 0:
            out[z] = d
    return out


@dataclass
class GaugeStructure:
    """The gauge generators of an analysis and the honest account of Dirac's conjecture.

    Attributes
    ----------
    generators
        One :class:`GaugeGenerator` per independent gauge parameter (free multiplier).
    without_transformation
        First-class constraints outside the span of every generator's terms: they
        generate no gauge transformation of the equations of motion (after a partial
        gauge fixing: no transformation with a time-dependent parameter is left).
    unclosed
        Primary first-class combinations whose Castellani chain did not close.
    gauge_fixed
        Whether the analysis has gauge conditions (changes the account of
        ``without_transformation``).
    """

    generators: list[GaugeGenerator] = field(default_factory=list)
    without_transformation: list[sympy.Expr] = field(default_factory=list)
    unclosed: list[sympy.Expr] = field(default_factory=list)
    rejected: list[str] = field(default_factory=list)
    irregular_terms: list[sympy.Expr] = field(default_factory=list)
    second_class_present: bool = False
    gauge_fixed: bool = False

    @property
    def notes(self) -> list[str]:
        """How the generators were found, and each first-class constraint without one."""
        out = []
        if self.generators:
            out.append(
                "gauge generators by Castellani's algorithm: G = sum_k eps^(k) G_k with G_N primary first class, "
                "G_(k-1) = -{G_k, H'} + PFC and {G_0, H'} a primary first-class combination"
                + (" modulo second-class constraints" if self.second_class_present else "")
                + "; every term checked first class at the surface points"
            )
        for gamma in self.unclosed:
            out.append(
                f"Castellani's chain started at the primary first-class constraint {gamma} did not close within "
                "the number of stages: no generator is reported for it"
            )
        out.extend(self.rejected)
        for term in self.irregular_terms:
            out.append(
                f"the generator term {term} has a vanishing gradient on the constraint surface (an irregular "
                "constraint): the transformation it multiplies vanishes there, so it generates nothing"
            )
        for c in self.without_transformation:
            out.append(self.account(c))
        return out

    def account(self, constraint: sympy.Expr) -> str:
        """Why a first-class constraint has no generator."""
        if self.unclosed or self.rejected:
            return (
                f"the first-class constraint {constraint} is not in the span of the generators found; since some "
                "Castellani chains did not give a generator, whether it generates a gauge transformation is not decided"
            )
        if self.gauge_fixed:
            return (
                f"the first-class constraint {constraint} remains after the gauge conditions, but no free multiplier "
                "is left: it generates no gauge transformation with a time-dependent parameter (at most a residual "
                "one with a constant parameter)"
            )
        return (
            f"the first-class constraint {constraint} generates no gauge transformation: it is not in the span of "
            "the generators' terms (Dirac's conjecture does not hold for it, as in Cawley's example)"
        )


#: The longest bracket ``{G_k, H'}`` (printed characters) Castellani's chain expands: past it the
#: chain is not built and the report says so. Each stage differentiates the last, so a chain whose
#: terms swell costs more at every stage (a random three-coordinate system's went 280, 925,
#: 53860 characters, the third expansion 4.7 s of CPU, the fourth past minutes); the limit grows
#: with the phase space, whose local chains (a lattice's Gauss laws) are long only by their count.
CHAIN_TERM_LIMIT = 20000
CHAIN_TERM_PER_VARIABLE = 200


def _large(space: PhaseSpace) -> bool:
    """Whether span tests go by sparse blocks (:mod:`~dirac.analysis.gauge.local_span`)."""
    return len(space.variables) >= LARGE_SYSTEM


def _gradients(space: PhaseSpace, numerics, exprs: Sequence[sympy.Expr], points: Sequence[np.ndarray]) -> Any:
    """``grad expr`` at each point: array (points, len(exprs), dim); for a large system a list of sparse
    matrices, one per point (:func:`~dirac.analysis.gauge.local_span.sparse_gradients`)."""
    if _large(space):
        return sparse_gradients(space, numerics, exprs, points)
    n = len(space.variables)
    if not exprs:
        return np.zeros((len(points), 0, n))
    flat = [g for e in exprs for g in space.gradient(e)]
    return numerics.evaluate(flat, points).reshape(len(points), len(exprs), n)


def _in_span(vectors: Any, basis: Any) -> np.ndarray:
    """Which rows of ``vectors`` (points, k, n) lie in the row span of ``basis`` (points, b, n) at every point
    (sparse gradients of a large system: by connected blocks, :func:`~dirac.analysis.gauge.local_span.in_span_by_blocks`)."""
    if isinstance(vectors, list):
        return in_span_by_blocks(vectors, basis, SPAN_TOLERANCE)
    inside = np.ones(vectors.shape[1], dtype=bool)
    for vec, base in zip(vectors, basis):
        for j, v in enumerate(vec):
            size = 1.0 + np.linalg.norm(v)
            if base.shape[0] == 0:
                residual = v
            else:
                coeff = np.linalg.lstsq(base.T, v, rcond=None)[0]
                residual = v - base.T @ coeff
            if np.linalg.norm(residual) > SPAN_TOLERANCE * size * (1.0 + np.abs(base).max(initial=0.0)):
                inside[j] = False
    return inside


def gauge_structure(analysis: Any) -> GaugeStructure:
    """Castellani's generators of ``analysis`` (module docstring); empty without first-class constraints.

    A chain whose terms are not first class, or that fails Castellani's conditions when
    checked at the end, gives no generator; :attr:`GaugeStructure.rejected` says why.
    """
    if not analysis.first_class:
        return GaugeStructure()
    space: PhaseSpace = analysis._space
    numerics = analysis._numerics
    points = analysis._points
    split = first_class_hamiltonian(analysis)
    H1 = split.hamiltonian
    gammas = split.primary_first_class
    second = list(analysis.second_class)
    closing_basis = _gradients(space, numerics, gammas + second, points)
    if _large(space):  # its sparse blocks found once, for every closing test
        closing_basis = BlockBasis(closing_basis)
    constraints = list(analysis.constraints)
    limit = len(analysis.stages) + 1
    structure = GaugeStructure(second_class_present=bool(second), gauge_fixed=bool(analysis.gauge_conditions))
    multiplier_names = [u.name for u in analysis.primary_multipliers]
    time = getattr(analysis, "time", None)

    def evolve(G: sympy.Expr) -> sympy.Expr:
        """``{G, H'} + d_t G``: the d_t term only for a time-dependent analysis (Castellani's
        conditions with ``dG/dt = d_t G + {G, H_T}``)."""
        return space.poisson_bracket(G, H1) + (sympy.diff(G, time) if time is not None else sympy.S.Zero)

    secondary = [evolve(g) for g in gammas]  # S_a = {gamma_a, H'} (+ d_t gamma_a)
    expansion_basis = gammas + secondary + constraints
    chain_limit = max(CHAIN_TERM_LIMIT, CHAIN_TERM_PER_VARIABLE * len(space.variables))
    touching = touching_index(space, constraints)  # for every chain's first-class check
    for index, (gamma, f) in enumerate(zip(gammas, split.free), start=1):
        chain = [gamma]  # G_N, G_{N-1}, ...
        closed = swollen = False
        for _ in range(limit):
            R = evolve(chain[-1])
            if R == 0 or _closes(space, numerics, R, points, closing_basis):
                closed = True
                break
            # G_(k-1) = -R + c_a gamma_a: c_a cancels the S_a-components of {R, H'}, so that
            # {G_(k-1), H'} = -{R, H'} + c_a S_a + PFC loses them (Castellani's PFC freedom)
            following = -R
            W = evolve(R)
            if not prints_shorter(W, chain_limit):  # the terms swell at each stage: each further one costs more
                swollen = True
                break
            coefficients = _expansion(space, numerics, W, expansion_basis, points)
            if coefficients is not None:
                c = coefficients[len(gammas) : 2 * len(gammas)]
                following += sum((ca * ga for ca, ga in zip(c, gammas) if ca != 0), sympy.S.Zero)  # zeros skipped: O(chain) not O(gammas)
            # a long one is expanded without rational normal forms (their gcds cost seconds per term)
            chain.append(tidy(following, space.variables, rational=prints_shorter(following, TIDY_LIMIT)))
        if swollen:
            structure.rejected.append(
                f"Castellani's chain started at {gamma} was not built: the bracket of its term at stage {len(chain)} "
                f"with H' prints longer than {chain_limit} characters (its terms grow at each stage): no generator "
                "is reported for it")
            continue
        if not closed:
            structure.unclosed.append(gamma)
            continue
        problem = _first_class_problem(space, numerics, chain, constraints, points, touching) or _chain_problem(
            space, numerics, list(reversed(chain)), H1, points, closing_basis, time
        )
        if problem:
            structure.rejected.append(f"the chain started at {gamma} was built, but {problem}: no generator is reported for it")
            continue
        generator = GaugeGenerator(f"eps_{index}", tuple(reversed(chain)), multiplier_names[f])
        generator.delta = transformation(space, generator.generator())
        structure.generators.append(generator)
    all_terms = [g for gen in structure.generators for g in gen.terms]
    if all_terms:
        if _large(space):
            size = gradient_sizes(space, numerics, all_terms, points)
        else:
            flat = _gradients(space, numerics, all_terms, points)
            size = np.max(np.abs(flat), axis=2)  # (points, terms)
        structure.irregular_terms = [g for g, s in zip(all_terms, np.all(size <= IRREGULAR_GRADIENT, axis=0)) if s]
    first = list(analysis.first_class)
    spanned = _in_span(_gradients(space, numerics, first, points), _gradients(space, numerics, all_terms + second, points))
    structure.without_transformation = [c for c, ok in zip(first, spanned) if not ok]
    return structure


def _expansion(space: PhaseSpace, numerics, W: sympy.Expr, basis: Sequence[sympy.Expr], points) -> list[sympy.Expr] | None:
    """Coefficients ``l_b`` with ``grad W ~ sum_b l_b grad basis_b`` on the surface (exact, weakly).

    ``W`` must vanish weakly; the basis elements are taken in the given order, dependent
    ones get coefficient 0. Pivot variables ``P`` (columns of the gradients with an
    invertible block) give ``(d basis_B / d z_P)^T l = d W / d z_P``, solved by
    :func:`~dirac.analysis.core.linear_solve.weak_solve`. ``None`` when ``W`` is not weakly
    zero or its gradient is not in the span.
    """
    if W == 0:
        return [sympy.S.Zero] * len(basis)
    if not numerics.weakly_zero([W], points)[0]:
        return None
    grads = _gradients(space, numerics, list(basis), points)
    kept = independent(list(grads), list(range(len(basis))))
    if not kept or not _in_span(_gradients(space, numerics, [W], points), grads[:, kept, :])[0]:
        return None
    columns = independent([g[kept].T for g in grads], list(range(len(space.variables))))
    if len(columns) != len(kept):
        return None
    variables = space.variables
    A = sympy.Matrix(len(columns), len(kept), lambda i, j: sympy.diff(basis[kept[j]], variables[columns[i]]))
    b = sympy.Matrix([sympy.diff(W, variables[i]) for i in columns])
    A_num = [g[np.ix_(kept, columns)].T for g in grads]
    b_num = [w[0, columns].reshape(-1, 1) for w in _gradients(space, numerics, [W], points)]
    x = weak_solve(A, b, A_num, b_num, variables=variables)
    out = [sympy.S.Zero] * len(basis)
    for j, k in enumerate(kept):
        out[k] = x[j, 0]
    return out


def _closes(space: PhaseSpace, numerics, R: sympy.Expr, points, basis: np.ndarray) -> bool:
    """Whether ``R = {G_k, H'}`` is a primary first-class combination (modulo second class):
    weakly zero with its gradient in the span of those constraints' gradients."""
    if not numerics.weakly_zero([R], points)[0]:
        return False
    return bool(_in_span(_gradients(space, numerics, [R], points), basis)[0])


def _chain_problem(space: PhaseSpace, numerics, terms: Sequence[sympy.Expr], H1: sympy.Expr, points, basis, time=None) -> str:
    """Castellani's conditions, checked on the final terms ``(G_0, ..., G_N)``: ``G_N`` and every
    ``G_(k-1) + {G_k, H'}`` and ``{G_0, H'}`` are primary first-class combinations (modulo
    second class) at the surface points; together they say ``dG/dt ~ PFC`` for every
    ``eps(t)``, i.e. that ``delta z = {z, G}`` maps solutions of the equations of motion to
    solutions. For a time-dependent analysis (``time`` given) each ``{G_k, H'}`` is
    ``{G_k, H'} + d_t G_k``. Returns what fails, or ``""``."""

    def pb(G: sympy.Expr, H: sympy.Expr) -> sympy.Expr:
        return space.poisson_bracket(G, H) + (sympy.diff(G, time) if time is not None else sympy.S.Zero)

    conditions = [terms[-1], pb(terms[0], H1)] + [terms[k - 1] + pb(terms[k], H1) for k in range(1, len(terms))]
    for c in conditions:
        if not (sympy.expand(c) == 0 or _closes(space, numerics, c, points, basis)):
            return f"Castellani's condition {c} = PFC fails on the constraint surface"
    return ""


def _first_class_problem(space: PhaseSpace, numerics, terms: Sequence[sympy.Expr], constraints, points,
                         touching: dict[sympy.Symbol, list[int]] | None = None) -> str:
    """Every ``G_k`` is weakly zero and has weakly zero brackets with every constraint;
    returns what fails, or ``""`` (``touching``: :func:`touching_index` of ``constraints``)."""
    pairs = sharing_pairs(space, terms, constraints, touching)  # every other bracket vanishes identically
    owner = list(range(len(terms))) + [k for k, _ in pairs]
    exprs = list(terms) + [space.poisson_bracket(terms[k], constraints[j]) for k, j in pairs]
    zero = numerics.weakly_zero(exprs, points)
    if np.all(zero):
        return ""
    bad = next(i for i, z in enumerate(zero) if not z)
    term = terms[owner[bad]]
    return f"its term {term} is not a first-class constraint on the surface"
