"""The ordinary method names on forced systems: ``rattle-2/4``, ``midpoint`` and the scipy methods.

A system with generalized forces ``Q(q, q_dot, t)`` (and impulses) is a
:class:`~dirac.flows.problems.ForcedProblem`; ``ConstrainedProblem`` gives one when the
system has forces. The names a user already knows integrate it:

* ``rattle-2`` and ``rattle-4`` run as ``forced-rattle-2`` and ``forced-rattle-4``
  (:mod:`dirac.flows.methods.forced`: RATTLE with the discrete Lagrange–d'Alembert forces
  of Marsden & West, Acta Numerica 10 (2001), Sect. 3.2), orders 2 and 4;
* ``midpoint`` is the implicit midpoint rule on the forced Dirac vector field (the
  generated ``force`` of a forced system is ``dH/dq - Q``, so ``p_dot`` carries the
  forces and the constraint forces keep the motion on the surface), order 2 (Hairer,
  Lubich & Wanner IV.2 for the rule; the forces make it neither symplectic nor
  symmetric in energy). The work of the forces over a step is the midpoint rule's own
  quadrature ``Q(z_mid, (q1 - q0)/h, t + h/2) . (q1 - q0)``, since
  ``q1 - q0 = h q_dot(z_mid)``; when ``work`` is an output the steps are taken one per
  kernel call for it;
* ``scipy-RK45`` and ``scipy-DOP853`` integrate the forced Dirac field with the work
  ``W`` as one more component, ``dW/dt = Q(q, q_dot, t) . q_dot``; impulses stop the
  solvers, jump ``p`` and restart them.

Impulses are applied between steps as by the forced methods (a step is cut so that one
ends on each impulse time).
"""

from __future__ import annotations

import numpy as np

from dirac.flows.dirac_field import constrained_outputs
from dirac.flows.methods.base import Method, Stepper
from dirac.flows.methods.constrained_stepper import singular_as_step_failure
from dirac.flows.methods.forced import METHODS as FORCED_METHODS
from dirac.flows.methods.forced import ForcedStepper, ImpulsesBetweenSteps
from dirac.flows.methods.midpoint import ConstrainedMidpointStepper
from dirac.flows.methods.scipy_rk import ScipyStepper

__all__ = ["ForcedMidpointStepper", "ForcedScipyStepper", "FORCED_VERSIONS", "forced_factories"]

#: an ordinary name -> the forced method it runs as
FORCED_VERSIONS: dict[str, str] = {"rattle-2": "forced-rattle-2", "rattle-4": "forced-rattle-4"}


class ForcedMidpointStepper(ImpulsesBetweenSteps, ConstrainedMidpointStepper):
    """The implicit midpoint rule on the forced Dirac field, with impulses and the work of the forces."""

    def __init__(self, problem, outputs: tuple[str, ...], options: dict) -> None:
        super().__init__(problem, outputs, options)
        self.work = np.zeros(self.z.shape[0])
        self.pending = list(problem.impulses)
        self._with_work = "work" in outputs

    def _advance(self, n_steps: int, dt: float, warm_up: bool = False) -> None:
        """``n_steps`` midpoint steps for every state (no impulse inside), the work summed."""
        if n_steps <= 0 or dt <= 0.0:
            return
        n = self.mechanics.dimension
        for b in range(self.z.shape[0]):
            per_call = 1 if self._with_work else n_steps
            time = self.time
            for _ in range(n_steps // per_call):
                before = self.z[b].copy() if self._with_work else None
                with singular_as_step_failure("midpoint"):
                    self._kernel_call(self._kernel, per_call, self.z[b], time, self.mechanics.params, dt, per_call,
                                      self.tol, self.max_iter, self.info, warm_up=warm_up)
                self.evaluations += int(self.info[2])
                self._raise_if_failed("midpoint")
                if before is not None:
                    moved = self.z[b, :n] - before[:n]
                    middle = 0.5 * (self.z[b, :n] + before[:n])
                    force = self.mechanics.applied_force(middle, moved / dt, time + 0.5 * dt)
                    self.work[b] += float(force @ moved)
                time += per_call * dt
        self.steps += n_steps
        self.time += n_steps * dt

    def warm_up(self) -> None:
        saved = (self.z.copy(), self.work.copy(), self.time, self.steps, self.evaluations)
        self._advance(1, 1e-6, warm_up=True)
        self.z[:], self.work[:] = saved[0], saved[1]
        self.time, self.steps, self.evaluations = saved[2], saved[3], saved[4]

    def observe(self) -> dict[str, np.ndarray]:
        names = tuple(name for name in self.outputs if name != "work")
        result = constrained_outputs(self.mechanics, names, self.q, self.p, self.time)
        if "work" in self.outputs:
            result["work"] = self.work.copy()
        return result


class ForcedScipyStepper(ScipyStepper):
    """scipy's RK45 or DOP853 on the forced Dirac field, the work ``W`` as the last component."""

    def __init__(self, method: Method, problem, outputs: tuple[str, ...], options: dict) -> None:
        super().__init__(method, problem, outputs, options)  # the constrained branch: the forced field
        mechanics = problem.mechanics
        n = mechanics.dimension
        field = self.field

        def forced(t: float, y: np.ndarray) -> np.ndarray:
            rates = np.empty_like(y)
            rates[:-1] = field(y[:-1], t)
            q_dot = rates[:n]
            rates[-1] = float(mechanics.applied_force(y[:n], q_dot, t) @ q_dot)
            return rates

        self._fun, self._args = forced, ()
        self.y = np.concatenate([self.y, np.zeros((self.y.shape[0], 1))], axis=1)
        self.pending = list(problem.impulses)

    def advance_to(self, t: float) -> None:
        n = self.problem.mechanics.dimension
        while self.pending and self.pending[0].t <= t:
            impulse = self.pending.pop(0)
            if impulse.t > self.t:
                self._advance_solvers(impulse.t)
            for y in self.y:
                y[n:2 * n], work = self.problem.mechanics.apply_impulse(y[:n], y[n:2 * n], impulse.vector, impulse.t)
                y[-1] += work
            self._solvers = self._make_solvers() if impulse.t < self.t_end else None
        if t > self.t:
            self._advance_solvers(t)

    def observe(self) -> dict[str, np.ndarray]:
        n = self.problem.mechanics.dimension
        names = tuple(name for name in self.outputs if name != "work")
        result = self.field.outputs(names, self.y[:, :n], self.y[:, n:2 * n], self.t)
        if "work" in self.outputs:
            result["work"] = self.y[:, -1].copy()
        return result

    def drift(self) -> float:
        n = self.problem.mechanics.dimension
        return max(self.problem.mechanics.constraint_residual(y[:n], y[n:2 * n], self.t) for y in self.y)


def _rattle_factory(method: Method, problem, outputs, options) -> Stepper:
    forced = next(m for m in FORCED_METHODS if m.name == FORCED_VERSIONS[method.name])
    return ForcedStepper(forced, problem, outputs, options)


def _midpoint_factory(method: Method, problem, outputs, options) -> Stepper:
    return ForcedMidpointStepper(problem, outputs, options)


def _scipy_factory(method: Method, problem, outputs, options) -> Stepper:
    return ForcedScipyStepper(method, problem, outputs, options)


def forced_factories(name: str) -> dict:
    """``{"forced": factory}`` for an ordinary method name that takes forces, else ``{}``."""
    if name in FORCED_VERSIONS:
        return {"forced": _rattle_factory}
    if name == "midpoint":
        return {"forced": _midpoint_factory}
    if name.startswith("scipy-"):
        return {"forced": _scipy_factory}
    return {}
