"""The heavy top: the free rigid body plus gravity, by splitting.

``H = H_0(M) + V(R)``, ``V = m g <chi, gamma>``, ``gamma = R^T e_z`` (third row of ``R``).
With the bracket (248)–(249) the flow of ``V`` alone is a *kick*: ``R`` stays fixed and
``dM/dt = m g gamma x chi``, so ``M(t) = M(0) + t m g gamma x chi`` exactly. Composing the
kick with a flow of ``H_0`` gives Poisson integrators that keep ``|gamma|^2 = 1``,
``R^T R = 1`` and the vertical lab momentum ``<m, e_z>`` (Celledoni, Fassò, Säfström &
Zanna, SIAM J. Sci. Comput. 30 (2008); Touma & Wisdom 1994). The base step
``K(h/2) F(h) K(h/2)`` is symmetric, so a composition of :mod:`dirac.compositions` raises
its order. The kernels are in :mod:`dirac.rigidbody.heavy_top`.

Two families of ``F``:

``lie-poisson-*`` (numba, fast)
    ``F`` is the Strang step of the Lie–Poisson splitting of ``H_0`` (exact rotations
    about the body axes; for ``lie-poisson-sym-*`` the symmetric-top split, which is the
    *exact* free flow of a Lagrange top ``I_1 = I_2``).
With an external torque or angular impulses both families use the torque kicks of
:mod:`dirac.flows.methods.torqued` (gravity and torque in one kick); ``exact-kick-*`` also
integrates a torqued rigid body that way (on a free body the kicks are zero and the steps
are those of the exact flow).

``exact-kick-*`` (numba, one kernel)
    ``F`` is the exact free flow (Jacobi elliptic functions and an elliptic integral of
    the third kind), as in Celledoni et al. (2008): :func:`dirac.rigidbody.exact_step.free_flow_step`
    sets the flow up and evaluates it inside the compiled loop
    :func:`dirac.rigidbody.exact_step.exact_kick_advance`.

This module gives the ``lie-poisson-*`` methods their heavy-top factory
(:data:`LIE_POISSON_FACTORIES`, joined to them by :mod:`dirac.flows.methods.registry`);
:mod:`dirac.flows.methods.lie_poisson` does not know about the heavy top.
"""

from __future__ import annotations

from typing import cast

import numpy as np

from dirac.compositions import COMPOSITIONS, MAIN_SUFFIXES
from dirac.flows.methods.base import Method, Stepper, StepperFactory
from dirac.flows.methods.rigid_body_stepper import RigidBodyStepper
from dirac.flows.methods.torqued import TorquedStepper
from dirac.rigidbody.schemes import CompositionScheme, build_sequence

__all__ = ["HeavyTopSplittingStepper", "ExactKickStepper", "METHODS", "LIE_POISSON_FACTORIES"]


class HeavyTopSplittingStepper(RigidBodyStepper):
    """Kick + Lie–Poisson free step, composed (numba loop)."""

    def __init__(self, method: Method, problem, outputs: tuple[str, ...]) -> None:
        super().__init__(problem, outputs)
        from dirac.rigidbody.heavy_top import heavy_top_advance  # numba: imported when a top runs

        self._kernel = heavy_top_advance
        scheme = cast(CompositionScheme, method.data)
        self.gammas = np.asarray(scheme.coefficients, dtype=float)
        self.sequence = build_sequence(self.inv_inertia, (1.0,), scheme.splitting)
        self.w = np.asarray(problem.weight_vector, dtype=float)
        self._stages = len(self.gammas) * (len(self.sequence[0]) + 1)

    def warm_up(self) -> None:
        self._kernel(self.M[0].copy(), self.R[0].copy(), self.w, self.gammas, *self.sequence, 1e-3, 1)

    def step(self, n_steps: int, dt: float) -> None:
        for b in range(self.M.shape[0]):
            self._kernel(self.M[b], self.R[b], self.w, self.gammas, *self.sequence, dt, n_steps)
        self.steps += n_steps
        self.evaluations += n_steps * self._stages * self.M.shape[0]


class ExactKickStepper(RigidBodyStepper):
    """Kick + exact free flow (Celledoni et al. 2008), composed; one compiled loop."""

    def __init__(self, method: Method, problem, outputs: tuple[str, ...]) -> None:
        super().__init__(problem, outputs)
        self.gammas = np.asarray(cast(tuple[float, ...], method.data), dtype=float)
        self.w = np.asarray(problem.weight_vector, dtype=float)
        from dirac.rigidbody.exact_step import FreeFlowWork, exact_kick_advance  # numba: when a top runs

        self._kernel = exact_kick_advance
        self.work = FreeFlowWork()

    def warm_up(self) -> None:
        self._kernel(self.M[0].copy(), self.R[0].copy(), self.inv_inertia, self.w, self.gammas, 1e-3, 1,
                           *self.work.arrays())

    def step(self, n_steps: int, dt: float) -> None:
        for b in range(self.M.shape[0]):
            self._kernel(self.M[b], self.R[b], self.inv_inertia, self.w, self.gammas, dt, n_steps,
                               *self.work.arrays())
        self.steps += n_steps
        self.evaluations += n_steps * 3 * len(self.gammas) * self.M.shape[0]


def _splitting_factory(method: Method, problem, outputs, options) -> Stepper:
    """Stepper of a ``lie-poisson-*`` method on a :class:`HeavyTopProblem`."""
    if problem.driven:  # external torque or impulses: gravity and torque in one kick
        scheme = cast(CompositionScheme, method.data)
        return TorquedStepper(problem, outputs, tuple(scheme.coefficients), scheme.splitting, options)
    return HeavyTopSplittingStepper(method, problem, outputs)


def _exact_kick_factory(method: Method, problem, outputs, options) -> Stepper:
    if problem.driven or problem.kind == "rigid_body":  # torque kicks (zero for a free body; gravity for a top)
        return TorquedStepper(problem, outputs, cast(tuple[float, ...], method.data), "exact", options)
    return ExactKickStepper(method, problem, outputs)


#: What the ``lie-poisson-*`` methods do on a heavy top: kick + their free step, composed.
LIE_POISSON_FACTORIES: dict[str, StepperFactory] = {"heavy_top": _splitting_factory}

#: ``exact-kick-2/4/6/8``: kick + exact free flow, composed.
METHODS: tuple[Method, ...] = tuple(
    Method(
        name=f"exact-kick-{composition.suffix}",
        order=composition.order,
        kind="fixed",
        symplectic=True,
        preserves_casimirs=True,
        description=f"heavy top, torqued body: exact free flow + gravity/torque kick (Celledoni et al. 2008), "
        f"order {composition.order}",
        reference=f"Celledoni, Fasso, Safstrom & Zanna, SIAM J. Sci. Comput. 30 (2008); {composition.reference}",
        factories={"heavy_top": _exact_kick_factory, "rigid_body": _exact_kick_factory},
        data=composition.coefficients,
    )
    for composition in COMPOSITIONS
    if composition.suffix in MAIN_SUFFIXES
)
