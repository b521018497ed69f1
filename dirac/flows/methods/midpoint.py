"""``midpoint``: the implicit midpoint rule ``z1 = z0 + h F((z0 + z1)/2)``.

Symmetric, order 2, and it keeps every quadratic first integral of ``F`` exactly
(Cooper 1987; Hairer, Lubich & Wanner IV.2). That makes it a Poisson integrator for the
rigid body (Lie–Poisson structure, Austin, Krishnaprasad & Wang 1993): ``|M|^2``, ``H_0``,
``m = R M`` and ``R^T R = 1`` are all quadratic and all kept.

* Free rigid body, Euler–Poisson (250)–(251): ``M`` first, by Newton on 3 unknowns with
  the exact Jacobian; then ``R1 = R0 cay(h Omega_mid)`` with the Cayley transform
  ``cay(A) = (1 + A/2)(1 - A/2)^{-1}`` of ``hat(Omega_mid)`` (the midpoint rule for
  ``dR/dt = R hat(Omega_mid)``, orthogonal by construction).
* General systems: the Dirac vector field of :mod:`dirac.flows.dirac_field` with
  simplified Newton iterations (numba kernel ``midpoint_run``). Quadratic holonomic
  constraints (pendulums) and their quadratic time derivatives are kept to the Newton
  tolerance.
* Analysed systems (any Lagrangian the Dirac–Bergmann engine analyses): the Dirac vector
  field on the full phase space, :mod:`dirac.flows.analysed`. Its later-stage
  constraints (e.g. the fourth stage, cubic in the pendulum) are not quadratic, so each
  step ends with an orthogonal projection onto the constraint surface (Hairer, Lubich &
  Wanner IV.4); this projected midpoint is no longer exactly symmetric, still order 2.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from dirac.flows.constrained_kernels import report
from dirac.flows.methods.lie_poisson import RigidBodyStepper
from dirac.flows.methods.base import Method, Stepper, StepFailure, register_method
from dirac.flows.methods.rattle import ConstrainedStepper, newton_options, singular_as_step_failure

__all__ = ["midpoint_rigid_body"]


@njit(cache=True)
def _solve3(J, r):  # noqa: ANN001, ANN202
    """Solve the 3 x 3 system J d = r by Cramer's rule."""
    c00 = J[1, 1] * J[2, 2] - J[1, 2] * J[2, 1]
    c01 = J[1, 2] * J[2, 0] - J[1, 0] * J[2, 2]
    c02 = J[1, 0] * J[2, 1] - J[1, 1] * J[2, 0]
    det = J[0, 0] * c00 + J[0, 1] * c01 + J[0, 2] * c02
    d0 = (r[0] * c00 + J[0, 1] * (r[2] * J[1, 2] - r[1] * J[2, 2]) + J[0, 2] * (r[1] * J[2, 1] - r[2] * J[1, 1])) / det
    d1 = (J[0, 0] * (r[1] * J[2, 2] - r[2] * J[1, 2]) + r[0] * c01 + J[0, 2] * (r[2] * J[1, 0] - r[1] * J[2, 0])) / det
    d2 = (J[0, 0] * (J[1, 1] * r[2] - J[2, 1] * r[1]) + J[0, 1] * (J[2, 0] * r[1] - J[1, 0] * r[2]) + r[0] * c02) / det
    return d0, d1, d2


