"""Rigid bodies and heavy tops driven by external torques and angular impulses.

The step is ``K(h/2) F(h) K(h/2)`` composed with the fractions of a symmetric composition
(:mod:`dirac.flows.torque_kernels` has the kick ``K``, the free step ``F`` and why the
orders hold): ``F`` the exact free flow for ``exact-kick-*`` (Celledoni, Fassò, Säfström &
Zanna, SIAM J. Sci. Comput. 30 (2008)), the Lie–Poisson Strang step of the method's
splitting for ``lie-poisson-*``. The kick of a torque free of ``M`` and ``Omega`` is exact;
otherwise it is an implicit midpoint kick solved by Newton's method (tolerance and
iterations of :func:`dirac.flows.integrate`).

Angular impulses: the steps land on the impulse time (a step that straddles it is cut in
two), ``M`` jumps by the impulse and the work by the jump of the kinetic energy. The state
at an impulse time is the state after the jump (an impulse at ``t = 0`` acts on the initial
state).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from dirac.errors import InputError
from dirac.flows.methods.base import StepFailure
from dirac.flows.methods.rigid_body_stepper import RigidBodyStepper, rigid_body_outputs
from dirac.rigidbody.schemes import build_sequence

if TYPE_CHECKING:
    from dirac.flows.torques import Torque

__all__ = ["TorquedStepper", "DRIVEN_METHOD_PREFIXES", "refuse_undriven"]

#: Methods whose names start so integrate torques and impulses (besides the scipy baselines).
DRIVEN_METHOD_PREFIXES = ("lie-poisson-", "exact-kick-", "scipy-")

_ZERO = ("0", "0", "0")


def refuse_undriven(problem, method_name: str, capable: list[str]) -> None:
    """Refuse a method that does not integrate torques or impulses on a driven problem.

    Raises
    ------
    InputError
        Naming the method, what it cannot do, and the methods that can (``capable``).
    """
    if getattr(problem, "driven", False) and method_name not in capable:
        what = "an external torque" if problem.torque is not None else "angular impulses"
        raise InputError(
            f"method {method_name!r} cannot integrate {what}; use one of: {', '.join(capable)}"
        )


class TorquedStepper(RigidBodyStepper):
    """Torque kicks composed with a free step (module docstring), with angular impulses.

    Parameters
    ----------
    problem : RigidBodyProblem or HeavyTopProblem
    outputs : tuple of str
    gammas : tuple of float
        Composition fractions of the symmetric base step.
    free : {"exact", "axes", "symmetric"}
        The free step: the exact flow, or the Strang step of that Lie–Poisson splitting.
    options : dict
        ``newton_tolerance`` and ``max_newton_iterations`` of the midpoint kick.
    """

    def __init__(self, problem, outputs: tuple[str, ...], gammas: tuple[float, ...], free: str,
                 options: dict) -> None:
        super().__init__(problem, outputs)
        from dirac.flows.torques import Torque  # the parser and code generator: only for driven bodies

        self.torque: Torque = problem.torque if problem.torque is not None else Torque(_ZERO)
        self.with_R = self.with_R or self.torque.depends_on_attitude or free == "exact"
        self.kernels = self.torque.kernels
        self.gammas = np.asarray(gammas, dtype=float)
        self.free = free
        self.w = (np.asarray(problem.weight_vector, dtype=float) if problem.kind == "heavy_top" else np.zeros(3))
        self.newton_tolerance = float(options.get("newton_tolerance", 1e-12))
        self.max_iterations = int(options.get("max_newton_iterations", 50))
        self.work = np.zeros(self.M.shape[0])
        self.t = 0.0
        self.impulses = tuple(problem.impulses)
        self._next = 0
        if free == "exact":
            from dirac.rigidbody.exact_step import FreeFlowWork  # numba: imported when a body runs

            self._scratch = FreeFlowWork()
        else:
            self._sequence = build_sequence(self.inv_inertia, (1.0,), free)
        # per stage: two kicks and a free step (3 rotations for the axes split, 1 exact step)
        self._per_step = len(self.gammas) * (2 + (1 if free == "exact" else len(self._sequence[0])))
        self._apply_impulses_at(0.0)

    # ------------------------------------------------------------------ kernels
    def _advance(self, n_steps: int, dt: float, t0: float) -> int:
        """``n_steps`` steps of size ``dt`` from time ``t0`` for every body; the fewest
        steps any body completed."""
        done = n_steps
        k = self.kernels
        cell = np.zeros(1)
        for b in range(self.M.shape[0]):
            cell[0] = self.work[b]
            if self.free == "exact":
                completed = k.exact_advance(self.M[b], self.R[b], self.inv_inertia, self.w, self.gammas, t0, dt,
                                            n_steps, cell, *self._scratch.arrays(), self.newton_tolerance,
                                            self.max_iterations)
            else:
                completed = k.split_advance(self.M[b], self.R[b], self.inv_inertia, self.w, self.gammas,
                                            *self._sequence, self.with_R, t0, dt, n_steps, cell,
                                            self.newton_tolerance, self.max_iterations)
            self.work[b] = cell[0]
            done = min(done, int(completed))
        self.evaluations += n_steps * self._per_step * self.M.shape[0]
        return done

    def _advance_or_fail(self, n_steps: int, dt: float, t0: float, steps_before: int) -> None:
        done = self._advance(n_steps, dt, t0)
        if done < n_steps:
            raise StepFailure(
                f"the implicit midpoint kick of the torque did not converge in {self.max_iterations} Newton "
                "iterations (reduce dt, or raise max_newton_iterations)",
                steps_done=steps_before + done,
            )

    def _apply_impulses_at(self, t: float) -> None:
        """Apply every impulse not yet applied whose time is ``t`` (within round-off)."""
        while self._next < len(self.impulses) and self.impulses[self._next].t <= t + 1e-12 * max(1.0, abs(t)):
            jump = self.impulses[self._next].vector
            before = 0.5 * np.sum(self.M * self.M * self.inv_inertia, axis=-1)
            self.M += jump
            self.work += 0.5 * np.sum(self.M * self.M * self.inv_inertia, axis=-1) - before
            self._next += 1

    # ------------------------------------------------------------------ the Stepper interface
    def warm_up(self) -> None:
        k = self.kernels
        M = self.M[0].copy()
        R = self.R[0].copy()
        cell = np.zeros(1)
        if self.free == "exact":
            k.exact_advance(M, R, self.inv_inertia, self.w, self.gammas, 0.0, 1e-3, 1, cell,
                            *type(self._scratch)().arrays(), self.newton_tolerance, self.max_iterations)
        else:
            k.split_advance(M, R, self.inv_inertia, self.w, self.gammas, *self._sequence, self.with_R, 0.0, 1e-3,
                            1, cell, self.newton_tolerance, self.max_iterations)

    def step(self, n_steps: int, dt: float) -> None:
        """``n_steps`` steps of the grid ``t0 + k dt``; a step with impulses inside is cut at
        each of them (pieces from the grid point to the first, between them, and from the last
        to the next grid point); impulses on a grid point (within ``1e-9 dt``) act between
        two steps."""
        t0 = self.t
        target = t0 + n_steps * dt
        done = 0
        slack = 1e-9 * dt
        while self._next < len(self.impulses) and self.impulses[self._next].t <= target + slack:
            t_impulse = self.impulses[self._next].t
            before = min(n_steps, int(math.floor((t_impulse - t0 + slack) / dt)))
            if before > done:
                self._advance_or_fail(before - done, dt, t0 + done * dt, done)
                done = before
            t_here = t0 + done * dt
            rest = t_impulse - t_here
            if rest > slack and done < n_steps:  # the impulse falls inside the next step: cut it there
                step_end = t0 + (done + 1) * dt
                self._advance_or_fail(1, rest, t_here, done)
                self._apply_impulses_at(t_impulse)
                covered, at = rest, t_impulse
                # later impulses inside the same step: cut at each (the body is at the last one's time)
                while self._next < len(self.impulses) and self.impulses[self._next].t < step_end - slack:
                    following = self.impulses[self._next].t
                    self._advance_or_fail(1, following - at, at, done)
                    self._apply_impulses_at(following)
                    covered += following - at
                    at = following
                self._advance_or_fail(1, dt - covered, at, done)
                done += 1
            else:
                self._apply_impulses_at(t_impulse)
        if done < n_steps:
            self._advance_or_fail(n_steps - done, dt, t0 + done * dt, done)
        self.t = target
        self.steps += n_steps

    def observe(self) -> dict[str, np.ndarray]:
        return rigid_body_outputs(self.outputs, self.M, self.R, self.inertia, self.weight, self.work)

