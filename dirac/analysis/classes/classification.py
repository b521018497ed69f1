"""First- and second-class constraints from the bracket matrix ``C_ab = {Phi_a, Phi_b}``.

A constraint is first class when its bracket with every constraint vanishes weakly;
the rank of ``C`` on the surface counts the second-class constraints (docs/conventions.md,
the matrix Δ of (240)-(245)). The rank is decided at regular surface points, which must
all agree: a disagreement is refused, never resolved by taking the largest. When ``C`` is singular but no single constraint is first
class, first-class *combinations* ``F_a = Phi_a + k_s Phi_s`` are built, with ``k``
solving ``C_SS^T k = -C_aS^T`` for a set ``S`` of constraints whose principal block
``C_SS`` is invertible (for an antisymmetric matrix the rows of a row basis give such a
block).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import sympy

from dirac.analysis.core.linear_solve import weak_solve
from dirac.analysis.core.numeric import Numerics, independent_rows, numeric_rank
from dirac.analysis.core.phase_space import PhaseSpace
from dirac.analysis.legendre.regularity import branch_hint
from dirac.errors import AnalysisError, SeparableParts

__all__ = ["Classification", "classify", "bracket_matrix"]


def bracket_matrix(space: PhaseSpace, constraints: list[sympy.Expr]) -> sympy.Matrix:
    """``C_ab = {Phi_a, Phi_b}`` (antisymmetric; only ``a < b`` is computed).

    Only pairs that share a canonical pair can have a non-zero bracket: the constraints
    are indexed by the coordinates whose ``q`` or ``p`` they contain, and brackets are
    computed only where ``Phi_a`` contains ``q_i`` and ``Phi_b`` contains ``p_i`` or the
    reverse (for a local system ``O(m)`` brackets instead of ``m^2 / 2``).
    """
    m = len(constraints)
    by_q: dict[sympy.Symbol, list[int]] = {}
    by_p: dict[sympy.Symbol, list[int]] = {}
    for a, c in enumerate(constraints):
        dq, dp = space.partials(c)
        for q in dq:
            by_q.setdefault(q, []).append(a)
        for q in dp:
            by_p.setdefault(q, []).append(a)
    pairs = {
        (min(a, b), max(a, b))
        for q, rows in by_q.items()
        for a in rows
        for b in by_p.get(q, ())
        if a != b
    }
    entries: dict[tuple[int, int], sympy.Expr] = {}
    for a, b in sorted(pairs):
        value = space.poisson_bracket(constraints[a], constraints[b])
        if value != 0:
            entries[(a, b)] = value
            entries[(b, a)] = -value
    return sympy.Matrix(sympy.SparseMatrix(m, m, entries)) if m else sympy.zeros(0, 0)


@dataclass
class Classification:
    """Result of :func:`classify`.

    Attributes
    ----------
    first_class
        First-class constraints (single constraints or combinations).
    second_class
        Second-class constraints (their ``C`` block is invertible on the surface).
    second_indices
        Indices of the second-class constraints in the full list.
    rank
        Rank of ``C`` on the surface (= number of second-class constraints).
    combinations
        Number of first-class constraints that had to be built as combinations.
    """

    first_class: list[sympy.Expr]
    second_class: list[sympy.Expr]
    second_indices: list[int]
    rank: int
    combinations: int


def classify(space: PhaseSpace, numerics: Numerics, constraints: list[sympy.Expr], points: list[np.ndarray], C: sympy.Matrix | None = None) -> Classification:
    """Split ``constraints`` into first and second class (decisions at surface ``points``)."""
    m = len(constraints)
    if m == 0:
        return Classification([], [], [], 0, 0)
    if C is None:
        C = bracket_matrix(space, constraints)
    nonzero = C.todok()  # only the non-zero entries are compiled and evaluated (most, for a local system, are zero)
    values = np.zeros((len(points), m, m))
    if nonzero:
        where = list(nonzero)
        at = numerics.evaluate([nonzero[k] for k in where], points)
        rows = np.array([i for i, _ in where], dtype=int)
        cols = np.array([j for _, j in where], dtype=int)
        values[:, rows, cols] = at
    scale = 1.0 + np.max(np.abs(values), axis=(1, 2), keepdims=True)
    tiny = np.all(np.abs(values) <= 1e-9 * scale, axis=0)
    alone_first = [a for a in range(m) if np.all(tiny[a])]
    rest = [a for a in range(m) if a not in alone_first]
    # entries at round-off of the matrix's scale are weak zeros, as in ``tiny``: not rank
    ranks = [numeric_rank(np.where(np.abs(v) <= 1e-9 * sc, 0.0, v)) for v, sc in zip(values, scale)]
    if len(set(ranks)) > 1:
        raise SeparableParts(
            f"the rank of the bracket matrix C_ab = {{Phi_a, Phi_b}} differs between regular points of the constraint "
            f"surface ({', '.join(map(str, ranks))}): the first/second-class split is not the same everywhere on it "
            "(parts of different structure)"
            + (branch_hint(constraints, space.variables) or "; analyse each part as a system of its own"),
            points=list(points),
            ranks=list(ranks),
            variables=list(space.variables),
        )
    rank = ranks[0] if ranks else 0
    if not rest:
        return Classification(list(constraints), [], [], 0, 0)
    S = independent_rows([v[np.ix_(rest, rest)] for v in values], list(range(len(rest))))
    S = [rest[i] for i in S]
    if len(S) != rank:
        raise AnalysisError(
            f"the second-class block found ({len(S)} constraints) does not match the rank {rank} of C_ab = "
            "{Phi_a, Phi_b} on the surface: the classification cannot be decided consistently"
        )
    first = [constraints[a] for a in alone_first]
    combos = 0
    for a in rest:
        if a in S:
            continue
        sub = [v[np.ix_(S, S)].T for v in values]
        rhs = [-v[a, S].reshape(-1, 1) for v in values]
        k = weak_solve(C[S, S].T, -C[a, S].T, sub, rhs, variables=space.variables)
        combo = constraints[a] + sum((k[i, 0] * constraints[s] for i, s in enumerate(S)), sympy.S.Zero)
        first.append(combo)
        combos += 1
    return Classification(first, [constraints[s] for s in S], S, rank, combos)
