"""Loci where a rank the analysis reads drops, and sample points kept away from them.

The engine reads ranks at a few surface points: of the Hessian ``W`` (how many velocities
are solved), of ``{Phi_a, phi_k}`` (which multipliers are fixed) and of
``C_ab = {Phi_a, Phi_b}`` (the classes). A rank read at a point right on a locus where it
drops is wrong; one read next to such a locus is right, but everything built on the
inverse of that block (multipliers, the Dirac bracket) is ill-conditioned there, by
``1 / s`` for a singular value ``s``. Gauss–Newton projections are drawn to such loci
(onto ``p_2 (p_1 - 2) + 4 q_2^2 = 0`` they land at ``q_2 ~ 1e-3`` half the time). Here a
point is *next to* a locus when a singular value of the block, scaled by the size of the
terms its entries are computed from (:func:`magnitude`), is small but not round-off
(:func:`near_rank_drop`); :meth:`dirac.analysis.core.numeric.Numerics.surface_points`
sets such points aside.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import sympy

from dirac.analysis.core.numeric import ZERO_TOLERANCE, Numerics

__all__ = ["POLE_DISTANCE", "SINGULAR_MINOR", "BracketBlocks", "DivisorLocus", "EntryBlock", "magnitude", "near_rank_drop"]

#: a singular value of a matrix whose rank the analysis uses (``W``, ``{Phi_a, Phi_b}``,
#: ``{Phi_a, phi_k}``), relative to the size of the terms its entries are computed from,
#: between ``ZERO_TOLERANCE`` and this marks a point next to a locus where that rank drops
#: (:func:`near_rank_drop`): the rank is still read right there, but everything built on
#: the inverse of that block is ill-conditioned at the point (by ``1 / s`` per inverse)
SINGULAR_MINOR = 1e-4

#: a point whose first-order distance ``|d| / |grad d|`` to the zero set of a divisor ``d`` of
#: ``H_c`` is below this fraction of its size (``max(1, max_i |z_i|)``) lies next to a pole
#: (:class:`DivisorLocus`): a pole of order ``k`` amplifies the round-off of every quantity
#: evaluated there by about ``distance^-k``, which no relative test of cancellation sees when
#: the divisor is a monomial (``|q_1| / magnitude(q_1) = 1`` at every point)
POLE_DISTANCE = 0.05


def magnitude(expr: sympy.Expr, memo: dict[sympy.Expr, sympy.Expr] | None = None) -> sympy.Expr:
    """The size of the terms ``expr`` is computed from: ``expr`` with every sum and product taken of absolute values.

    ``|a + b| -> |a| + |b|``, ``|a b| -> |a| |b|``, ``|a^k| -> |a|^k`` (``k`` a positive
    integer), any other node ``f -> |f|``. Evaluated at a point, it bounds the value
    (``|expr| <= magnitude(expr)``), and the ratio of the two measures the cancellation
    at that point: the rounding error of evaluating ``expr`` is at most a small multiple
    of the unit round-off times this bound (Higham, *Accuracy and Stability of Numerical
    Algorithms*, 2nd ed., 2002, Sect. 3.1 and Sect. 5.1, the running error bound). Unlike
    :meth:`Numerics.term_scale` (top-level terms only), a cancellation inside a factor
    (``p_2 (p_1 - 2)`` at ``p_1 = 2``) is seen.
    """
    memo = {} if memo is None else memo
    found = memo.get(expr)
    if found is not None:
        return found
    # built unevaluated: only compiled, never simplified (sympy's canonical ordering would cost more than the rest)
    if expr.is_Number:
        size: sympy.Expr = abs(expr)
    elif expr.is_Symbol:
        size = sympy.Abs(expr, evaluate=False)
    elif expr.is_Add or expr.is_Mul:
        size = expr.func(*(magnitude(a, memo) for a in expr.args), evaluate=False)
    elif expr.is_Pow and expr.exp.is_Integer and expr.exp > 0:
        size = sympy.Pow(magnitude(expr.base, memo), expr.exp, evaluate=False)
    else:
        size = sympy.Abs(expr, evaluate=False)
    memo[expr] = size
    return size


def near_rank_drop(values: np.ndarray, sizes: np.ndarray) -> float | None:
    """The smallest singular value of ``values`` that is small but not round-off, or ``None``.

    ``values`` is a matrix at one point and ``sizes`` the :func:`magnitude` of each entry
    there. Entries at round-off of their own size (``|v| <= ZERO_TOLERANCE * size``) are
    zeros and are dropped, with their sizes (an entry written ``8 q (2 - p) + 8 q (p - 2)``
    is zero, however large its terms). The rest is equilibrated, rows and then columns
    divided by their largest size (constraints may be multiplied by any non-zero function,
    so only the scale-free part of the rank counts), and its singular values ``s`` are
    taken. A value with ``ZERO_TOLERANCE < s < SINGULAR_MINOR`` says that the point lies
    next to a locus where the rank drops (the values of a rank-deficient block at a
    regular point are round-off, below ``ZERO_TOLERANCE``; those of a full-rank block are
    of the order of its terms).
    """
    s = _equilibrated_singular_values(values, sizes)
    small = s[(s > ZERO_TOLERANCE) & (s < SINGULAR_MINOR)]
    return float(np.min(small)) if small.size else None


def _equilibrated_singular_values(values: np.ndarray, sizes: np.ndarray) -> np.ndarray:
    """Singular values of ``values`` with round-off entries dropped and rows, then columns, scaled by their largest size.

    Empty where nothing is left or a value is not finite (no decision can be read there).
    """
    sizes = np.where(np.abs(values) > ZERO_TOLERANCE * sizes, sizes, 0.0)
    rows = np.max(sizes, axis=1, initial=0.0) > 0
    values, sizes = values[rows], sizes[rows]
    if not values.size:
        return np.zeros(0)
    row_size = np.max(sizes, axis=1)
    values, sizes = values / row_size[:, None], sizes / row_size[:, None]
    columns = np.max(sizes, axis=0) > 0
    values = values[:, columns] / np.max(sizes[:, columns], axis=0)
    if not values.size or not np.all(np.isfinite(values)):
        return np.zeros(0)
    return np.linalg.svd(values, compute_uv=False)


class BracketBlocks:
    """Blocks of ``C_ab = {Phi_a, Phi_b}`` whose ranks the analysis reads, tested at points (:func:`near_rank_drop`).

    ``C`` and the sizes of its terms are formed at each point from the gradients of the
    constraints, ``C_ab = sum_i (dPhi_a/dq_i dPhi_b/dp_i - dPhi_a/dp_i dPhi_b/dq_i)`` and
    ``S_ab = sum_i (|dPhi_a/dq_i| |dPhi_b/dp_i| + |dPhi_a/dp_i| |dPhi_b/dq_i|)`` with
    ``|.|`` the :func:`magnitude` of each derivative: the magnitude of the bracket written
    out as that sum, without compiling the brackets (only the gradients, which the surface
    projections compile anyway, and their magnitudes).

    Parameters
    ----------
    numerics
        Where the gradients are compiled.
    rows
        The constraints (all that any block uses).
    blocks
        Name -> (row indices, column indices) into ``rows``: ``C_ab`` over all the
        constraints, ``{Phi_a, phi_k}`` over them and the primaries.
    memo
        :func:`magnitude` memo shared between the stages of one analysis.
    """

    def __init__(
        self,
        numerics: Numerics,
        rows: Sequence[sympy.Expr],
        blocks: Mapping[str, tuple[Sequence[int], Sequence[int]]],
        memo: dict[sympy.Expr, sympy.Expr] | None = None,
    ) -> None:
        space = numerics.phase_space
        self.blocks = {name: (list(r), list(c)) for name, (r, c) in blocks.items()}
        self._shape = (len(rows), len(space.variables))
        at_rows, at_cols, entries = space.gradient_entries(rows)
        self._at = (np.asarray(at_rows, dtype=int), np.asarray(at_cols, dtype=int))
        memo = {} if memo is None else memo
        self._values = numerics.function(entries)
        self._sizes = numerics.function([magnitude(e, memo) for e in entries])

    def near_rank_drop(self, z: np.ndarray) -> tuple[float, str] | None:
        """The smallest :func:`near_rank_drop` value of the blocks at ``z``, with the block's name."""
        gradients = np.zeros(self._shape)
        sizes = np.zeros(self._shape)
        gradients[self._at] = self._values(z)
        sizes[self._at] = self._sizes(z)
        n = self._shape[1] // 2
        dq, dp, sq, sp_ = gradients[:, :n], gradients[:, n:], sizes[:, :n], sizes[:, n:]
        C = dq @ dp.T - dp @ dq.T
        S = sq @ sp_.T + sp_ @ sq.T
        found = [(s, name) for name, (r, c) in self.blocks.items() if (s := near_rank_drop(C[np.ix_(r, c)], S[np.ix_(r, c)])) is not None]
        return min(found) if found else None


