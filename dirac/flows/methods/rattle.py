"""RATTLE for holonomically constrained systems, and its symmetric compositions.

RATTLE (Andersen 1983; Leimkuhler & Skeel 1994; Hairer, Lubich & Wanner, Geometric
Numerical Integration, Sect. VII.1.4) is symplectic on the constraint manifold, symmetric
and of order 2; the positions satisfy ``chi(q) = 0`` to the Newton tolerance and the
momenta the hidden constraint ``G(q) M^{-1} p = 0`` exactly (a linear solve). Because it is
symmetric, the compositions of :data:`dirac.rigidbody.splitting.COMPOSITIONS` (Yoshida,
Kahan–Li) raise its order to 4, 6, 8 (``rattle-4`` ...), with the coefficients as data.

With a constant mass matrix (Cartesian coordinates) the Newton iteration runs on the
``m`` multipliers only; otherwise on ``(p_half, q1, lambda)`` (Jay 1996). Both step loops
are numba kernels compiled once (:mod:`dirac.flows.constrained_kernels`). A step whose
Newton iteration does not converge within ``max_newton_iterations`` stops the run with
the state of the last completed step.
"""

from __future__ import annotations

import numpy as np

from dirac.flows.dirac_field import constrained_outputs
from dirac.flows.methods.base import Method, Stepper, StepFailure, register_method

__all__ = ["ConstrainedStepper", "RattleStepper"]


def newton_options(options: dict) -> tuple[float, int, np.ndarray]:
    """``(tol, max_iter, info)`` of a stepper with a Newton iteration: the run's
    ``newton_tolerance`` and ``max_newton_iterations`` and the ``info`` buffer its kernel fills."""
    return float(options.get("newton_tolerance", 1e-12)), int(options.get("max_newton_iterations", 50)), np.zeros(4)


class ConstrainedStepper(Stepper):
    """Common state ``(q, p)`` (batched) and outputs of steppers of constrained systems."""

    def __init__(self, problem, outputs: tuple[str, ...], options: dict) -> None:  # noqa: ANN001
        super().__init__()
        self.problem = problem
        self.mechanics = problem.mechanics
        self.outputs = outputs
        self.q = np.ascontiguousarray(problem.q0, dtype=float).copy()
        self.p = np.ascontiguousarray(problem.p0, dtype=float).copy()
        self.tol, self.max_iter, self.info = newton_options(options)

    def observe(self) -> dict[str, np.ndarray]:
        return constrained_outputs(self.mechanics, self.outputs, self.q, self.p)

    def finite(self) -> bool:
        return bool(np.all(np.isfinite(self.q)) and np.all(np.isfinite(self.p)))

    def drift(self) -> float:
        return max(self.mechanics.constraint_residual(q, p) for q, p in zip(self.q, self.p))

    def _raise_if_failed(self, what: str) -> None:
        if self.info[1] != 0.0:
            raise StepFailure(
                f"{what}: Newton iteration did not converge in {self.max_iter} iterations "
                f"(residual {self.info[3]:.3g} > tolerance {self.tol:.1g}); reduce dt",
                steps_done=int(self.info[0]),
            )


class singular_as_step_failure:  # noqa: N801 - used as a context manager
    """Turn the kernels' division by a zero pivot into a :class:`StepFailure`.

    The Newton matrix ``G M^{-1} G^T`` is singular where the constraints are not independent
    (e.g. a pendulum of length 0 at the origin); the compiled solve then divides by zero.
    """

    def __init__(self, what: str) -> None:
        self.what = what

    def __enter__(self) -> None:
        return None

    def __exit__(self, kind, value, traceback) -> bool:  # noqa: ANN001
        if kind is not None and issubclass(kind, ZeroDivisionError):
            raise StepFailure(
                f"{self.what}: the Newton matrix G M^-1 G^T is singular (the constraints are not independent "
                "here); check the constraints and the state"
            ) from None
        return False


class RattleStepper(ConstrainedStepper):
    """RATTLE composed with the coefficients of ``method.data`` (fractions of a step)."""

    def __init__(self, method: Method, problem, outputs: tuple[str, ...], options: dict) -> None:  # noqa: ANN001
        super().__init__(problem, outputs, options)
        self.name = method.name
        self.fractions = np.asarray(method.data, dtype=float)
        from dirac.flows import constrained_kernels as kernels

        self.constant = self.mechanics.constant_mass is not None
        if self.constant:
            self.mechanics.mass_matrix(self.q[0])  # checks positivity
            self.minv = np.linalg.inv(self.mechanics.constant_mass)
            self._kernel = kernels.rattle_constant_mass
        else:
            for q in self.q:
                self.mechanics.mass_matrix(q)
            self._kernel = kernels.rattle_general

    def _call(self, q: np.ndarray, p: np.ndarray, n_steps: int, dt: float) -> None:
        m = self.mechanics.n_constraints
        params = self.mechanics.params
        fns = self.mechanics.functions
        if self.constant:
            self._kernel(fns, q, p, self.minv, params, m, self.fractions, dt, n_steps, self.tol, self.max_iter, self.info)
        else:
            self._kernel(fns, q, p, params, m, self.fractions, dt, n_steps, self.tol, self.max_iter, self.info)

    def warm_up(self) -> None:
        from dirac.flows.constrained_kernels import quiet

        with quiet():
            self._call(self.q[0].copy(), self.p[0].copy(), 1, 1e-6)

    def step(self, n_steps: int, dt: float) -> None:
        from dirac.flows.constrained_kernels import quiet

        for b in range(self.q.shape[0]):
            with quiet(), singular_as_step_failure(self.name):
                self._call(self.q[b], self.p[b], n_steps, dt)
            self.evaluations += int(self.info[2])
            self._raise_if_failed(self.name)
        self.steps += n_steps


def _factory(method: Method, problem, outputs, options) -> Stepper:  # noqa: ANN001
    return RattleStepper(method, problem, outputs, options)


def _register() -> None:
    from dirac.rigidbody.splitting import COMPOSITIONS

    for suffix, order, coefficients, reference in COMPOSITIONS:
        if suffix not in ("2", "4", "6", "8"):
            continue
        register_method(
            Method(
                name=f"rattle-{suffix}",
                order=order,
                kind="fixed",
                problems=("constrained",),
                symplectic=True,
                preserves_casimirs=False,
                description=f"constrained systems: RATTLE{'' if order == 2 else ', composed: ' + reference}, order {order}",
                reference="Andersen (1983); Hairer, Lubich & Wanner VII.1.4" + ("" if order == 2 else f"; {reference}"),
                factory=_factory,
                data=tuple(coefficients),
            )
        )


_register()