@njit(cache=True)
def midpoint_rigid_body(M, R, inv_inertia, dt, n_steps, with_R, tol, max_iter, info):  # noqa: ANN001, N803, PLR0913
    """Advance ``(M, R)`` in place by ``n_steps`` implicit-midpoint steps (Euler–Poisson).

    Newton on ``Mm = M0 + h/2 Mm x (I^{-1} Mm)``, Jacobian
    ``1 - h/2 (hat(Mm) I^{-1} - hat(Omega_m))``; then ``M1 = 2 Mm - M0`` and
    ``R1 = R0 (1 + h/2 hat(Omega_m)) (1 - h/2 hat(Omega_m))^{-1}``.
    ``info = [steps_done, failed, evaluations, last_increment]``.
    """
    a0 = inv_inertia[0]
    a1 = inv_inertia[1]
    a2 = inv_inertia[2]
    evals = 0.0
    size = 0.0
    J = np.empty((3, 3))
    r = np.empty(3)
    B = np.zeros((3, 3))  # hat(b): only the off-diagonal entries are set, per step
    C = np.empty((3, 3))
    for step in range(n_steps):
        x0 = M[0]
        x1 = M[1]
        x2 = M[2]
        m0 = x0
        m1 = x1
        m2 = x2
        hh = 0.5 * dt
        converged = False
        for it in range(max_iter):
            w0 = a0 * m0
            w1 = a1 * m1
            w2 = a2 * m2
            r[0] = m0 - x0 - hh * (m1 * w2 - m2 * w1)
            r[1] = m1 - x1 - hh * (m2 * w0 - m0 * w2)
            r[2] = m2 - x2 - hh * (m0 * w1 - m1 * w0)
            evals += 1.0
            # d(M x (A M))/dM = hat(M) A - hat(A M)
            J[0, 0] = 1.0 - hh * (0.0)
            J[0, 1] = -hh * (-m2 * a1 + w2)
            J[0, 2] = -hh * (m1 * a2 - w1)
            J[1, 0] = -hh * (m2 * a0 - w2)
            J[1, 1] = 1.0
            J[1, 2] = -hh * (-m0 * a2 + w0)
            J[2, 0] = -hh * (-m1 * a0 + w1)
            J[2, 1] = -hh * (m0 * a1 - w0)
            J[2, 2] = 1.0
            d0, d1, d2 = _solve3(J, r)
            m0 -= d0
            m1 -= d1
            m2 -= d2
            size = max(abs(d0), abs(d1), abs(d2))
            scale = max(1e-300, math.sqrt(m0 * m0 + m1 * m1 + m2 * m2))
            if size <= tol * scale:
                converged = True
                break
            if size != size:
                break
        if not converged:
            report(info, step, True, evals, size)
            return
        M[0] = 2.0 * m0 - x0
        M[1] = 2.0 * m1 - x1
        M[2] = 2.0 * m2 - x2
        if with_R:
            # C = (1 + B)(1 - B)^{-1}, B = hh hat(w)
            b0 = hh * a0 * m0
            b1 = hh * a1 * m1
            b2 = hh * a2 * m2
            # (1 - B)^{-1} = (1 + B + b b^T) / (1 + |b|^2)   for skew B = hat(b)
            nb = 1.0 + b0 * b0 + b1 * b1 + b2 * b2
            # Cayley: cay = 1 + 2 (B + B^2) / (1 + |b|^2)
            B[0, 1] = -b2
            B[0, 2] = b1
            B[1, 0] = b2
            B[1, 2] = -b0
            B[2, 0] = -b1
            B[2, 1] = b0
            for i in range(3):
                for j in range(3):
                    acc = 0.0
                    for k in range(3):
                        acc += B[i, k] * B[k, j]
                    C[i, j] = (1.0 if i == j else 0.0) + 2.0 * (B[i, j] + acc) / nb
            for i in range(3):
                r0 = R[i, 0]
                r1 = R[i, 1]
                r2 = R[i, 2]
                for j in range(3):
                    R[i, j] = r0 * C[0, j] + r1 * C[1, j] + r2 * C[2, j]
    report(info, n_steps, False, evals, size)


def _raise_if_failed(info: np.ndarray, max_iter: int) -> None:
    """The :class:`StepFailure` of a midpoint kernel whose ``info`` reports a failed step."""
    if info[1] != 0.0:
        raise StepFailure(f"midpoint: Newton iteration did not converge in {max_iter} iterations "
                          f"(increment {info[3]:.3g}); reduce dt", steps_done=int(info[0]))


class RigidBodyMidpointStepper(RigidBodyStepper):
    """Implicit midpoint on the Euler–Poisson equations."""

    def __init__(self, problem, outputs: tuple[str, ...], options: dict) -> None:  # noqa: ANN001
        super().__init__(problem, outputs)
        self.tol, self.max_iter, self.info = newton_options(options)

    def warm_up(self) -> None:
        midpoint_rigid_body(self.M[0].copy(), self.R[0].copy(), self.inv_inertia, 1e-3, 1, self.with_R,
                            self.tol, self.max_iter, self.info)

    def step(self, n_steps: int, dt: float) -> None:
        for b in range(self.M.shape[0]):
            midpoint_rigid_body(self.M[b], self.R[b], self.inv_inertia, dt, n_steps, self.with_R,
                                self.tol, self.max_iter, self.info)
            self.evaluations += int(self.info[2])
            _raise_if_failed(self.info, self.max_iter)
        self.steps += n_steps


