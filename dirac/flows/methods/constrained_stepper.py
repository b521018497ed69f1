"""What the methods of constrained systems share: the batched state ``(q, p)``, its
outputs, the Newton options and the translation of kernel failures into
:class:`~dirac.flows.methods.base.StepFailure`.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np

from dirac.flows.dirac_field import constrained_outputs
from dirac.flows.methods.base import StepFailure, Stepper

__all__ = ["ConstrainedStepper", "newton_options", "singular_as_step_failure", "tiered", "call_tiered"]


def newton_options(options: dict) -> tuple[float, int, np.ndarray]:
    """``(tol, max_iter, info)`` of a stepper with a Newton iteration: the run's
    ``newton_tolerance`` and ``max_newton_iterations`` and the ``info`` buffer its kernel fills."""
    return float(options.get("newton_tolerance", 1e-12)), int(options.get("max_newton_iterations", 50)), np.zeros(4)


class ConstrainedStepper(Stepper):
    """Common state ``(q, p)`` (batched) and outputs of steppers of constrained systems."""

    def __init__(self, problem, outputs: tuple[str, ...], options: dict) -> None:
        super().__init__()
        self.problem = problem
        self.mechanics = problem.mechanics
        self.outputs = outputs
        self.q = np.ascontiguousarray(problem.q0, dtype=float).copy()
        self.p = np.ascontiguousarray(problem.p0, dtype=float).copy()
        self.tol, self.max_iter, self.info = newton_options(options)
        self.time = 0.0  # the time of the state (time-dependent systems)
        self.planned_steps: int | None = options.get("planned_steps")
        #: a pilot of ``auto``: a run of the same loop over a longer span follows
        self.pilot = bool(options.get("pilot", False))

    def _kernel_call(self, kernel: Any, steps: int, *args: Any, warm_up: bool = False) -> None:
        """Call a step loop of the generated module: a tiered one (interpreted while the
        steps still planned are few, :mod:`dirac.codegen.tiers`) or a compiled one;
        ``warm_up``: a one-step call on scratch arguments that decides the tier."""
        call_tiered(kernel, self.planned_steps, self.steps, steps, args, warm_up, pilot=self.pilot)

    def observe(self) -> dict[str, np.ndarray]:
        return constrained_outputs(self.mechanics, self.outputs, self.q, self.p, self.time)

    def finite(self) -> bool:
        return bool(np.all(np.isfinite(self.q)) and np.all(np.isfinite(self.p)))

    def drift(self) -> float:
        return max(self.mechanics.constraint_residual(q, p, self.time) for q, p in zip(self.q, self.p))

    def _raise_if_failed(self, what: str) -> None:
        if self.info[1] != 0.0:
            raise StepFailure(
                f"{what}: Newton iteration did not converge in {self.max_iter} iterations "
                f"(residual {self.info[3]:.3g} > tolerance {self.tol:.1g}); reduce dt",
                steps_done=int(self.info[0]),
            )


@contextmanager
def singular_as_step_failure(what: str) -> Iterator[None]:
    """Turn the kernels' division by a zero pivot into a :class:`StepFailure`.

    The Newton matrix ``G M^{-1} G^T`` is singular where the constraints are not independent
    (e.g. a pendulum of length 0 at the origin); the compiled solve then divides by zero.
    """
    try:
        yield
    except ZeroDivisionError:
        raise StepFailure(
            f"{what}: the Newton matrix G M^-1 G^T is singular (the constraints are not independent "
            "here); check the constraints and the state"
        ) from None


def call_tiered(kernel: Any, planned_steps: int | None, steps_done: int, steps: int, args: tuple[Any, ...],
                warm_up: bool = False, pilot: bool = False) -> None:
    """``kernel(*args)`` advancing ``steps`` steps of a run of ``planned_steps`` (None:
    unknown), ``steps_done`` of them done, through its tier when it is a
    :class:`~dirac.codegen.tiers.TieredFunction`; ``pilot``: a pilot of ``auto``, which a
    run of the same loop over a longer span follows
    (:meth:`~dirac.codegen.tiers.TieredFunction.expect_longer_run`)."""
    from dirac.codegen.tiers import TieredFunction  # not at import: a rigid-body run never needs codegen

    if not isinstance(kernel, TieredFunction):
        kernel(*args)
        return
    if pilot:
        kernel.expect_longer_run()
    planned = None if planned_steps is None else max(planned_steps - steps_done, steps)
    if warm_up:
        kernel.warm_up(planned, *args)
    else:
        kernel.run_steps(steps, planned, *args)


def tiered(module: Any, name: str) -> Any:
    """``name`` of a generated module: its tiered function (:func:`dirac.codegen.tiers.tiered`)."""
    from dirac.codegen.tiers import tiered as tiered_function

    return tiered_function(module, name)
