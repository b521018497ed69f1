"""The heavy top: the free rigid body plus gravity, by splitting.

``H = H_0(M) + V(R)``, ``V = m g <chi, gamma>``, ``gamma = R^T e_z`` (third row of ``R``).
With the bracket (248)–(249) the flow of ``V`` alone is a *kick*: ``R`` stays fixed and
``dM/dt = m g gamma x chi``, so ``M(t) = M(0) + t m g gamma x chi`` exactly. Composing the
kick with a flow of ``H_0`` gives Poisson integrators that keep ``|gamma|^2 = 1``,
``R^T R = 1`` and the vertical lab momentum ``<m, e_z>`` (Celledoni, Fassò, Säfström &
Zanna, SIAM J. Sci. Comput. 30 (2008); Touma & Wisdom 1994). The base step
``K(h/2) F(h) K(h/2)`` is symmetric, so the composition table of
:mod:`dirac.rigidbody.splitting` raises its order.

Two families of ``F``:

``lie-poisson-*`` (numba, fast)
    ``F`` is the Strang step of the Lie–Poisson splitting of ``H_0`` (exact rotations
    about the body axes; for ``lie-poisson-sym-*`` the symmetric-top split, which is the
    *exact* free flow of a Lagrange top ``I_1 = I_2``).
``exact-kick-*``
    ``F`` is the exact free flow (:class:`dirac.rigidbody.exact.ExactRigidBodyFlow`,
    elliptic functions), as in Celledoni et al. (2008); one Python call per stage.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from dirac.flows.methods.lie_poisson import RigidBodyStepper, exact_flow
from dirac.flows.methods.base import Method, Stepper, register_method
from dirac.rigidbody.splitting import advance_sequence

__all__ = ["heavy_top_advance", "HeavyTopSplittingStepper", "ExactKickStepper"]


@njit(cache=True, inline="always")
def _kick(M, R, w, tau):  # noqa: ANN001, N803
    g0 = R[2, 0]
    g1 = R[2, 1]
    g2 = R[2, 2]
    M[0] += tau * (g1 * w[2] - g2 * w[1])
    M[1] += tau * (g2 * w[0] - g0 * w[2])
    M[2] += tau * (g0 * w[1] - g1 * w[0])


@njit(cache=True)
def heavy_top_advance(M, R, w, gammas, axes, rates, fractions, casimir_rate, dt, n_steps):  # noqa: ANN001, N803, PLR0913
    """``n_steps`` composed steps ``prod_i K(g_i dt/2) F(g_i dt) K(g_i dt/2)`` in place.

    ``w = m g chi`` (body frame); ``F`` is the free-body Strang step given by the
    sub-step sequence ``(axes, rates, fractions, casimir_rate)`` of
    :func:`dirac.rigidbody.splitting.build_sequence`. Adjacent kicks are merged.
    """
    s = gammas.shape[0]
    if n_steps <= 0:
        return
    _kick(M, R, w, 0.5 * gammas[0] * dt)
    for step in range(n_steps):
        for i in range(s):
            advance_sequence(M, R, axes, rates, fractions, casimir_rate, gammas[i] * dt, 1, True)
            if i < s - 1:
                _kick(M, R, w, 0.5 * (gammas[i] + gammas[i + 1]) * dt)
            elif step < n_steps - 1:
                _kick(M, R, w, 0.5 * (gammas[i] + gammas[0]) * dt)
            else:
                _kick(M, R, w, 0.5 * gammas[i] * dt)


class HeavyTopSplittingStepper(RigidBodyStepper):
    """Kick + Lie–Poisson free step, composed (numba loop)."""

    def __init__(self, method: Method, problem, outputs: tuple[str, ...]) -> None:  # noqa: ANN001
        super().__init__(problem, outputs)
        from dirac.rigidbody.splitting import build_sequence

        scheme = method.data
        self.gammas = np.asarray(scheme.coefficients, dtype=float)  # type: ignore[attr-defined]
        self.sequence = build_sequence(self.inv_inertia, (1.0,), scheme.splitting)  # type: ignore[attr-defined]
        self.w = np.asarray(problem.weight_vector, dtype=float)
        self._stages = len(self.gammas) * (len(self.sequence[0]) + 1)

    def warm_up(self) -> None:
        heavy_top_advance(self.M[0].copy(), self.R[0].copy(), self.w, self.gammas, *self.sequence, 1e-3, 1)

    def step(self, n_steps: int, dt: float) -> None:
        for b in range(self.M.shape[0]):
            heavy_top_advance(self.M[b], self.R[b], self.w, self.gammas, *self.sequence, dt, n_steps)
        self.steps += n_steps
        self.evaluations += n_steps * self._stages * self.M.shape[0]


class ExactKickStepper(RigidBodyStepper):
    """Kick + exact free flow (Celledoni et al. 2008), composed; Python loop over stages."""

    def __init__(self, method: Method, problem, outputs: tuple[str, ...]) -> None:  # noqa: ANN001
        super().__init__(problem, outputs)
        self.gammas = np.asarray(method.data, dtype=float)
        self.w = np.asarray(problem.weight_vector, dtype=float)

    def _free(self, b: int, tau: float) -> None:
        flow = exact_flow(self.inertia, self.M[b].copy(), self.R[b].copy())
        M1, R1 = flow.state(np.array([tau]))
        self.M[b] = M1[0]
        self.R[b] = R1[0]

    def _kick(self, b: int, tau: float) -> None:
        _kick(self.M[b], self.R[b], self.w, tau)  # compiled: np.cross costs ~100x more per call

    def warm_up(self) -> None:
        exact_flow(self.inertia, self.M[0], self.R[0]).state(np.array([1e-3]))
        _kick(self.M[0].copy(), self.R[0], self.w, 0.0)

    def step(self, n_steps: int, dt: float) -> None:
        for b in range(self.M.shape[0]):
            for _ in range(n_steps):
                for gamma in self.gammas:
                    self._kick(b, 0.5 * gamma * dt)
                    self._free(b, gamma * dt)
                    self._kick(b, 0.5 * gamma * dt)
        self.steps += n_steps
        self.evaluations += n_steps * 3 * len(self.gammas) * self.M.shape[0]


def heavy_top_factory(method: Method, problem, outputs, options) -> Stepper:  # noqa: ANN001
    """Stepper of a ``lie-poisson-*`` method on a :class:`HeavyTopProblem`."""
    return HeavyTopSplittingStepper(method, problem, outputs)


def _exact_kick_factory(method: Method, problem, outputs, options) -> Stepper:  # noqa: ANN001
    return ExactKickStepper(method, problem, outputs)


def _register() -> None:
    from dirac.rigidbody.splitting import COMPOSITIONS

    for suffix, order, coefficients, reference in COMPOSITIONS:
        if suffix not in ("2", "4", "6", "8"):
            continue
        register_method(
            Method(
                name=f"exact-kick-{suffix}",
                order=order,
                kind="fixed",
                problems=("heavy_top",),
                symplectic=True,
                preserves_casimirs=True,
                description=f"heavy top: exact free flow + gravity kick (Celledoni et al. 2008), order {order}",
                reference=f"Celledoni, Fasso, Safstrom & Zanna, SIAM J. Sci. Comput. 30 (2008); {reference}",
                factory=_exact_kick_factory,
                data=tuple(coefficients),
            )
        )


_register()
