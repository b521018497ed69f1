"""Irregular new constraints of a large chain stage, with one orthogonal basis per point.

The test of :meth:`dirac.analysis.constraint_chain.ConstraintChain._irregular` (a new
constraint whose gradient is numerically normal to the surface's other gradients where
it holds: ``f^2 = 0``, ``x^2 + y^2 = 0``; Henneaux–Teitelboim, Sect. 1.1.2) projects each
candidate's gradient off the span of the earlier gradients. Done candidate by candidate
that is one QR factorisation of the whole base per candidate and point; here the base is
factorised once per point (twice: the old constraints for kept candidates, the old and
kept ones for dropped candidates) and every candidate projected on it — the same sizes,
the same decisions, at the cost of one factorisation per point. With sparse gradients
(:func:`_normal_norms`) the projection is taken per connected block of the gradients'
sparsity graph by sparse LU, and the dense factorisation is only the fallback.
"""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING

import numpy as np
import sympy

from dirac.analysis.core.sparse_numeric import components, independent_rows_eliminated
from dirac.analysis.legendre.regularity import IRREGULAR_GRADIENT, ROUND_OFF

if TYPE_CHECKING:
    import scipy.sparse as sp

    from dirac.analysis.core.numeric import Numerics
    from dirac.analysis.core.phase_space import PhaseSpace

__all__ = ["irregular_candidates", "gradient_values"]


def gradient_values(space: PhaseSpace, numerics: Numerics, constraints: list[sympy.Expr], points: list[np.ndarray]) -> np.ndarray:
    """The gradients of ``constraints`` at ``points``: shape ``(points, constraints, variables)``.

    Only the non-zero partial derivatives (:meth:`PhaseSpace.partials`) are evaluated and
    scattered into the dense array (a constraint of a local system touches O(1) variables):
    the same values as evaluating :meth:`PhaseSpace.gradient` entry by entry.
    """
    n = len(space.variables)
    rows, cols, entries = space.gradient_entries(constraints)
    out = np.zeros((len(points), len(constraints), n))
    if entries:
        out[:, np.array(rows, dtype=int), np.array(cols, dtype=int)] = numerics.evaluate(entries, points)
    return out


def _basis(base: np.ndarray) -> np.ndarray | None:
    """Orthonormal columns spanning the rows of ``base`` (as in :func:`~dirac.analysis.legendre.regularity.normal_components`)."""
    if not base.size:
        return None
    q, r = np.linalg.qr(base.T)
    keep = np.abs(np.diag(r)) > 1e-12 * (np.max(np.abs(r)) if r.size else 1.0)
    return q[:, keep]


def _normal_sizes(rows: np.ndarray, q: np.ndarray | None, scales: np.ndarray) -> np.ndarray:
    """``|(1 - Q Q^T) row| / scale`` for each row."""
    normal = rows - (rows @ q) @ q.T if q is not None else rows
    return np.linalg.norm(normal, axis=1) / scales


def _normal_norms(base: sp.csr_matrix, rows: sp.csr_matrix) -> np.ndarray | None:
    """``|(1 - P) row|`` for each row of ``rows``, ``P`` the orthogonal projector onto the rows of ``base``; sparse.

    The rows of ``base`` spanning its row space are chosen by sparse elimination; then, per
    connected component of the rows' sparsity graph (a row is projected only on the base
    rows it is connected to: the others span a space orthogonal to it), the projection is
    ``B^T (B B^T)^{-1} B row`` by sparse LU of ``B B^T`` with one step of iterative
    refinement (Björck, "Numerical Methods for Least Squares Problems", Sect. 2.9).
    ``None`` when a choice or a factorisation is not clear (the caller takes the dense path).
    """
    import scipy.sparse as sp  # imported when used: small systems never need it
    from scipy.sparse.linalg import MatrixRankWarning, splu  # with scipy.linalg: imported when used

    norms = np.sqrt(np.asarray(rows.multiply(rows).sum(axis=1)).ravel())
    if base.shape[0]:
        chosen = independent_rows_eliminated([base], list(range(base.shape[0])))
        if chosen is None:
            return None
        base = base[chosen]
    if not base.shape[0] or not rows.shape[0]:
        return norms
    stacked = sp.vstack([base, rows]).tocsr()
    pattern = (stacked != 0).astype(float)
    nb = base.shape[0]
    for block in components(pattern @ pattern.T):
        inside_base = block[block < nb]
        inside_rows = block[block >= nb] - nb
        if not len(inside_base) or not len(inside_rows):
            continue
        B = base[inside_base]
        R = rows[inside_rows]
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("error", MatrixRankWarning)
                lu = splu((B @ B.T).tocsc())
        except (RuntimeError, MatrixRankWarning):
            return None
        normal = R.toarray()
        for _ in range(2):  # the projection and one refinement of it
            coefficients = lu.solve(np.asarray(B @ normal.T))
            if not np.all(np.isfinite(coefficients)):
                return None
            normal = normal - np.asarray(B.T @ coefficients).T
        norms[inside_rows] = np.linalg.norm(normal, axis=1)
    return norms


