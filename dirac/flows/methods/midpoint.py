"""``midpoint``: the implicit midpoint rule ``z1 = z0 + h F((z0 + z1)/2)``.

Symmetric, order 2, and it keeps every quadratic first integral of ``F`` exactly
(Cooper 1987; Hairer, Lubich & Wanner IV.2). That makes it a Poisson integrator for the
rigid body (Lie–Poisson structure, Austin, Krishnaprasad & Wang 1993): ``|M|^2``, ``H_0``,
``m = R M`` and ``R^T R = 1`` are all quadratic and all kept.

* Free rigid body, Euler–Poisson (250)–(251): ``M`` first, by Newton on 3 unknowns with
  the exact Jacobian; then ``R1 = R0 cay(h Omega_mid)`` with the Cayley transform
  ``cay(A) = (1 + A/2)(1 - A/2)^{-1}`` of ``hat(Omega_mid)`` (the midpoint rule for
  ``dR/dt = R hat(Omega_mid)``, orthogonal by construction); numba kernel
  :func:`dirac.rigidbody.midpoint.midpoint_rigid_body`.
* General systems: the Dirac vector field of :mod:`dirac.flows.dirac_field` with
  simplified Newton iterations (``midpoint_run`` of the system's generated kernel module,
  :mod:`dirac.codegen.kernel_source`). Quadratic holonomic
  constraints (pendulums) and their quadratic time derivatives are kept to the Newton
  tolerance.
* Analysed systems (any Lagrangian the Dirac–Bergmann engine analyses): the Dirac vector
  field on the full phase space, :mod:`dirac.flows.analysed`. Its later-stage
  constraints (e.g. the fourth stage, cubic in the pendulum) are not quadratic, so each
  step ends with an orthogonal projection onto the constraint surface (Hairer, Lubich &
  Wanner IV.4); this projected midpoint is no longer exactly symmetric, still order 2.
"""

from __future__ import annotations

import numpy as np

from dirac.flows.methods.base import Method, StepFailure, Stepper
from dirac.flows.methods.constrained_stepper import (
    ConstrainedStepper,
    call_tiered,
    newton_options,
    singular_as_step_failure,
    tiered,
)
from dirac.flows.methods.rigid_body_stepper import RigidBodyStepper

__all__ = ["RigidBodyMidpointStepper", "ConstrainedMidpointStepper", "AnalysedMidpointStepper", "METHODS"]


def _raise_if_failed(info: np.ndarray, max_iter: int) -> None:
    """The :class:`StepFailure` of a midpoint kernel whose ``info`` reports a failed step."""
    if info[1] != 0.0:
        raise StepFailure(f"midpoint: Newton iteration did not converge in {max_iter} iterations "
                          f"(increment {info[3]:.3g}); reduce dt", steps_done=int(info[0]))


class RigidBodyMidpointStepper(RigidBodyStepper):
    """Implicit midpoint on the Euler–Poisson equations."""

    def __init__(self, problem, outputs: tuple[str, ...], options: dict) -> None:
        super().__init__(problem, outputs)
        self.tol, self.max_iter, self.info = newton_options(options)
        from dirac.rigidbody.midpoint import midpoint_rigid_body  # numba: imported when a body runs

        self._kernel = midpoint_rigid_body

    def warm_up(self) -> None:
        self._kernel(self.M[0].copy(), self.R[0].copy(), self.inv_inertia, 1e-3, 1, self.with_R,
                            self.tol, self.max_iter, self.info)

    def step(self, n_steps: int, dt: float) -> None:
        for b in range(self.M.shape[0]):
            self._kernel(self.M[b], self.R[b], self.inv_inertia, dt, n_steps, self.with_R,
                                self.tol, self.max_iter, self.info)
            self.evaluations += int(self.info[2])
            _raise_if_failed(self.info, self.max_iter)
        self.steps += n_steps