class ConstrainedMidpointStepper(ConstrainedStepper):
    """Implicit midpoint on the Dirac vector field of a general system."""

    def __init__(self, problem, outputs: tuple[str, ...], options: dict) -> None:  # noqa: ANN001
        super().__init__(problem, outputs, options)
        for q in self.q:
            self.mechanics.mass_matrix(q)
        self.z = np.ascontiguousarray(np.concatenate([self.q, self.p], axis=1))
        # q and p are views of z, so the kernel's updates of z show in them
        n = self.mechanics.dimension
        self.q = self.z[:, :n]
        self.p = self.z[:, n:]
        from dirac.flows import constrained_kernels

        self._kernel = constrained_kernels.midpoint_run

    def warm_up(self) -> None:
        from dirac.flows.constrained_kernels import quiet

        n, m = self.mechanics.dimension, self.mechanics.n_constraints
        with quiet():
            self._kernel(0, self.mechanics.functions, self.z[0].copy(), self.mechanics.params, n, m, 1e-6, 1, self.tol, self.max_iter, self.info)

    def step(self, n_steps: int, dt: float) -> None:
        from dirac.flows.constrained_kernels import quiet

        n, m = self.mechanics.dimension, self.mechanics.n_constraints
        for b in range(self.z.shape[0]):
            with quiet(), singular_as_step_failure("midpoint"):
                self._kernel(0, self.mechanics.functions, self.z[b], self.mechanics.params, n, m, dt, n_steps, self.tol, self.max_iter, self.info)
            self.evaluations += int(self.info[2])
            self._raise_if_failed("midpoint")
        self.steps += n_steps


class AnalysedMidpointStepper(Stepper):
    """Implicit midpoint on the Dirac vector field of an analysed system (full phase space)."""

    def __init__(self, problem, outputs: tuple[str, ...], options: dict) -> None:  # noqa: ANN001
        super().__init__()
        from dirac.flows import constrained_kernels

        self.problem = problem
        self.analysed = problem.analysed
        self.outputs = outputs
        self.z = np.ascontiguousarray(problem.z0, dtype=float).copy()
        self.tol, self.max_iter, self.info = newton_options(options)
        self._kernel = constrained_kernels.midpoint_run

    def _run(self, z: np.ndarray, n_steps: int, dt: float) -> None:
        from dirac.flows.constrained_kernels import quiet

        with quiet():
            self._kernel(1, self.analysed.functions, z, self.analysed.params, self.analysed.dimension // 2,
                         self.analysed.n_constraints, dt, n_steps, self.tol, self.max_iter, self.info)

    def warm_up(self) -> None:
        self._run(self.z[0].copy(), 1, 1e-6)

    def step(self, n_steps: int, dt: float) -> None:
        for b in range(self.z.shape[0]):
            self._run(self.z[b], n_steps, dt)
            self.evaluations += int(self.info[2])
            _raise_if_failed(self.info, self.max_iter)
        self.steps += n_steps

    def observe(self) -> dict[str, np.ndarray]:
        from dirac.flows.analysed import analysed_outputs

        return analysed_outputs(self.analysed, self.outputs, self.z)

    def finite(self) -> bool:
        return bool(np.all(np.isfinite(self.z)))

    def drift(self) -> float:
        return max(self.analysed.constraint_residual(z) for z in self.z)


def _factory(method: Method, problem, outputs, options) -> Stepper:  # noqa: ANN001
    if getattr(problem, "system", "") == "rigid_body":
        return RigidBodyMidpointStepper(problem, outputs, options)
    if hasattr(problem, "analysed"):
        return AnalysedMidpointStepper(problem, outputs, options)
    return ConstrainedMidpointStepper(problem, outputs, options)


register_method(
    Method(
        name="midpoint",
        order=2,
        kind="fixed",
        problems=("rigid_body", "constrained", "analysed"),
        symplectic=True,
        preserves_casimirs=True,
        description="implicit midpoint rule: Euler-Poisson for the rigid body, Dirac vector field for general and analysed systems",
        reference="Hairer, Lubich & Wanner IV.2; Austin, Krishnaprasad & Wang (1993)",
        factory=_factory,
    )
)
