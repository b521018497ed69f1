"""The constrained Hamiltonian vector field of a general system, and its outputs.

On ``z = (q, p)`` with ``H = 1/2 p^T M(q)^{-1} p + V(q)`` and the second-class
constraints ``Phi = (chi(q), G(q) M(q)^{-1} p)`` (the paper's second and third stages,
Sect. X; the first and fourth stages only fix the multipliers and their momenta, which
are eliminated here), the motion is the Dirac-bracket flow (240)

    z_dot = {z, H}_D = J grad H - J grad Phi^T C^{-1} (grad Phi J grad H),
    C_ab = {Phi_a, Phi_b} = grad Phi_a^T J grad Phi_b,

with ``J = [[0, 1], [-1, 0]]``. ``C`` is evaluated and solved numerically at each point
(never a symbolic inverse); the numba kernel is
:func:`field` of the system's generated kernel module (:mod:`dirac.codegen.kernel_source`). Every ``Phi_a`` is an exact invariant of this field
(``{Phi_a, H}_D = 0`` identically), so quadratic constraints are kept by the implicit
midpoint rule.
"""

from __future__ import annotations

import numpy as np

__all__ = ["ConstrainedField", "constrained_outputs"]


class ConstrainedField:
    """Numerical Dirac vector field of a :class:`MechanicalSystem` (numba kernel)."""

    def __init__(self, mechanics) -> None:
        self.mechanics = mechanics
        if hasattr(mechanics, "require_field"):
            mechanics.require_field("a scipy method")
        self.n = mechanics.dimension
        self.m = mechanics.n_constraints
        self._kernel = mechanics.module.field
        self._params = mechanics.params

    def __call__(self, z: np.ndarray, time: float = 0.0) -> np.ndarray:
        """``z_dot`` at ``z = (q, p)`` (shape (2n,)) and ``time``."""
        out = np.empty(2 * self.n)
        self._kernel(np.ascontiguousarray(z, dtype=float), float(time), self._params, out)
        return out

    def scipy_rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        """``fun(t, y)`` for scipy's solvers."""
        return self(y, t)

    def outputs(self, names: tuple[str, ...], q: np.ndarray, p: np.ndarray, time: float = 0.0) -> dict[str, np.ndarray]:
        return constrained_outputs(self.mechanics, names, q, p, time)


def constrained_outputs(mechanics, names: tuple[str, ...], q: np.ndarray, p: np.ndarray,
                        time: float = 0.0) -> dict[str, np.ndarray]:
    """Outputs of a constrained system from batched ``q`` (B, n) and ``p`` (B, n) at ``time``.

    ``q_dot = M(q, t)^{-1} p``; ``energy = H``; ``constraint_residual`` is
    ``max(|chi(q, t)|, |G M^{-1} p + d chi/dt|)`` (positions and velocities).
    """
    result: dict[str, np.ndarray] = {}
    for name in names:
        if name == "q":
            result[name] = q.copy()
        elif name == "p":
            result[name] = p.copy()
        elif name == "q_dot":
            result[name] = np.array([np.linalg.solve(mechanics.mass_matrix(a, time), b) for a, b in zip(q, p)])
        elif name == "energy":
            result[name] = np.array([mechanics.energy(a, b, time) for a, b in zip(q, p)])
        elif name == "constraint_residual":
            result[name] = np.array([mechanics.constraint_residual(a, b, time) for a, b in zip(q, p)])
        else:  # pragma: no cover - validated before
            raise KeyError(name)
    return result
