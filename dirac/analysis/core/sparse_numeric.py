"""Numerical decisions for large, local systems: one pass instead of one SVD per row.

The Dirac–Bergmann chain decides independence (of constraint gradients, of the rows of
the consistency matrix) by a greedy choice of rows in an order of preference: a row is
kept when it raises the rank at a majority of the surface points
(:func:`dirac.analysis.core.numeric.independent_rows`). Computed with one SVD of the growing
stack per candidate row, that costs ``O(m)`` SVDs, ``O(m^2 n^2)`` in all for ``m`` rows of
length ``n``. Here the same greedy choice is made in one pass per point: an orthonormal
basis of the rows kept so far is extended row by row (Gram–Schmidt with one
re-orthogonalisation, Björck, "Numerical Methods for Least Squares Problems", Sect.
2.4.5), and a row raises the rank when the part of it orthogonal to the basis is larger
than ``ZERO`` times the size of the stack (the largest row norm, which bounds the largest
singular value from below). ``O(m r n)`` per point for ``r`` kept rows.

The Gauss–Newton steps of the surface points (minimum-norm solution of ``J dz = -r``)
and the regularity test of a point (the row-normalised Jacobian has full rank) work on
the sparse Jacobian of a local system: :func:`minimum_norm_step` solves the normal
equations of the second kind ``J J^T y = -r``, ``dz = J^T y`` by sparse LU when they are
regular, and otherwise with LSQR (Paige–Saunders 1982), whose iterates from zero converge
to the minimum-norm solution,
and :func:`full_row_rank` decides the rank of ``J J^T`` block by block over the connected
components of its sparsity graph (dense eigenvalues of each small block).
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from scipy.sparse.linalg import MatrixRankWarning, lsqr, splu

__all__ = ["independent_rows_one_pass", "minimum_norm_step", "full_row_rank", "components", "ZERO"]

#: relative size of the orthogonal part below which a row counts as dependent
ZERO = 1e-8


class _Basis:
    """An orthonormal basis of the rows kept so far at one point (rows of ``Q``)."""

    def __init__(self, n: int, capacity: int) -> None:
        self.Q = np.zeros((max(capacity, 1), n))
        self.size = 0
        self.scale = 0.0

    def orthogonal_part(self, row: np.ndarray) -> np.ndarray:
        """``row`` minus its projection on the basis (twice: classical Gram–Schmidt, re-orthogonalised)."""
        Q = self.Q[: self.size]
        out = row.astype(float, copy=True)
        if self.size:
            out -= Q.T @ (Q @ out)
            out -= Q.T @ (Q @ out)
        return out

    def raises_rank(self, row: np.ndarray) -> tuple[bool, np.ndarray]:
        """Whether ``row`` is independent of the basis (relative to the stack's size), and its orthogonal part."""
        norm = float(np.linalg.norm(row))
        if not np.isfinite(norm):
            return False, row
        scale = max(self.scale, norm)
        if scale == 0.0:
            return False, row
        part = self.orthogonal_part(row)
        return bool(np.linalg.norm(part) > ZERO * scale), part

    def add(self, row: np.ndarray, part: np.ndarray) -> None:
        """Extend the basis by the normalised orthogonal part of ``row``."""
        if self.size == len(self.Q):
            self.Q = np.vstack([self.Q, np.zeros_like(self.Q)])
        self.Q[self.size] = part / np.linalg.norm(part)
        self.size += 1
        self.scale = max(self.scale, float(np.linalg.norm(row)))


def independent_rows_one_pass(
    matrices: Sequence[np.ndarray], order: Sequence[int], base: Sequence[np.ndarray] | None = None
) -> list[int]:
    """Greedy choice of rows that raise the rank, in the given order, at a majority of points.

    The same choice as :func:`dirac.analysis.core.numeric.independent_rows` (same arguments,
    same majority vote), made in one orthogonalisation pass per point instead of one SVD
    per candidate row. The rows of ``base`` (already kept) enter the basis first, the
    independent ones among them only.

    Parameters
    ----------
    matrices
        The same matrix evaluated at several surface points.
    order
        Row indices in order of preference.
    base
        Rows already chosen, one block per point, that every candidate must be
        independent of.

    Returns
    -------
    list of int
        Chosen row indices.
    """
    if not len(matrices):
        return []
    n = matrices[0].shape[1] if matrices[0].ndim == 2 else 0
    bases = []
    for k in range(len(matrices)):
        rows_base = base[k] if base is not None and len(base[k]) else np.zeros((0, n))
        basis = _Basis(n, len(rows_base) + len(order))
        for row in rows_base:
            independent, part = basis.raises_rank(row)
            if independent:
                basis.add(row, part)
        bases.append(basis)
    chosen: list[int] = []
    for row in order:
        decisions = [basis.raises_rank(m[row]) for basis, m in zip(bases, matrices)]
        if 2 * sum(flag for flag, _ in decisions) > len(matrices):
            chosen.append(row)
            for basis, m, (flag, part) in zip(bases, matrices, decisions):
                if flag:  # a point that disagrees keeps its basis: the later rank checks catch it
                    basis.add(m[row], part)
    return chosen


def components(pattern: sp.spmatrix) -> list[np.ndarray]:
    """Row sets of the connected components of the sparsity graph of a square ``pattern``."""
    count, labels = connected_components(sp.csr_matrix(pattern != 0), directed=False)
    order = np.argsort(labels, kind="stable")
    cuts = np.flatnonzero(np.diff(labels[order])) + 1
    return [np.sort(block) for block in np.split(order, cuts)] if count else []


def full_row_rank(jacobian: sp.spmatrix, tolerance: float) -> bool:
    """Whether the rows of the sparse ``jacobian`` are independent after scaling each to unit length.

    The smallest singular value of the row-normalised ``J`` must exceed ``tolerance``
    (the test of :meth:`dirac.analysis.core.numeric.Numerics._regular_point`): the smallest
    eigenvalue of ``J J^T`` must exceed ``tolerance**2``. ``J J^T`` is block diagonal over
    the connected components of its sparsity graph; each block's eigenvalues are taken
    densely.
    """
    J = sp.csr_matrix(jacobian, dtype=float)
    if J.shape[0] == 0:
        return True
    if not np.all(np.isfinite(J.data)):
        return False
    norms = np.sqrt(np.asarray(J.multiply(J).sum(axis=1)).ravel())
    if np.any(norms == 0):
        return False
    if J.shape[0] > J.shape[1]:
        return False
    Jn = sp.diags(1.0 / norms) @ J
    G = (Jn @ Jn.T).tocsr()
    for block in components(G):
        values = np.linalg.eigvalsh(G[block][:, block].toarray())
        if values[0] <= tolerance**2:
            return False
    return True


def minimum_norm_step(jacobian: sp.spmatrix, residual: np.ndarray) -> np.ndarray:
    """The minimum-norm least-squares solution ``dz`` of ``J dz = -r`` (sparse ``J``).

    LSQR from ``dz = 0`` (Paige and Saunders, ACM TOMS 8 (1982) 43) converges to the
    minimum-norm solution, also for a rank-deficient ``J`` (reducible constraints): the
    step ``numpy.linalg.lstsq`` gives, without a dense factorisation.
    """
    J = sp.csr_matrix(jacobian, dtype=float)
    rhs = -np.asarray(residual, dtype=float)
    if J.shape[0] <= J.shape[1]:  # full row rank: dz = J^T y with J J^T y = -r, by sparse LU
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("error", MatrixRankWarning)
                y = splu((J @ J.T).tocsc()).solve(rhs)
            step = J.T @ y
            if np.all(np.isfinite(step)) and np.linalg.norm(J @ step - rhs) <= 1e-10 * (1.0 + np.linalg.norm(rhs)):
                return np.asarray(step, dtype=float)
        except (RuntimeError, MatrixRankWarning):
            pass  # singular J J^T (dependent rows): LSQR below
    result = lsqr(J, rhs, atol=1e-15, btol=1e-15, iter_lim=20 * max(J.shape))
    return np.asarray(result[0], dtype=float)
