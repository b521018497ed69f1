"""Exact linear solves weakly simplified on a constraint surface, by block triangular structure.

The algorithm meets linear systems ``A X = B`` whose entries are phase-space functions:
the equations that fix the multipliers, the combinations that make constraints first
class, and ``C^{-1}`` in the Dirac bracket (240). A dense symbolic inverse of a large
``A`` is hopeless, but these matrices are sparse once entries that vanish *weakly* (on
the constraint surface) are dropped — the paper uses exactly this when it inverts the
block matrix (245). Here the structure is found automatically: weakly zero entries of
``A`` and ``B`` are set to exact zeros (decided numerically at surface points), ``A`` is
permuted to block lower-triangular form (a perfect matching puts non-zeros on the
diagonal; strongly connected components of the dependency graph give the blocks, in
order), and each diagonal block is solved exactly; solution entries that vanish weakly
are set to exact zeros before they are used further. The result equals the true
solution on the surface.
"""

from __future__ import annotations

import time
from collections.abc import Sequence

import numpy as np
import sympy

from dirac.analysis.core.algebra import prints_shorter, tidy
from dirac.analysis.core.graphs import maximum_bipartite_matching
from dirac.errors import AnalysisError

__all__ = ["weak_solve", "weakly_solvable", "block_order", "SingularAtSamplePoint"]

RELATIVE_ZERO = 1e-9

#: expressions longer than this (characters of ``str``) are not given a rational normal
#: form: the gcds of ``cancel`` hang on them (the 24x24 solves of the rigid body)
TIDY_LIMIT = 4000

#: largest diagonal block solved by symbolic LU when a time limit is set
MAX_EXACT_BLOCK = 6


class SingularAtSamplePoint(AnalysisError):
    """A system that is independent at some sample points of the surface is singular at another.

    The surface then has parts of different structure; the caller, which knows the points,
    turns this into :class:`~dirac.errors.SeparableParts` so that the parts can be analysed
    one by one (:mod:`dirac.analysis.components`).
    """


class SolveTooLarge(AnalysisError):
    """An exact weak solve would exceed its size or time limit (see :func:`weak_solve`)."""


def _zero_mask(values: np.ndarray) -> np.ndarray:
    """Entries small at every point relative to the largest entry at that point."""
    # values: (points, rows, cols)
    scale = np.max(np.abs(values), axis=(1, 2), keepdims=True)
    scale[scale == 0] = 1.0
    return np.all(np.abs(values) <= RELATIVE_ZERO * scale, axis=0)


