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

import heapq
import warnings
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from dirac.analysis.core.graphs import connected_components, issparse

if TYPE_CHECKING:  # scipy.sparse is imported where it is used
    import scipy.sparse as sp

__all__ = ["independent_rows_one_pass", "independent_rows_eliminated", "Undecided", "CLEAR", "minimum_norm_step", "full_row_rank", "components", "ZERO"]

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

    def decide(self, row: np.ndarray) -> tuple[bool, np.ndarray]:
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
            independent, part = basis.decide(row)
            if independent:
                basis.add(row, part)
        bases.append(basis)
    return _majority_choice(bases, matrices, order)


def _majority_choice(states: Sequence[Any], rows: Sequence[Any], order: Sequence[int]) -> list[int]:
    """The greedy choice shared by the one-pass and the sparse elimination: row ``i`` (in
    ``order``) is kept when it raises the rank at a majority of the points.

    ``states[k]`` holds the rows kept at point ``k`` (``decide(row) -> (independent, reduced)``,
    ``add(row, reduced)``); ``rows[k][i]`` is row ``i`` there. A point that disagrees with the
    majority keeps its rows as they are: the later rank checks catch it.
    """
    chosen: list[int] = []
    for i in order:
        decisions = [state.decide(r[i]) for state, r in zip(states, rows)]
        if 2 * sum(flag for flag, _ in decisions) > len(states):
            chosen.append(i)
            for state, r, (flag, reduced) in zip(states, rows, decisions):
                if flag:
                    state.add(r[i], reduced)
    return chosen


#: a reduced row below ``ZERO`` times the stack's size is dependent, above ``CLEAR`` times it
#: independent; in between the elimination does not decide (the dense pass does)
CLEAR = 1e-6


class Undecided(Exception):
    """A row the sparse elimination cannot classify clearly: the dense pass must decide."""


class _Echelon:
    """Rows kept so far at one point, in echelon form: pivot column -> (position, row scaled to pivot 1).

    A row kept at position ``k`` is zero at the pivot columns of the rows kept before it, so a
    new row is reduced by the pivot rows in the order they were kept (a heap of the pivot
    columns it touches); the fill stays local for the rows of a local system.
    """

    def __init__(self) -> None:
        self.rows: dict[int, tuple[int, dict[int, float]]] = {}
        self.scale = 0.0

    def reduce(self, row: dict[int, float]) -> dict[int, float]:
        """``row`` minus the combination of kept rows that clears it at every pivot column."""
        out = dict(row)
        heap = [(self.rows[c][0], c) for c in out if c in self.rows]
        heapq.heapify(heap)
        while heap:
            _, c = heapq.heappop(heap)
            factor = out.pop(c, 0.0)
            if factor == 0.0:
                continue
            for k, x in self.rows[c][1].items():
                if k == c:
                    continue
                if k not in out and k in self.rows:
                    heapq.heappush(heap, (self.rows[k][0], k))
                out[k] = out.get(k, 0.0) - factor * x
        return out

    def decide(self, row: dict[int, float]) -> tuple[bool, dict[int, float]]:
        """Whether ``row`` is independent of the kept rows (relative to the stack's size), and its reduced form.

        Raises
        ------
        Undecided
            When the reduced row is neither below ``ZERO`` nor above ``CLEAR`` times the size.
        """
        values = np.fromiter(row.values(), dtype=float, count=len(row))
        norm = float(np.linalg.norm(values))
        if not np.isfinite(norm):
            return False, row
        scale = max(self.scale, norm)
        if scale == 0.0:
            return False, row
        reduced = self.reduce(row)
        size = float(np.linalg.norm(np.fromiter(reduced.values(), dtype=float, count=len(reduced))))
        if size <= ZERO * scale:
            return False, reduced  # the part normal to the kept rows is at most the reduced row: dependent
        if size > CLEAR * scale and np.isfinite(size):
            return True, reduced
        raise Undecided

    def add(self, row: dict[int, float], reduced: dict[int, float]) -> None:
        """Keep ``row``: its reduced form, scaled so that its largest entry (the pivot) is 1."""
        pivot = max(reduced, key=lambda k: (abs(reduced[k]), -k))
        value = reduced[pivot]
        self.rows[pivot] = (len(self.rows), {k: x / value for k, x in reduced.items() if x != 0.0})
        values = np.fromiter(row.values(), dtype=float, count=len(row))
        self.scale = max(self.scale, float(np.linalg.norm(values)))


def _sparse_rows(matrix: sp.spmatrix | np.ndarray) -> list[dict[int, float]]:
    """The rows of ``matrix`` as ``{column: value}`` of their non-zero entries."""
    import scipy.sparse as sp  # imported when used: small systems never need it
    M = sp.csr_matrix(matrix, dtype=float)
    M.eliminate_zeros()
    return [
        dict(zip(M.indices[M.indptr[i] : M.indptr[i + 1]].tolist(), M.data[M.indptr[i] : M.indptr[i + 1]].tolist()))
        for i in range(M.shape[0])
    ]


