"""What the rigid-body methods share: the batched state ``(M, R)`` and its outputs.

Used by the Lie–Poisson splittings, the heavy top, the implicit midpoint rule and the
exact flow; the outputs are those of :class:`dirac.flows.problems.RigidBodyProblem` and
:class:`dirac.flows.problems.HeavyTopProblem`.
"""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING, cast

import numpy as np

from dirac.errors import DiracWarning
from dirac.flows.methods.base import Stepper
from dirac.flows.problems import HeavyTopProblem, RigidBodyProblem

if TYPE_CHECKING:
    from dirac.rigidbody.exact import ExactRigidBodyFlow

__all__ = ["RigidBodyStepper", "exact_flow", "gravity_weight", "needs_attitude", "rigid_body_outputs"]


def exact_flow(inertia: np.ndarray, M0: np.ndarray, R0: np.ndarray | None) -> ExactRigidBodyFlow:
    """:class:`ExactRigidBodyFlow` of already validated data (its warnings were shown once)."""
    from dirac.rigidbody.exact import ExactRigidBodyFlow  # numba: only when a rigid body runs

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DiracWarning)
        return ExactRigidBodyFlow(inertia, M0, R0)


def needs_attitude(outputs: tuple[str, ...]) -> bool:
    """Whether any requested output depends on ``R``."""
    return any(name in ("R", "lab_momentum", "lab_momentum_z", "orthogonality") for name in outputs)


def gravity_weight(problem: RigidBodyProblem) -> np.ndarray | None:
    """``m g chi`` (body frame) of a heavy top; None for the free body."""
    if problem.kind == "heavy_top":
        return cast(HeavyTopProblem, problem).weight_vector
    return None


class RigidBodyStepper(Stepper):
    """Common state ``(M, R)`` (batched) and outputs of rigid-body steppers."""

    def __init__(self, problem: RigidBodyProblem, outputs: tuple[str, ...]) -> None:
        super().__init__()
        self.problem = problem
        self.weight = gravity_weight(problem)
        self.inertia = np.asarray(problem.inertia, dtype=float)
        self.inv_inertia = 1.0 / self.inertia
        self.outputs = outputs
        self.with_R = needs_attitude(outputs) or problem.kind == "heavy_top"
        self.M = np.ascontiguousarray(problem.M0, dtype=float).copy()
        self.R = np.ascontiguousarray(problem.R0, dtype=float).copy()

    def observe(self) -> dict[str, np.ndarray]:
        return rigid_body_outputs(self.outputs, self.M, self.R, self.inertia, self.weight)

    def finite(self) -> bool:
        return bool(np.all(np.isfinite(self.M)) and (not self.with_R or np.all(np.isfinite(self.R))))

    def drift(self) -> float:
        if not self.with_R:
            return 0.0
        eye = np.eye(3)
        return float(np.max(np.abs(np.einsum("bki,bkj->bij", self.R, self.R) - eye)))


def _attitude(R: np.ndarray | None) -> np.ndarray:
    if R is None:  # pragma: no cover - steppers keep R whenever an output needs it
        raise ValueError("this output needs the attitude R, which was not computed")
    return R


def rigid_body_outputs(
    outputs: tuple[str, ...], M: np.ndarray, R: np.ndarray | None, inertia: np.ndarray,
    weight: np.ndarray | None = None, work: np.ndarray | None = None,
) -> dict[str, np.ndarray]:
    """Compute the requested outputs from batched ``M`` (B, 3) and ``R`` (B, 3, 3).

    ``energy`` is ``H_0`` (247) for the free body and ``H_0 + m g <chi, R^T e_z>`` for
    the heavy top (``weight = m g chi``, :func:`gravity_weight`); ``casimir`` is
    ``|M|^2``; ``lab_momentum`` is ``m = R M``; ``lab_momentum_z`` its vertical
    component (conserved by the heavy top); ``work`` the work ``∫ N·Omega dt`` of the
    external torques and impulses since ``t = 0`` (zero when ``work`` is not given: no
    external torque acts).
    """
    result: dict[str, np.ndarray] = {}
    for name in outputs:
        if name == "M":
            result[name] = M.copy()
        elif name == "R":
            result[name] = _attitude(R).copy()
        elif name == "energy":
            energy = 0.5 * np.sum(M * M / inertia, axis=-1)
            if weight is not None:
                energy = energy + _attitude(R)[:, 2, :] @ weight
            result[name] = energy
        elif name == "casimir":
            result[name] = np.sum(M * M, axis=-1)
        elif name == "lab_momentum":
            result[name] = np.einsum("bij,bj->bi", _attitude(R), M)
        elif name == "lab_momentum_z":
            result[name] = np.einsum("bj,bj->b", _attitude(R)[:, 2, :], M)
        elif name == "work":
            result[name] = np.zeros(M.shape[0]) if work is None else np.array(work, dtype=float)
        else:  # pragma: no cover - outputs are validated before
            raise KeyError(name)
    return result
