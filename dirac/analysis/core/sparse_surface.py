"""The sparse Jacobian of a large, local system, for the projection onto its constraint surface.

:meth:`dirac.analysis.core.numeric.Numerics.surface_points` (random start, minimum-norm
Gauss–Newton steps bounded in length, convergence relative to each constraint's term sizes,
only regular points kept) takes its Jacobian from here for a large system, compiled entry by
entry over its non-zero pattern (a constraint of a local system touches O(1)
variables) and the step and the regularity test taken sparsely
(:func:`~dirac.analysis.core.sparse_numeric.minimum_norm_step`,
:func:`~dirac.analysis.core.sparse_numeric.full_row_rank`). Dense ``lstsq`` and SVD of an
``m x n`` Jacobian cost ``O(m n min(m, n))`` per step; here a step costs about the number
of non-zeros times the LSQR iterations.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
import sympy

from dirac.analysis.core.sparse_numeric import full_row_rank, minimum_norm_step

if TYPE_CHECKING:  # scipy.sparse is imported where it is used
    import scipy.sparse as sp

__all__ = ["SparseJacobian", "LARGE_SYSTEM"]

#: phase-space dimension from which surface points, independence and regularity are decided sparsely
LARGE_SYSTEM = 120


class SparseJacobian:
    """The Jacobian of ``constraints`` compiled over its non-zero pattern: ``J(z)`` as a CSR matrix."""

    def __init__(
        self, numerics: Any, constraints: Sequence[sympy.Expr], regular_tolerance: float, singular_gradient: float
    ) -> None:
        # numerics: a dirac.analysis.core.numeric.Numerics (not imported: numeric imports this module)
        space = numerics.phase_space
        rows, cols, entries = space.gradient_entries(constraints)
        self.shape = (len(constraints), len(space.variables))
        self.rows = np.array(rows, dtype=int)
        self.cols = np.array(cols, dtype=int)
        self._values = numerics.function(entries)

        self._entries = entries
        self._numerics = numerics
        self._regular_tolerance = regular_tolerance
        self._singular_gradient = singular_gradient

    def __call__(self, z: np.ndarray) -> sp.csr_matrix:
        import scipy.sparse as sp  # imported when used: small systems never need it
        return sp.csr_matrix((self._values(z), (self.rows, self.cols)), shape=self.shape)

    @staticmethod
    def finite(jacobian: sp.csr_matrix) -> bool:
        """Whether every stored entry is finite."""
        return bool(np.all(np.isfinite(jacobian.data)))

    @staticmethod
    def step(jacobian: sp.csr_matrix, residual: np.ndarray) -> np.ndarray:
        """The minimum-norm Gauss–Newton step ``dz`` of ``J dz = -r`` (LSQR or sparse LU)."""
        return minimum_norm_step(jacobian, residual)

    def singular(self, z: np.ndarray, regular: int) -> bool:
        """Whether the first ``regular`` gradients are dependent, or one of them vanishing, at ``z``."""
        return not full_row_rank(self(z)[:regular], self._regular_tolerance) or self.vanishing(
            z, regular, self._singular_gradient)

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