def independent_rows_eliminated(
    matrices: Sequence[sp.spmatrix | np.ndarray], order: Sequence[int], base: Sequence[sp.spmatrix | np.ndarray] | None = None
) -> list[int] | None:
    """Greedy choice of rows that raise the rank, in the given order, at a majority of points, by sparse elimination.

    The choice of :func:`dirac.analysis.core.numeric.independent_rows` for sparse rows: at each
    point the kept rows are held in echelon form (Gaussian elimination with the largest entry
    of each reduced row as its pivot, Golub & Van Loan, *Matrix Computations*, Sect. 3.4) and a
    candidate is reduced by them. The reduced row differs from the candidate by a
    combination of kept rows, so its norm bounds the part of the candidate normal to them
    from above: below ``ZERO`` times the size of the stack the row is dependent, as in the
    orthogonalisation pass; above ``CLEAR`` times the size it is independent. A row in
    between at some point is not decided here: ``None`` is returned and the caller takes the
    dense pass. Cost: the fill of the elimination, ``O(non-zeros)`` for the rows of a local system.

    Parameters
    ----------
    matrices
        The same matrix at several surface points (scipy sparse or dense arrays).
    order
        Row indices in order of preference.
    base
        Rows already chosen, one block per point, that every candidate must be independent of.

    Returns
    -------
    list of int or None
        Chosen row indices, or ``None`` when a decision is not clear at some point.
    """
    if not len(matrices):
        return []
    echelons = []
    rows = []
    try:
        for k, m in enumerate(matrices):
            echelon = _Echelon()
            if base is not None and base[k].shape[0]:
                for row in _sparse_rows(base[k]):
                    independent, reduced = echelon.decide(row)
                    if independent:
                        echelon.add(row, reduced)
            echelons.append(echelon)
            rows.append(_sparse_rows(m))
        return _majority_choice(echelons, rows, order)
    except Undecided:
        return None


def components(pattern: sp.spmatrix | np.ndarray) -> list[np.ndarray]:
    """Row sets of the connected components of the sparsity graph of a square ``pattern`` (sparse or dense)."""
    if issparse(pattern):
        import scipy.sparse as sp  # imported when used: a dense pattern never needs it

        count, labels = connected_components(sp.csr_matrix(pattern != 0))
    else:
        count, labels = connected_components(np.asarray(pattern) != 0)
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
    import scipy.sparse as sp  # imported when used: small systems never need it
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
    blocks = components(G)
    alone = np.array([block[0] for block in blocks if len(block) == 1], dtype=int)
    if len(alone) and np.min(G.diagonal()[alone]) <= tolerance**2:  # a 1 x 1 block is its eigenvalue
        return False
    for block in blocks:
        if len(block) == 1:
            continue
        part = G[block][:, block]
        if len(block) > DENSE_BLOCK:
            definite = _positive_definite((part - tolerance**2 * sp.identity(len(block))).tocsc())
            if definite is not None:
                if not definite:
                    return False
                continue
        values = np.linalg.eigvalsh(part.toarray())
        if values[0] <= tolerance**2:
            return False
    return True


#: blocks of ``J J^T`` larger than this are tested by a sparse factorisation, not dense eigenvalues
DENSE_BLOCK = 200


def _positive_definite(A: sp.csc_matrix) -> bool | None:
    """Whether the symmetric sparse ``A`` is positive definite, by its ``L D L^T`` factorisation.

    Sparse LU with a symmetric fill-reducing ordering and no row pivoting is ``P A P^T =
    L D L^T`` (``U = D L^T``); by Sylvester's law of inertia ``A`` is positive definite
    exactly when every ``D_ii > 0`` (Golub & Van Loan, *Matrix Computations*, Sect. 4.2,
    where the factorisation of a positive definite matrix needs no pivoting and is
    backward stable). ``None`` when the solver had to pivot off the diagonal (a zero on
    it): the caller decides densely.
    """
    from scipy.sparse.linalg import MatrixRankWarning, splu  # with scipy.linalg: imported when used

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", MatrixRankWarning)
            lu = splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
    except (RuntimeError, MatrixRankWarning):
        return False  # exactly singular: not positive definite
    if not np.array_equal(lu.perm_r, lu.perm_c):
        return None
    pivots = lu.U.diagonal()
    return bool(np.all(np.isfinite(pivots)) and np.all(pivots > 0.0))


def minimum_norm_step(jacobian: sp.spmatrix, residual: np.ndarray) -> np.ndarray:
    """The minimum-norm least-squares solution ``dz`` of ``J dz = -r`` (sparse ``J``).

    LSQR from ``dz = 0`` (Paige and Saunders, ACM TOMS 8 (1982) 43) converges to the
    minimum-norm solution, also for a rank-deficient ``J`` (reducible constraints): the
    step ``numpy.linalg.lstsq`` gives, without a dense factorisation.
    """
    import scipy.sparse as sp  # imported when used: small systems never need it
    from scipy.sparse.linalg import MatrixRankWarning, lsqr, splu  # with scipy.linalg: imported when used

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
