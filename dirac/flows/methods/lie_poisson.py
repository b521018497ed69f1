"""Lie–Poisson splitting methods for the free rigid body, wrapped as methods.

The mathematics (exact rotations of ``M`` and ``R`` for each ``H_k = M_k^2 / (2 I_k)``,
symmetric compositions with coefficient tables as data) lives in
:mod:`dirac.rigidbody.splitting`; this module binds it to :class:`RigidBodyProblem`:
one :class:`Method` per composition scheme (``lie-poisson-2/4/6/8`` and the extras).

Only what is asked for is advanced: when no output needs ``R`` the kernel never touches
it (``with_R = False``).
"""

from __future__ import annotations

import numpy as np

from dirac.flows.methods.base import Method, Stepper, register_method

__all__ = ["RigidBodyStepper", "LiePoissonStepper", "needs_attitude", "exact_flow"]

#: Batches of at least this many bodies use the batched kernel (3-term split only).
BATCH_THRESHOLD = 2


def exact_flow(inertia, M0, R0):  # noqa: ANN001, ANN201
    """:class:`ExactRigidBodyFlow` of already validated data (its warnings were shown once)."""
    import warnings

    from dirac.errors import DiracWarning
    from dirac.rigidbody.exact import ExactRigidBodyFlow

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DiracWarning)
        return ExactRigidBodyFlow(inertia, M0, R0)


def needs_attitude(outputs: tuple[str, ...]) -> bool:
    """Whether any requested output depends on ``R``."""
    return any(name in ("R", "lab_momentum", "lab_momentum_z", "orthogonality") for name in outputs)


class RigidBodyStepper(Stepper):
    """Common state ``(M, R)`` (batched) and outputs of rigid-body steppers."""

    def __init__(self, problem, outputs: tuple[str, ...]) -> None:  # noqa: ANN001
        super().__init__()
        self.problem = problem
        self.inertia = np.asarray(problem.inertia, dtype=float)
        self.inv_inertia = 1.0 / self.inertia
        self.outputs = outputs
        self.with_R = needs_attitude(outputs) or getattr(problem, "system", "") == "heavy_top"
        self.M = np.ascontiguousarray(problem.M0, dtype=float).copy()
        self.R = np.ascontiguousarray(problem.R0, dtype=float).copy()

    def observe(self) -> dict[str, np.ndarray]:
        return rigid_body_outputs(self.outputs, self.M, self.R, self.inertia, self.problem)

    def finite(self) -> bool:
        return bool(np.all(np.isfinite(self.M)) and (not self.with_R or np.all(np.isfinite(self.R))))

    def drift(self) -> float:
        if not self.with_R:
            return 0.0
        eye = np.eye(3)
        return float(np.max(np.abs(np.einsum("bki,bkj->bij", self.R, self.R) - eye)))


def rigid_body_outputs(
    outputs: tuple[str, ...], M: np.ndarray, R: np.ndarray | None, inertia: np.ndarray, problem: object
) -> dict[str, np.ndarray]:
    """Compute the requested outputs from batched ``M`` (B, 3) and ``R`` (B, 3, 3).

    ``energy`` is ``H_0`` (247) for the free body and ``H_0 + m g <chi, R^T e_z>`` for
    the heavy top; ``casimir`` is ``|M|^2``; ``lab_momentum`` is ``m = R M``;
    ``lab_momentum_z`` its vertical component (conserved by the heavy top).
    """
    result: dict[str, np.ndarray] = {}
    for name in outputs:
        if name == "M":
            result[name] = M.copy()
        elif name == "R":
            result[name] = R.copy()  # type: ignore[union-attr]
        elif name == "energy":
            energy = 0.5 * np.sum(M * M / inertia, axis=-1)
            if getattr(problem, "system", "") == "heavy_top":
                energy = energy + R[:, 2, :] @ problem.weight_vector  # type: ignore[index, attr-defined]
            result[name] = energy
        elif name == "casimir":
            result[name] = np.sum(M * M, axis=-1)
        elif name == "lab_momentum":
            result[name] = np.einsum("bij,bj->bi", R, M)
        elif name == "lab_momentum_z":
            result[name] = np.einsum("bj,bj->b", R[:, 2, :], M)  # type: ignore[index]
        else:  # pragma: no cover - outputs are validated before
            raise KeyError(name)
    return result


class LiePoissonStepper(RigidBodyStepper):
    """Composed Lie–Poisson splitting (McLachlan 1993; Reich 1994; Touma & Wisdom 1994)."""

    def __init__(self, method: Method, problem, outputs: tuple[str, ...]) -> None:  # noqa: ANN001
        super().__init__(problem, outputs)
        from dirac.rigidbody import splitting

        scheme = method.data
        self._axes, self._rates, self._fractions, self._casimir_rate = splitting.build_sequence(
            self.inv_inertia, scheme.coefficients, scheme.splitting  # type: ignore[attr-defined]
        )
        self._kernel = splitting.advance_sequence
        self._stages = int(self._axes.shape[0] - 1)
        # many bodies with the 3-term split: all advanced together by the batched kernel
        # (dirac.rigidbody.batch: blocks over the cores, vectorised trigonometry)
        self._coefficients = tuple(scheme.coefficients)  # type: ignore[attr-defined]
        self._batched = scheme.splitting == "axes" and self.M.shape[0] >= BATCH_THRESHOLD  # type: ignore[attr-defined]

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


def _lie_poisson_factory(method: Method, problem, outputs, options) -> Stepper:  # noqa: ANN001
    if getattr(problem, "system", "") == "heavy_top":
        from dirac.flows.methods.heavy_top import heavy_top_factory

        return heavy_top_factory(method, problem, outputs, options)
    return LiePoissonStepper(method, problem, outputs)


def _register() -> None:
    from dirac.rigidbody.splitting import SCHEMES

    for name, scheme in SCHEMES.items():
        split = "3-term axes split" if scheme.splitting == "axes" else "symmetric-top split (Fasso 2003)"
        register_method(
            Method(
                name=name,
                order=scheme.order,
                kind="fixed",
                problems=("rigid_body", "heavy_top"),
                symplectic=True,
                preserves_casimirs=True,
                description=f"rigid body (heavy top: + gravity kick): Lie-Poisson splitting, {split}, order {scheme.order}",
                reference=scheme.reference,
                factory=_lie_poisson_factory,
                data=scheme,
            )
        )


_register()