def block_order(pattern: np.ndarray) -> tuple[np.ndarray, list[list[int]]]:
    """Block lower-triangular order of a structurally non-singular square pattern.

    Returns
    -------
    match, blocks
        ``match[i]`` is the column (unknown) paired with row ``i``; ``blocks`` lists row
        sets in solving order (each block only needs unknowns of earlier blocks).
    """
    k = pattern.shape[0]
    matching = maximum_bipartite_matching(pattern.astype(np.int8))  # dense: no scipy.sparse import
    if np.any(matching < 0):
        raise AnalysisError("a matrix that must be invertible on the constraint surface is structurally singular")
    match = np.asarray(matching)
    col_row = np.empty(k, dtype=int)
    col_row[match] = np.arange(k)
    # row i depends on row j when A[i, match[j]] != 0
    edges = [[int(col_row[c]) for c in np.nonzero(pattern[i])[0] if col_row[c] != i] for i in range(k)]
    blocks: list[list[int]] = []
    index = [0]
    indices = [-1] * k
    low = [0] * k
    on_stack = [False] * k
    stack: list[int] = []

    def strong(v: int) -> None:  # Tarjan: emits components dependencies-first
        indices[v] = low[v] = index[0]
        index[0] += 1
        stack.append(v)
        on_stack[v] = True
        for w in edges[v]:
            if indices[w] < 0:
                strong(w)
                low[v] = min(low[v], low[w])
            elif on_stack[w]:
                low[v] = min(low[v], indices[w])
        if low[v] == indices[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack[w] = False
                comp.append(w)
                if w == v:
                    break
            blocks.append(sorted(comp))

    for v in range(k):
        if indices[v] < 0:
            strong(v)
    return match, blocks


def weakly_solvable(
    a_num: Sequence[np.ndarray], b_num: Sequence[np.ndarray] | np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[list[int]]]:
    """Check that ``A X = B`` is solvable at every sample point; its weak-zero pattern and the solutions there.

    The numeric half of :func:`weak_solve`, which :func:`weak_solve` runs first: a caller
    that defers the exact solve runs it at once, so that a refusal is never deferred.

    Returns
    -------
    a_zero, x_values, match, blocks
        The weakly zero entries of ``A`` (``k x k``), ``X`` at each point (``points x k x c``)
        and the block lower-triangular order of the pattern (:func:`block_order`).

    Raises
    ------
    AnalysisError
        When ``A`` is singular at a sample point, or structurally singular once its weakly
        zero entries are dropped.
    """
    a_vals = np.asarray(a_num, dtype=float)
    k = a_vals.shape[-1]
    a_vals = a_vals.reshape(-1, k, k)
    b_vals = np.asarray(b_num, dtype=float).reshape(len(a_vals), k, -1)
    a_zero = _zero_mask(a_vals)
    try:
        x_vals = np.array([np.linalg.solve(a, b) for a, b in zip(a_vals, b_vals)])
    except np.linalg.LinAlgError:
        raise SingularAtSamplePoint(
            f"a {k}x{k} system the analysis solves on the constraint surface is singular at one of its sample "
            "points, though independent at others: the surface has parts of different structure (a constraint "
            "whose branches cross, or a rank that changes on it); write the constraints so that each part is a "
            "system of its own"
        ) from None
    match, blocks = block_order(~a_zero)  # structurally singular: refused here
    return a_zero, x_vals, match, blocks
def _lu_solve(a: sympy.Matrix, b: sympy.Matrix, values: np.ndarray) -> sympy.Matrix | None:
    """``a^{-1} b`` by symbolic LU elimination with pivots chosen at the surface points.

    The arithmetic of :meth:`sympy.Matrix.LUsolve` (Doolittle elimination, forward and
    back substitution, row by row), so the same expressions for the same pivots. Only the
    pivot search differs: sympy takes the first candidate of a column that its
    assumptions cannot show to be zero (``is_zero``, costly on large entries, and blind to
    an entry that vanishes on the constraint surface only); here it is the first candidate
    that is non-zero at every point of ``values`` (the block at the surface points, shape
    ``(points, k, k)``, eliminated alongside), so no pivot vanishes on the surface.
    Products with an exact zero, which sympy forms and then discards, are skipped.
    ``None`` when some column has no such candidate.
    """
    k = a.shape[0]
    lu = [[a[i, j] for j in range(k)] for i in range(k)]
    num = np.array(values, dtype=float).copy()
    rows = list(range(k))
    zero = sympy.S.Zero
    for col in range(k - 1):
        scale = np.max(np.abs(num[:, col:, col:]), axis=(1, 2))
        scale[scale == 0] = 1.0
        pivot = next((r for r in range(col, k) if lu[r][col] != 0
                      and np.all(np.abs(num[:, r, col]) > RELATIVE_ZERO * scale)), None)
        if pivot is None:
            return None
        if pivot != col:
            lu[col], lu[pivot] = lu[pivot], lu[col]
            num[:, [col, pivot]] = num[:, [pivot, col]]
            rows[col], rows[pivot] = rows[pivot], rows[col]
        for r in range(col + 1, k):
            factor = lu[r][col] / lu[col][col] if lu[r][col] != 0 else zero
            lu[r][col] = factor
            ratio = num[:, r, col] / num[:, col, col]
            num[:, r, col + 1 :] -= ratio[:, None] * num[:, col, col + 1 :]
            if factor == 0:
                continue
            for c in range(col + 1, k):
                if lu[col][c] != 0:
                    lu[r][c] = lu[r][c] - factor * lu[col][c]
    last = np.max(np.abs(num[:, k - 1 :, k - 1 :]), axis=(1, 2))
    if lu[k - 1][k - 1] == 0 or not np.all(np.abs(num[:, k - 1, k - 1]) > RELATIVE_ZERO * np.where(last == 0, 1.0, last)):
        return None
    x = [[b[r, c] for c in range(b.shape[1])] for r in rows]
    for i in range(k):  # forward substitution (unit lower triangle)
        for j in range(i):
            if lu[i][j] != 0:
                x[i] = [xi - lu[i][j] * xj if xj != 0 else xi for xi, xj in zip(x[i], x[j])]
    for i in range(k - 1, -1, -1):  # back substitution
        for j in range(i + 1, k):
            if lu[i][j] != 0:
                x[i] = [xi - lu[i][j] * xj if xj != 0 else xi for xi, xj in zip(x[i], x[j])]
        inverse = lu[i][i] ** -1
        x[i] = [inverse * xi for xi in x[i]]
    return sympy.Matrix(x)


def weak_solve(
    a_sym: sympy.Matrix,
    b_sym: sympy.Matrix,
    a_num: Sequence[np.ndarray],
    b_num: Sequence[np.ndarray],
    simplify: bool = True,
    variables: Sequence[sympy.Symbol] = (),
    time_limit: float | None = None,
) -> sympy.Matrix:
    """Solve ``A X = B`` exactly, weakly (on the surface where ``a_num``, ``b_num`` were taken).

    Parameters
    ----------
    a_sym, b_sym
        Square ``A`` (``k x k``) and right-hand side ``B`` (``k x c``), sympy matrices.
    a_num, b_num
        ``A`` and ``B`` evaluated at several points of the constraint surface.
    simplify
        Bring solutions of 1x1 blocks to the readable form of
        :func:`~dirac.analysis.chain.constraint_chain.tidy` (in the phase-space ``variables``);
        solutions longer than ``TIDY_LIMIT`` characters are left as they are (no gcd).
    time_limit
        Seconds allowed (``None``: no limit). With a limit, diagonal blocks larger than
        ``MAX_EXACT_BLOCK`` are refused at once and the clock is checked between blocks.

    Returns
    -------
    sympy.Matrix
        ``X`` (``k x c``), equal to ``A^{-1} B`` on the surface.

    Raises
    ------
    SolveTooLarge
        When a limit is exceeded (only with ``time_limit``).
    """
    start = time.monotonic()
    k = a_sym.shape[0]
    cols = b_sym.shape[1]
    b_vals = np.asarray(b_num, dtype=float).reshape(-1, k, cols)
    a_vals = np.asarray(a_num, dtype=float).reshape(-1, k, k)
    a_zero, x_vals, match, blocks = weakly_solvable(list(a_vals), b_vals)
    b_zero = _zero_mask(b_vals)
    x_zero = _zero_mask(x_vals)
    A = sympy.Matrix(k, k, lambda i, j: sympy.S.Zero if a_zero[i, j] else a_sym[i, j])
    B = sympy.Matrix(k, cols, lambda i, j: sympy.S.Zero if b_zero[i, j] else b_sym[i, j])
    X = sympy.zeros(k, cols)
    for block in blocks:
        unknowns = [int(match[i]) for i in block]
        rhs = sympy.Matrix(len(block), cols, lambda r, c, block=block: B[block[r], c])
        for r, i in enumerate(block):
            for j in range(k):
                if j in unknowns or A[i, j] == 0:
                    continue
                for c in range(cols):
                    if X[j, c] != 0:
                        rhs[r, c] -= A[i, j] * X[j, c]
        if all(x_zero[u, c] for u in unknowns for c in range(cols)):
            continue
        if time_limit is not None:
            if len(block) > MAX_EXACT_BLOCK:
                raise SolveTooLarge(
                    f"the exact solve needs a {len(block)}x{len(block)} block that does not vanish weakly "
                    f"(limit {MAX_EXACT_BLOCK}x{MAX_EXACT_BLOCK})"
                )
            if time.monotonic() - start > time_limit:
                raise SolveTooLarge(f"the exact solve took more than {time_limit:g} s")
        sub = sympy.Matrix(len(block), len(block), lambda r, s, block=block, unknowns=unknowns: A[block[r], unknowns[s]])
        if len(block) == 1:
            sol = rhs / sub[0, 0]
        else:
            values = np.where(a_zero[np.ix_(block, unknowns)], 0.0, a_vals[:, block][:, :, unknowns])
            sol = _lu_solve(sub, rhs, values)
            if sol is None:  # no pivot order that is non-zero at every point: sympy's own search
                sol = sub.LUsolve(rhs)
        for r, u in enumerate(unknowns):
            for c in range(cols):
                if x_zero[u, c]:
                    continue
                value = sol[r, c]
                if simplify and len(block) == 1:
                    value = tidy(value, variables, rational=prints_shorter(value, TIDY_LIMIT))
                X[u, c] = value
    return X
