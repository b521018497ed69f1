"""RATTLE for holonomically constrained systems, and its symmetric compositions.

RATTLE (Andersen 1983; Leimkuhler & Skeel 1994; Hairer, Lubich & Wanner, Geometric
Numerical Integration, Sect. VII.1.4) is symplectic on the constraint manifold, symmetric
and of order 2; the positions satisfy ``chi(q) = 0`` to the Newton tolerance and the
momenta the hidden constraint ``G(q) M^{-1} p = 0`` exactly (a linear solve). Because it is
symmetric, the compositions of :data:`dirac.compositions.COMPOSITIONS` (Yoshida,
Kahan–Li) raise its order to 4, 6, 8 (``rattle-4`` ...), with the coefficients as data.

With a constant mass matrix (Cartesian coordinates) the Newton iteration runs on the
``m`` multipliers only; otherwise on ``(p_half, q1, lambda)`` (Jay 1996). Both step loops
are generated per system with every expression inlined
(:mod:`dirac.codegen.kernel_source`) and compiled once per machine. Time-dependent
constraints and potentials are evaluated at the times of the sub-steps. A step whose
Newton iteration does not converge within ``max_newton_iterations`` stops the run with
the state of the last completed step.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import cast

import numpy as np

from dirac.compositions import COMPOSITIONS, MAIN_SUFFIXES
from dirac.flows.methods.base import Method, Stepper
from dirac.flows.methods.constrained_stepper import ConstrainedStepper, singular_as_step_failure, tiered

__all__ = ["RattleStepper", "METHODS"]


class RattleStepper(ConstrainedStepper):
    """RATTLE composed with the coefficients of ``method.data`` (fractions of a step)."""

    def __init__(self, method: Method, problem, outputs: tuple[str, ...], options: dict) -> None:
        super().__init__(problem, outputs, options)
        self.name = method.name
        self.fractions = np.asarray(cast(tuple[float, ...], method.data), dtype=float)
        self._kernel: Callable[..., None]
        self.constant = self.mechanics.constant_mass is not None
        if self.constant:
            self.mechanics.mass_matrix(self.q[0])  # checks positivity
            self._kernel = tiered(self.mechanics.module, "rattle_constant_mass")
        else:
            for q in self.q:
                self.mechanics.mass_matrix(q)
            self._kernel = tiered(self.mechanics.module, "rattle_general")

    def _call(self, q: np.ndarray, p: np.ndarray, n_steps: int, dt: float, warm_up: bool = False) -> None:
        self._kernel_call(self._kernel, n_steps, q, p, self.time, self.mechanics.params, self.fractions, dt, n_steps,
                          self.tol, self.max_iter, self.info, warm_up=warm_up)

    def warm_up(self) -> None:
        self._call(self.q[0].copy(), self.p[0].copy(), 1, 1e-6, warm_up=True)

    def step(self, n_steps: int, dt: float) -> None:
        for b in range(self.q.shape[0]):
            with singular_as_step_failure(self.name):
                self._call(self.q[b], self.p[b], n_steps, dt)
            self.evaluations += int(self.info[2])
            self._raise_if_failed(self.name)
        self.steps += n_steps
        self.time += n_steps * dt


def _factory(method: Method, problem, outputs, options) -> Stepper:
    return RattleStepper(method, problem, outputs, options)


#: ``rattle-2`` and its compositions ``rattle-4/6/8``.
METHODS: tuple[Method, ...] = tuple(
    Method(
        name=f"rattle-{composition.suffix}",
        order=composition.order,
        kind="fixed",
        symplectic=True,
        preserves_casimirs=False,
        description=f"constrained systems: RATTLE{'' if composition.order == 2 else ', composed: ' + composition.reference}, "
        f"order {composition.order}",
        reference="Andersen (1983); Hairer, Lubich & Wanner VII.1.4"
        + ("" if composition.order == 2 else f"; {composition.reference}"),
        factories={"constrained": _factory},
        data=composition.coefficients,
    )
    for composition in COMPOSITIONS
    if composition.suffix in MAIN_SUFFIXES
)
