"""Points of the constraint surface of a large, local system: Gauss–Newton with a sparse Jacobian.

The same projection as :meth:`dirac.analysis.core.numeric.Numerics.surface_points` (random
start, minimum-norm Gauss–Newton steps bounded in length, convergence relative to each
constraint's term sizes, only regular points kept), with the Jacobian compiled entry by
entry over its non-zero pattern (a constraint of a local system touches O(1)
variables) and the step and the regularity test taken sparsely
(:func:`~dirac.analysis.core.sparse_numeric.minimum_norm_step`,
:func:`~dirac.analysis.core.sparse_numeric.full_row_rank`). Dense ``lstsq`` and SVD of an
``m x n`` Jacobian cost ``O(m n min(m, n))`` per step; here a step costs about the number
of non-zeros times the LSQR iterations.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import scipy.sparse as sp
import sympy

from dirac.analysis.core.sparse_numeric import full_row_rank, minimum_norm_step

__all__ = ["sparse_surface_points", "SparseJacobian", "LARGE_SYSTEM"]

#: phase-space dimension from which surface points, independence and regularity are decided sparsely
LARGE_SYSTEM = 120


class SparseJacobian:
    """The Jacobian of ``constraints`` compiled over its non-zero pattern: ``J(z)`` as a CSR matrix."""

    def __init__(self, numerics: Any, constraints: Sequence[sympy.Expr]) -> None:
        # numerics: a dirac.analysis.core.numeric.Numerics (not imported: numeric imports this module)
        space = numerics.phase_space
        position = {s: k for k, s in enumerate(space.variables)}
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
                cols.append(position[space.momenta[space.coordinates.index(q)]])
                entries.append(d)
        self.shape = (len(constraints), len(space.variables))
        self.rows = np.array(rows, dtype=int)
        self.cols = np.array(cols, dtype=int)
        self._values = numerics.function(entries)

        self._entries = entries
        self._numerics = numerics

    def __call__(self, z: np.ndarray) -> sp.csr_matrix:
        return sp.csr_matrix((self._values(z), (self.rows, self.cols)), shape=self.shape)

    def vanishing(self, z: np.ndarray, regular: int, threshold: float) -> bool:
        """Whether one of the first ``regular`` gradients is vanishing at ``z`` relative to its terms.

        The test of :meth:`dirac.analysis.core.numeric.Numerics._vanishing_gradient` over the
        non-zero entries: each row's length against ``1 + sum |term|`` of its entries; below
        ``threshold`` the point lies next to where the gradient vanishes (a singular point,
        Henneaux–Teitelboim, Sect. 1.1.2).
        """
        keep = self.rows < regular
        if not np.any(keep):
            return False
        values = np.asarray(self._values(z), dtype=float)[keep]
        rows = self.rows[keep]
        scales = self._numerics.term_scale([e for e, k in zip(self._entries, keep) if k], [z])[0] - 1.0
        lengths = np.sqrt(np.bincount(rows, weights=values**2, minlength=regular))
        sizes = lengths / (1.0 + np.bincount(rows, weights=scales, minlength=regular))
        return bool(np.any(sizes < threshold))


def sparse_surface_points(
    numerics: Any,
    constraints: Sequence[sympy.Expr],
    count: int,
    fixed: Mapping[int, float] | None = None,
    attempts: int = 40,
    start: np.ndarray | None = None,
    regular: int = 0,
    surface_tolerance: float = 1e-11,
    regular_tolerance: float = 1e-6,
    singular_gradient: float = 1e-4,
) -> tuple[list[np.ndarray], int]:
    """Regular points on ``constraints = 0``: :meth:`Numerics.surface_points` with sparse linear algebra.

    Same arguments and tolerances as :meth:`dirac.analysis.core.numeric.Numerics.surface_points`
    (which passes its own). Returns the points found (up to ``count``) and the number of
    converged points dropped as singular; the caller raises when there are too few.
    """

    constraints = [sympy.sympify(c) for c in constraints]
    residual = numerics.function(constraints)
    jacobian = SparseJacobian(numerics, constraints)
    n = len(numerics.phase_space.variables)
    m = len(constraints)
    fixed = dict(fixed or {})
    free = np.array([i for i in range(n) if i not in fixed], dtype=int)
    points: list[np.ndarray] = []
    tries = 0
    singular = 0
    while len(points) < count and tries < attempts:
        tries += 1
        z = start.copy() if (start is not None and tries == 1) else numerics.random_point()
        for i, v in fixed.items():
            z[i] = v
        if m == 0:
            points.append(z)
            continue
        ok = False
        for _ in range(60):
            r = residual(z)
            if not np.all(np.isfinite(r)):
                break
            size = numerics.term_scale(constraints, [z])[0] if np.max(np.abs(r)) < 1e-6 else None
            if size is not None and np.all(np.abs(r) <= surface_tolerance * size):
                ok = True
                break
            J = jacobian(z)
            if not np.all(np.isfinite(J.data)):
                break
            step = minimum_norm_step(J[:, free], r)
            norm = np.linalg.norm(step)
            if norm > 10.0:  # keep steps bounded far from the surface
                step *= 10.0 / norm
            z = z.copy()
            z[free] += step
        if ok and regular and not full_row_rank(jacobian(z)[:regular], regular_tolerance):
            singular += 1
            continue
        if ok and regular and jacobian.vanishing(z, regular, singular_gradient):
            singular += 1
            continue
        if ok:
            points.append(z)
    return points, singular