class ConstrainedMidpointStepper(ConstrainedStepper):
    """Implicit midpoint on the Dirac vector field of a general system."""

    def __init__(self, problem, outputs: tuple[str, ...], options: dict) -> None:
        super().__init__(problem, outputs, options)
        self.mechanics.require_field("midpoint")
        for q in self.q:
            self.mechanics.mass_matrix(q)
        self.z = np.ascontiguousarray(np.concatenate([self.q, self.p], axis=1))
        # q and p are views of z, so the kernel's updates of z show in them
        n = self.mechanics.dimension
        self.q = self.z[:, :n]
        self.p = self.z[:, n:]
        self._kernel = tiered(self.mechanics.module, "midpoint_run")

    def warm_up(self) -> None:
        self._kernel_call(self._kernel, 1, self.z[0].copy(), self.time, self.mechanics.params, 1e-6, 1, self.tol,
                          self.max_iter, self.info, warm_up=True)

    def step(self, n_steps: int, dt: float) -> None:
        for b in range(self.z.shape[0]):
            with singular_as_step_failure("midpoint"):
                self._kernel_call(self._kernel, n_steps, self.z[b], self.time, self.mechanics.params, dt, n_steps,
                                  self.tol, self.max_iter, self.info)
            self.evaluations += int(self.info[2])
            self._raise_if_failed("midpoint")
        self.steps += n_steps
        self.time += n_steps * dt


class AnalysedMidpointStepper(Stepper):
    """Implicit midpoint on the Dirac vector field of an analysed system (full phase space)."""

    def __init__(self, problem, outputs: tuple[str, ...], options: dict) -> None:
        super().__init__()
        self.problem = problem
        self.analysed = problem.analysed
        self.outputs = outputs
        self.z = np.ascontiguousarray(problem.z0, dtype=float).copy()
        self.tol, self.max_iter, self.info = newton_options(options)
        self._kernel = tiered(self.analysed.module, "midpoint_run")
        self.time = 0.0
        self.planned_steps: int | None = options.get("planned_steps")
        self.pilot = bool(options.get("pilot", False))  # a pilot of auto (ConstrainedStepper.pilot)

    def _run(self, z: np.ndarray, n_steps: int, dt: float, warm_up: bool = False) -> None:
        args = (z, self.time, self.analysed.params, dt, n_steps, self.tol, self.max_iter, self.info)
        call_tiered(self._kernel, self.planned_steps, self.steps, n_steps, args, warm_up, pilot=self.pilot)

    def warm_up(self) -> None:
        self._run(self.z[0].copy(), 1, 1e-6, warm_up=True)

    def step(self, n_steps: int, dt: float) -> None:
        for b in range(self.z.shape[0]):
            with singular_as_step_failure("midpoint"):
                self._run(self.z[b], n_steps, dt)
            self.evaluations += int(self.info[2])
            _raise_if_failed(self.info, self.max_iter)
        self.steps += n_steps
        self.time += n_steps * dt

    def observe(self) -> dict[str, np.ndarray]:
        from dirac.flows.analysed import analysed_outputs  # imports sympy: only for analysed systems

        return analysed_outputs(self.analysed, self.outputs, self.z, self.time)

    def finite(self) -> bool:
        return bool(np.all(np.isfinite(self.z)))

    def drift(self) -> float:
        return max(self.analysed.constraint_residual(z, self.time) for z in self.z)


def _rigid_body_factory(method: Method, problem, outputs, options) -> Stepper:
    return RigidBodyMidpointStepper(problem, outputs, options)


def _constrained_factory(method: Method, problem, outputs, options) -> Stepper:
    return ConstrainedMidpointStepper(problem, outputs, options)


def _analysed_factory(method: Method, problem, outputs, options) -> Stepper:
    return AnalysedMidpointStepper(problem, outputs, options)


#: The one method of this family.
METHODS: tuple[Method, ...] = (
    Method(
        name="midpoint",
        order=2,
        kind="fixed",
        symplectic=True,
        preserves_casimirs=True,
        description="implicit midpoint rule: Euler-Poisson for the rigid body, Dirac vector field for general and analysed systems",
        reference="Hairer, Lubich & Wanner IV.2; Austin, Krishnaprasad & Wang (1993)",
        factories={
            "rigid_body": _rigid_body_factory,
            "constrained": _constrained_factory,
            "analysed": _analysed_factory,
        },
    ),
)
