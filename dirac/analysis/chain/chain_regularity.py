"""Irregular new constraints of a large chain stage, with one orthogonal basis per point.

The test of :meth:`dirac.analysis.constraint_chain.ConstraintChain._irregular` (a new
constraint whose gradient is numerically normal to the surface's other gradients where
it holds: ``f^2 = 0``, ``x^2 + y^2 = 0``; Henneaux–Teitelboim, Sect. 1.1.2) projects each
candidate's gradient off the span of the earlier gradients. Done candidate by candidate
that is one QR factorisation of the whole base per candidate and point; here the base is
factorised once per point (twice: the old constraints for kept candidates, the old and
kept ones for dropped candidates) and every candidate projected on it — the same sizes,
the same decisions, at the cost of one factorisation per point.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import sympy

from dirac.analysis.legendre.regularity import IRREGULAR_GRADIENT, ROUND_OFF

if TYPE_CHECKING:
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
    position = {s: k for k, s in enumerate(space.variables)}
    momentum_position = {q: position[p] for q, p in zip(space.coordinates, space.momenta)}
    rows: list[int] = []
    cols: list[int] = []
    entries: list[sympy.Expr] = []
    for i, c in enumerate(constraints):
        dq, dp = space.partials(c)
        for q, d in dq.items():
            rows.append(i)
            cols.append(position[q])
            entries.append(d)
        for q, d in dp.items():
            rows.append(i)
            cols.append(momentum_position[q])
            entries.append(d)
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