class EntryBlock:
    """A matrix of expressions whose rank the analysis relies on (the Hessian ``W``), compiled with its sizes.

    Parameters
    ----------
    numerics
        Where the entries and their :func:`magnitude` are compiled.
    matrix
        The matrix (entries in the phase-space variables, ``t`` and parameters).
    name
        How notes and errors name it.
    """

    def __init__(self, numerics: Numerics, matrix: sympy.Matrix, name: str) -> None:
        self.name = name
        self.shape = matrix.shape
        nonzero = matrix.todok()
        self._where = list(nonzero)
        self._at = tuple(np.array(k, dtype=int) for k in zip(*self._where)) if self._where else None
        exprs = [nonzero[k] for k in self._where]
        memo: dict[sympy.Expr, sympy.Expr] = {}
        self._values = numerics.function(exprs)
        self._sizes = numerics.function([magnitude(e, memo) for e in exprs])

    def at(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The matrix and the sizes of its entries at ``z``."""
        values = np.zeros(self.shape)
        sizes = np.zeros(self.shape)
        if self._at is not None:
            values[self._at] = self._values(z)
            sizes[self._at] = self._sizes(z)
        return values, sizes

    def near_rank_drop(self, z: np.ndarray) -> tuple[float, str] | None:
        """:func:`near_rank_drop` of the matrix at ``z``, with its name."""
        s = near_rank_drop(*self.at(z))
        return None if s is None else (s, self.name)

    def rank(self, z: np.ndarray) -> int:
        """The rank at ``z`` of the matrix with rows and columns scaled by the sizes of their terms.

        Entries at round-off of their own size are zeros; singular values at or below
        ``ZERO_TOLERANCE`` of the equilibrated matrix do not count (see :func:`near_rank_drop`).
        """
        return int(np.sum(_equilibrated_singular_values(*self.at(z)) > ZERO_TOLERANCE))


class DivisorLocus:
    """The zero sets of denominators of ``H_c``, tested at points like a block whose rank drops.

    Where the Legendre map solves the velocities from a block of ``W``, the block's
    determinant divides the canonical Hamiltonian; where it vanishes, ``H_c`` and every
    consistency condition have a pole, and ranks read there are meaningless. Gauss–Newton
    projections are drawn there too: onto the primary surface of the rigid body in its
    matrix coordinates (``R p_R^T`` symmetric), three of four projections landed within
    ``1e-11`` of ``det R = 0`` (one exactly on it). A point is *next to* the pole of a
    divisor ``d`` when either

    * ``|d| / magnitude(d)`` is below :data:`SINGULAR_MINOR` (or not finite): ``d`` is
      cancellation of its terms there, or
    * its first-order (Newton) distance to ``d = 0``, ``|d(z)| / |grad d(z)|``, is below
      :data:`POLE_DISTANCE` times ``max(1, max_i |z_i|)``. The first test cannot see a
      monomial divisor: ``q_1`` is never cancellation, yet onto ``p_3 + q_1^2 = 0`` three
      of four projections landed within ``0.03`` of ``q_1 = 0``
      (``L = -q_1 q_2'^2 - 2 q_1' - 2 q_2' - q_1^2 q_3'``, ``H_c`` divides by ``q_1``), where the rate of ``p_3 + q_1^2``
      under ``H_T``, ``~ 1 / q_1^4``, carried the round-off of the point to ``2e-6`` of its
      terms (Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd ed., 2002,
      Sect. 1.6: a condition number that grows as the point nears a singularity).

    Such a point is reported like a point next to a rank drop, and
    :meth:`dirac.analysis.core.numeric.Numerics.surface_points` sets it aside.

    Parameters
    ----------
    numerics
        Where the divisors, their gradients and their :func:`magnitude` are compiled.
    divisors
        The factors of the denominators of ``H_c``.
    """

    def __init__(self, numerics: Numerics, divisors: Sequence[sympy.Expr]) -> None:
        self.divisors = list(divisors)
        memo: dict[sympy.Expr, sympy.Expr] = {}
        space = numerics.phase_space
        self._width = len(space.variables)
        self._values = numerics.function(self.divisors)
        self._sizes = numerics.function([magnitude(d, memo) for d in self.divisors])
        self._gradients = numerics.function([g for d in self.divisors for g in space.gradient(d)])

    def near_rank_drop(self, z: np.ndarray) -> tuple[float, str] | None:
        """The smaller of ``|d| / magnitude(d)`` (when below :data:`SINGULAR_MINOR`) and the relative
        distance to ``d = 0`` (when below :data:`POLE_DISTANCE`) at ``z``, over the divisors,
        with the divisor's name; ``None`` when neither test fires."""
        with np.errstate(all="ignore"):
            values = np.abs(self._values(z))
            ratios = values / self._sizes(z)
            slopes = np.linalg.norm(self._gradients(z).reshape(len(self.divisors), self._width), axis=1)
            scale = max(1.0, float(np.max(np.abs(z[: self._width]), initial=0.0)))
            distances = values / (slopes * scale)
        ratios = np.where(np.isfinite(ratios), ratios, 0.0)
        distances = np.where(np.isnan(distances), 0.0, distances)  # 0/0: on a singular point of d = 0
        found = [(float(ratios[k]), k) for k in range(len(ratios)) if ratios[k] < SINGULAR_MINOR]
        found += [(float(distances[k]), k) for k in range(len(distances)) if distances[k] < POLE_DISTANCE]
        if not found:
            return None
        value, k = min(found)
        return value, f"the block of W the velocities are solved from (its determinant {self.divisors[k]} divides H_c)"