def _irregular_sparse(
    space: PhaseSpace,
    numerics: Numerics,
    candidates: list[sympy.Expr],
    chosen: list[int],
    old: list[sympy.Expr],
    reducible: list[sympy.Expr],
    points: list[np.ndarray],
) -> list[int] | None:
    """:func:`irregular_candidates` with sparse gradients (``None``: not decided sparsely, take the dense path)."""
    kept = np.array([i in chosen for i in range(len(candidates))], dtype=bool)
    everything = old + reducible + [candidates[i] for i in chosen]
    stacked = numerics.sparse_gradients(everything, points)
    rows = numerics.sparse_gradients(candidates, points)
    n_old = len(old) + len(reducible)
    sizes = np.zeros((len(points), len(candidates)))
    rough = np.zeros_like(sizes)
    for p in range(len(points)):
        for flag, base in ((True, stacked[p][:n_old]), (False, stacked[p])):
            selected = np.flatnonzero(kept == flag)
            if not len(selected):
                continue
            norms = _normal_norms(base.tocsr(), rows[p][selected].tocsr())
            if norms is None:
                return None
            sizes[p, selected] = norms
            largest = float(np.max(np.abs(base.data), initial=0.0)) if base.nnz else 0.0
            rough[p, selected] = norms / (1.0 + largest)
    found = []
    for i, c in enumerate(candidates):
        if np.max(rough[:, i]) > 1e-2:  # clearly regular: skip the finer test
            continue
        dq, dp = space.partials(c)
        terms = [*dq.values(), *dp.values()]
        scales = (numerics.term_scale(terms, points) - 1.0).sum(axis=1) + 1.0 if terms else np.ones(len(points))
        fine = sizes[:, i] / scales  # 1 + sum of |terms| of the gradient
        if np.all(fine < IRREGULAR_GRADIENT) and np.any(fine > ROUND_OFF):
            found.append(i)
    return found


def irregular_candidates(
    space: PhaseSpace,
    numerics: Numerics,
    candidates: list[sympy.Expr],
    chosen: list[int],
    old: list[sympy.Expr],
    reducible: list[sympy.Expr],
    points: list[np.ndarray],
) -> list[int]:
    """Indices of the candidates whose gradient vanishes where they hold (see the module docstring).

    A kept candidate is compared with the old constraints (and the reducible ones), a
    dropped one with those and the kept candidates: a normal component below
    ``IRREGULAR_GRADIENT`` times the gradient's term size at every point, yet above
    ``ROUND_OFF`` at one, marks an irregular constraint.
    """
    sparse = _irregular_sparse(space, numerics, candidates, chosen, old, reducible, points)
    if sparse is not None:
        return sparse
    n = len(space.variables)
    kept = np.array([i in chosen for i in range(len(candidates))], dtype=bool)
    everything = old + reducible + [candidates[i] for i in chosen]
    stacked = gradient_values(space, numerics, everything, points)
    rows = gradient_values(space, numerics, candidates, points)
    n_old = len(old) + len(reducible)
    rough = np.zeros((len(points), len(candidates)))
    bases: list[tuple[np.ndarray | None, np.ndarray | None]] = []
    for p in range(len(points)):
        pair = (_basis(stacked[p, :n_old]), _basis(stacked[p]))
        bases.append(pair)
        for flag, q, base in ((True, pair[0], stacked[p, :n_old]), (False, pair[1], stacked[p])):
            selected = np.flatnonzero(kept == flag)
            if len(selected):
                size = 1.0 + np.max(np.abs(base), initial=0.0)
                rough[p, selected] = _normal_sizes(rows[p, selected], q, np.full(len(selected), size))
    found = []
    for i, c in enumerate(candidates):
        if np.max(rough[:, i]) > 1e-2:  # clearly regular: skip the finer test
            continue
        grad = space.gradient(c)
        scales = numerics.term_scale(grad, points).sum(axis=1) - (n - 1)  # 1 + sum of |terms| of the gradient
        which = 0 if kept[i] else 1
        sizes = np.array([_normal_sizes(rows[p, i : i + 1], bases[p][which], scales[p : p + 1])[0] for p in range(len(points))])
        if np.all(sizes < IRREGULAR_GRADIENT) and np.any(sizes > ROUND_OFF):
            found.append(i)
    return found
