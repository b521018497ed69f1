"""Lie–Poisson splitting methods for the free rigid body, wrapped as methods.

The mathematics (exact rotations of ``M`` and ``R`` for each ``H_k = M_k^2 / (2 I_k)``,
symmetric compositions with coefficient tables as data) lives in
:mod:`dirac.rigidbody.splitting`; this module binds it to :class:`RigidBodyProblem`:
one :class:`Method` per composition scheme (``lie-poisson-2/4/6/8`` and the extras).
On a heavy top the same methods compose the free step with gravity kicks
(:mod:`dirac.flows.methods.heavy_top`; the registry joins the two); with an external
torque or angular impulses, with torque kicks (:mod:`dirac.flows.methods.torqued`).

Only what is asked for is advanced: when no output needs ``R`` the kernel never touches
it (``with_R = False``).
"""

from __future__ import annotations

from typing import cast

from dirac.flows.methods.base import Method, Stepper
from dirac.flows.methods.rigid_body_stepper import RigidBodyStepper
from dirac.flows.methods.torqued import TorquedStepper
from dirac.rigidbody import schemes

__all__ = ["LiePoissonStepper", "METHODS", "BATCH_THRESHOLD"]

#: Batches of at least this many bodies use the batched kernel (3-term split only).
BATCH_THRESHOLD = 2


class LiePoissonStepper(RigidBodyStepper):
    """Composed Lie–Poisson splitting (McLachlan 1993; Reich 1994; Touma & Wisdom 1994)."""

    def __init__(self, method: Method, problem, outputs: tuple[str, ...]) -> None:
        super().__init__(problem, outputs)
        from dirac.rigidbody import splitting  # numba kernels: imported when a body runs

        scheme = cast(schemes.CompositionScheme, method.data)
        self._axes, self._rates, self._fractions, self._casimir_rate = schemes.build_sequence(
            self.inv_inertia, scheme.coefficients, scheme.splitting
        )
        self._kernel = splitting.advance_sequence
        self._stages = int(self._axes.shape[0] - 1)
        # many bodies with the 3-term split: all advanced together by the batched kernel
        # (dirac.rigidbody.batch: blocks over the cores, vectorised trigonometry)
        self._coefficients = tuple(scheme.coefficients)
        self._batched = scheme.splitting == "axes" and self.M.shape[0] >= BATCH_THRESHOLD

    def warm_up(self) -> None:
        M = self.M[0].copy()
        R = self.R[0].copy()
        self._kernel(M, R, self._axes, self._rates, self._fractions, self._casimir_rate, 1e-3, 1, self.with_R)
        if self._batched:
            from dirac.rigidbody.batch import advance_batch

            advance_batch(self.M[:2].copy(), self.R[:2].copy(), self.inv_inertia, 1e-3, 1, self._coefficients,
                          with_R=self.with_R)

    def step(self, n_steps: int, dt: float) -> None:
        if self._batched:
            from dirac.rigidbody.batch import advance_batch

            advance_batch(self.M, self.R, self.inv_inertia, dt, n_steps, self._coefficients, with_R=self.with_R)
        else:
            for b in range(self.M.shape[0]):
                M = self.M[b]
                R = self.R[b]
                self._kernel(M, R, self._axes, self._rates, self._fractions, self._casimir_rate, dt, n_steps,
                             self.with_R)
        self.steps += n_steps
        self.evaluations += n_steps * self._stages * self.M.shape[0]


def _factory(method: Method, problem, outputs, options) -> Stepper:
    if problem.driven:  # torques or impulses: kicks composed with the Strang step
        scheme = cast(schemes.CompositionScheme, method.data)
        return TorquedStepper(problem, outputs, tuple(scheme.coefficients), scheme.splitting, options)
    return LiePoissonStepper(method, problem, outputs)


def _method(scheme: schemes.CompositionScheme) -> Method:
    split = "3-term axes split" if scheme.splitting == "axes" else "symmetric-top split (Fasso 2003)"
    return Method(
        name=scheme.name,
        order=scheme.order,
        kind="fixed",
        symplectic=True,
        preserves_casimirs=True,
        description=f"rigid body (heavy top: + gravity kick): Lie-Poisson splitting, {split}, order {scheme.order}",
        reference=scheme.reference,
        factories={"rigid_body": _factory},
        data=scheme,
    )


#: One method per composition scheme and splitting, free rigid body only; the registry
#: adds the heavy top (:mod:`dirac.flows.methods.heavy_top`).
METHODS: tuple[Method, ...] = tuple(_method(scheme) for scheme in schemes.SCHEMES.values())
