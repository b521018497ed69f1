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
when a stage adds nothing; the last system then fixes the determined multipliers.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import sympy

from dirac.analysis.algebra import tidy
from dirac.analysis.linear_solve import weak_solve
from dirac.analysis.numeric import Numerics, independent_rows, numeric_rank
from dirac.analysis.phase_space import PhaseSpace
from dirac.errors import AnalysisError, InconsistentSystemError

__all__ = ["ConstraintChain", "tidy"]

SAMPLE_POINTS = 4


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

    After :meth:`run`: ``stages``, ``constraints``, ``solved_multipliers`` (name -> exact
    expression, only those the chain determines), ``undetermined`` (multiplier symbols
    left free), ``points`` (points of the final surface) and ``notes``.
    """

    phase_space: PhaseSpace
    numerics: Numerics
    canonical_hamiltonian: sympy.Expr
    primary: list[sympy.Expr]
    multipliers: tuple[sympy.Symbol, ...]
    stages: list[list[sympy.Expr]] = field(default_factory=list)
    solved_multipliers: dict[str, sympy.Expr] = field(default_factory=dict)
    undetermined: list[sympy.Symbol] = field(default_factory=list)
    points: list[np.ndarray] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    time: sympy.Symbol | None = None

    @property
    def constraints(self) -> list[sympy.Expr]:
        """All constraints, stage by stage."""
        return [c for stage in self.stages for c in stage]

    @property
    def total_hamiltonian(self) -> sympy.Expr:
        """``H_T = H_c + sum_k u_k phi_k`` ((207), (234))."""
        return self.canonical_hamiltonian + sum((u * phi for u, phi in zip(self.multipliers, self.primary)), sympy.S.Zero)

    # ------------------------------------------------------------------ helpers
    def _rows(self, constraint: sympy.Expr) -> tuple[sympy.Expr, list[sympy.Expr]]:
        cached = self._row_cache.get(constraint)
        if cached is None:
            pb = self.phase_space.poisson_bracket
            b = pb(constraint, self.canonical_hamiltonian)
            if self.time is not None:  # d Phi/dt = {Phi, H_T} + d_t Phi for a rheonomic system
                b = b + sympy.diff(constraint, self.time)
            cached = (b, [pb(constraint, phi) for phi in self.primary])
            self._row_cache[constraint] = cached
        return cached

    def _numeric_rows(self, constraints: list[sympy.Expr], points: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        K = len(self.primary)
        exprs = []
        for c in constraints:
            b, A = self._rows(c)
            exprs.append(b)
            exprs.extend(A)
        values = self.numerics.evaluate(exprs, points).reshape(len(points), len(constraints), K + 1)
        return values[:, :, 0], values[:, :, 1:]

    # ------------------------------------------------------------------ the algorithm
    def run(self, max_stages: int | None = None) -> ConstraintChain:
        """Carry out the algorithm; returns ``self``.

        Raises
        ------
        InconsistentSystemError
            When a consistency condition cannot hold (``1 = 0`` kind).
        AnalysisError
            When the chain does not terminate within the phase-space dimension.
        """
        self._row_cache: dict = {}
        primary = [tidy(p, self.phase_space.variables, sign=True, rational=len(str(p)) < 4000) for p in self.primary]
        self.primary = primary
        points = self.numerics.surface_points(primary, SAMPLE_POINTS) if primary else []
        base_grads = self._independent(primary, [], points) if primary else []
        self.stages = [[primary[i] for i in base_grads]] if primary else []
        if primary and len(base_grads) < len(primary):
            raise AnalysisError("the primary constraints are not independent; the analysis cannot proceed")
        limit = max_stages or (self.phase_space.dimension + 2)
        K = len(self.primary)
        pivots_rows: list[int] = []
        pivot_cols: list[int] = []
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
            direct: list[sympy.Expr] = []
            deferred: list[tuple[int, list[int]]] = []  # (row, pivot positions it must be reduced by)
            for i in range(len(constraints)):
                if i in pivots_rows or (b_zero[i] and a_row_zero[i]):
                    continue
                needed = [] if a_row_zero[i] else self._needed(i, pivots_rows, pivot_cols, A_num, b_zero)
                if needed:
                    deferred.append((i, needed))
                else:
                    direct.append(exprs_b[i])
            candidates, chosen = self._settle(self._nonzero(direct, points), constraints, limit) if direct else ([], [])
            if not chosen and deferred:
                # nothing new without them: build the conditions that need multipliers eliminated
                eliminated = [self._eliminate(i, needed, constraints, pivots_rows, pivot_cols, A_num) for i, needed in deferred]
                candidates, chosen = self._settle(self._nonzero(eliminated, points), constraints, limit)
            elif deferred:
                self.notes.append(
                    f"stage {len(self.stages) + 1}: {len(deferred)} consistency condition(s) that need multipliers "
                    "eliminated were deferred to the next stage and re-examined there on the smaller surface"
                )
            if not chosen:
                break
            self.stages.append([candidates[i] for i in chosen])
            points = self.numerics.surface_points(self.constraints, SAMPLE_POINTS)
        self.points = points
        self._solve_multipliers(points, pivots_rows, pivot_cols)
        return self

    def _nonzero(self, candidates: list[sympy.Expr], points: list[np.ndarray]) -> list[sympy.Expr]:
        """The candidates that are not weakly zero, tidied (constraints: the sign is free)."""
        if not candidates:
            return []
        keep = ~self.numerics.weakly_zero(candidates, points)
        return [tidy(c, self.phase_space.variables, sign=True, rational=len(str(c)) < 4000) for c, k in zip(candidates, keep) if k]

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
        try:
            new_points = self.numerics.surface_points(constraints + candidates, SAMPLE_POINTS)
        except AnalysisError:
            shown = "; ".join(f"{c} = 0" for c in candidates[:4])
            raise InconsistentSystemError(
                f"the stage-{len(self.stages) + 1} conditions {shown} have no real solution together with "
                "the earlier constraints: the Lagrangian has no consistent motion"
            ) from None
        return candidates, self._independent(candidates, constraints, new_points)

    def _needed(self, row: int, P: list[int], Q: list[int], A_num: np.ndarray, b_zero: np.ndarray) -> list[int]:
        """Pivot rows (positions in ``P``) with a non-zero ``b`` that row ``row`` must be reduced by."""
        if not P:
            return []
        coeff = np.array([np.linalg.lstsq(A[np.ix_(P, Q)].T, A[row, Q], rcond=None)[0] for A in A_num])
        scale = 1 + np.max(np.abs(coeff), axis=1, keepdims=True)
        return [k for k, p in enumerate(P) if not b_zero[p] and not np.all(np.abs(coeff[:, k]) <= 1e-9 * scale[:, 0])]

    def _independent(self, candidates: list[sympy.Expr], old: list[sympy.Expr], points: list[np.ndarray]) -> list[int]:
        n = len(self.phase_space.variables)
        grads = [g for c in candidates for g in self.phase_space.gradient(c)]
        cand = self.numerics.evaluate(grads, points).reshape(len(points), len(candidates), n)
        if old:
            og = [g for c in old for g in self.phase_space.gradient(c)]
            base = list(self.numerics.evaluate(og, points).reshape(len(points), len(old), n))
        else:
            base = None
        return independent_rows(list(cand), list(range(len(candidates))), base=base)

    def _eliminate(self, row, needed, constraints, P, Q, A_num):
        """``psi_a = b_a - c_a . b_P`` for a row that shares multipliers with the pivot rows ``needed``."""
        b_row = self._rows(constraints[row])[0]
        A_sym = sympy.Matrix([[self._rows(constraints[p])[1][k] for k in Q] for p in P])
        rhs = sympy.Matrix([self._rows(constraints[row])[1][k] for k in Q])
        c = weak_solve(A_sym.T, rhs, [A[np.ix_(P, Q)].T for A in A_num], [A[row, Q].reshape(-1, 1) for A in A_num], variables=self.phase_space.variables)
        return b_row - sum((c[k, 0] * self._rows(constraints[P[k]])[0] for k in needed), sympy.S.Zero)

    def _solve_multipliers(self, points, P, Q) -> None:
        """Solve ``b_P + A_PQ u_Q = 0`` for the determined multipliers ((214)-(215) ff.)."""
        K = len(self.primary)
        constraints = self.constraints
        if not K:
            return
        if not constraints or not P:
            self.undetermined = list(self.multipliers)
            return
        b_num, A_num = self._numeric_rows(constraints, points)
        determined = []
        for k in range(K):
            e = np.zeros(K)
            e[k] = 1.0
            votes = 0
            for A in A_num:
                M = A[P]
                s = np.max(np.abs(M)) or 1.0
                votes += numeric_rank(np.vstack([M, e * s]) / s) == numeric_rank(M / s)
            if 2 * votes > len(A_num):
                determined.append(k)
        self.undetermined = [self.multipliers[k] for k in range(K) if k not in determined]
        if not determined:
            return
        order = determined + [k for k in range(K) if k not in determined]
        Q = independent_rows([A[P].T for A in A_num], order)
        A_sym = sympy.Matrix([[self._rows(constraints[p])[1][k] for k in Q] for p in P])
        b_sym = sympy.Matrix([-self._rows(constraints[p])[0] for p in P])
        sol = weak_solve(
            A_sym,
            b_sym,
            [A[np.ix_(P, Q)] for A in A_num],
            [-b[P].reshape(-1, 1) for b in b_num],
            variables=self.phase_space.variables,
        )
        for r, k in enumerate(Q):
            if k in determined:
                self.solved_multipliers[self.multipliers[k].name] = sol[r, 0]
