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

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import sympy

from dirac.analysis.core.algebra import negated
from dirac.analysis.core.antisymmetric import mirrored
from dirac.analysis.core.linear_solve import weak_solve
from dirac.analysis.core.numeric import Numerics, independent_rows, numeric_rank
from dirac.analysis.core.phase_space import PhaseSpace
from dirac.analysis.core.sparse_numeric import components
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
            entries[(b, a)] = negated(value)  # the same expression as -value
    if not m:
        return sympy.zeros(0, 0)
    sparse = sympy.SparseMatrix(m, m, entries)
    return sparse if m >= SPARSE_BRACKETS else sympy.Matrix(sparse)


#: from this many constraints :func:`bracket_matrix` returns a ``sympy.SparseMatrix`` (most entries are zero)
SPARSE_BRACKETS = 64


def bracket_values(numerics: Numerics, C: Mapping[tuple[int, int], sympy.Expr], where: Sequence[tuple[int, int]],
                   points: Sequence[np.ndarray]) -> np.ndarray:
    """Values of the bracket matrix entries ``C[k]``, ``k`` in ``where``, at ``points``: ``(len(points), len(where))``.

    Only the entries above the diagonal are compiled and evaluated; those below are their
    mirrors' values negated (``C_ba = -C_ab``, :mod:`dirac.analysis.core.antisymmetric`).
    A pattern that is not antisymmetric is evaluated entry by entry.
    """
    if not where:
        return np.zeros((len(points), 0))
    reading = mirrored(where)
    if reading is None:
        return numerics.evaluate([C[k] for k in where], points)
    upper, pick, sign = reading
    values = numerics.evaluate([C[where[k]] for k in upper], points)
    return values[:, pick] * sign


def _rank_by_blocks(m: int, rows: np.ndarray, cols: np.ndarray, values: np.ndarray) -> int:
    """The rank of the ``m x m`` matrix with ``values`` at ``(rows, cols)``, as :func:`numeric_rank` gives it.

    The matrix is block diagonal over the connected components of its sparsity graph, so
    its singular values are those of the blocks together: each block's are taken densely,
    and the rank counts those above ``1e-8`` times the largest of all (the cut of
    :func:`numeric_rank`). Cost: the blocks' sizes cubed, not ``m^3``.
    """
    keep = values != 0.0
    if not np.any(keep):
        return 0
    if m < SPARSE_BRACKETS:  # the same blocks and singular values from dense arrays (no scipy.sparse import)
        dense = np.zeros((m, m))
        np.add.at(dense, (rows[keep], cols[keep]), values[keep])  # duplicates summed, as a CSR matrix does
        linked = np.zeros((m, m), dtype=bool)
        linked[rows[keep], cols[keep]] = True
        singular = [
            np.linalg.svd(dense[np.ix_(block, block)], compute_uv=False)
            for block in components(linked | linked.T)
            if len(block) > 1 or dense[block[0], block[0]] != 0.0
        ]
    else:
        import scipy.sparse as sp  # imported when used: large constraint sets only

        pattern = sp.coo_matrix((np.ones(int(keep.sum())), (rows[keep], cols[keep])), shape=(m, m)).tocsr()
        matrix = sp.csr_matrix((values[keep], (rows[keep], cols[keep])), shape=(m, m))
        singular = [
            np.linalg.svd(matrix[block][:, block].toarray(), compute_uv=False)
            for block in components(pattern + pattern.T)
            if len(block) > 1 or matrix[block[0], block[0]] != 0.0
        ]
    if not singular:
        return 0
    pooled = np.concatenate(singular)
    if not np.all(np.isfinite(pooled)):
        return numeric_rank(dense if m < SPARSE_BRACKETS else matrix.toarray())  # raises the error about non-finite entries
    return int(np.sum(pooled > 1e-8 * np.max(pooled))) if np.max(pooled) > 0 else 0


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
    where = list(nonzero)
    at = bracket_values(numerics, nonzero, where, points)
    rows = np.array([i for i, _ in where], dtype=int)
    cols = np.array([j for _, j in where], dtype=int)
    scale = 1.0 + np.max(np.abs(at), axis=1, initial=0.0)
    # entries at round-off of the matrix's scale are weak zeros: they make no constraint second class, nor rank
    big = np.abs(at) > 1e-9 * scale[:, None]
    touched = np.zeros(m, dtype=bool)
    touched[rows[np.any(big, axis=0)]] = True
    alone_first = [a for a in range(m) if not touched[a]]
    rest = [a for a in range(m) if touched[a]]
    ranks = [_rank_by_blocks(m, rows, cols, np.where(b, v, 0.0)) for v, b in zip(at, big)]
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
    # the values of C among the constraints that are not first class alone (dense: the second-class part)
    position = {a: k for k, a in enumerate(rest)}
    inside = np.array([i in position and j in position for i, j in where], dtype=bool)
    values = np.zeros((len(points), len(rest), len(rest)))
    if np.any(inside):
        values[:, [position[i] for i in rows[inside]], [position[j] for j in cols[inside]]] = at[:, inside]
    chosen = independent_rows(list(values), list(range(len(rest))))
    S = [rest[i] for i in chosen]
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
        sub = [v[np.ix_(chosen, chosen)].T for v in values]
        rhs = [-v[position[a], chosen].reshape(-1, 1) for v in values]
        k = weak_solve(C[S, S].T, -C[a, S].T, sub, rhs, variables=space.variables)
        combo = constraints[a] + sum((k[i, 0] * constraints[s] for i, s in enumerate(S)), sympy.S.Zero)
        first.append(combo)
        combos += 1
    return Classification(first, [constraints[s] for s in S], S, rank, combos)
