"""``method = "auto"``: pick the cheapest method that meets the tolerance.

* Free rigid body: ``exact`` costs a fixed amount per output sample, whatever ``t_end``;
  ``lie-poisson-8`` costs per step. A short pilot run of ``lie-poisson-8`` against the
  exact flow measures its error constant; assuming the error grows linearly in time
  (phase error of an integrable system) gives the step that meets ``tolerance`` at
  ``t_end`` and so the number of steps. The cheaper of the two is chosen with the cost
  ratio :data:`EXACT_SAMPLE_COST` (in units of one Strang sub-step). Dense, long outputs
  (many samples per period) favour the splitting; sparse or very long ones the exact flow.
* Heavy top and general systems: no exact reference, so each candidate of order ``p``
  (``lie-poisson-4/8`` resp. ``rattle-2/4``) is run over a pilot span with steps ``h`` and
  ``h/2``; Richardson's estimate ``|y_h - y_{h/2}| / (1 - 2^-p)`` with linear growth in
  time gives the step for ``tolerance``; the cheaper candidate wins.

The estimates are a-priori models, recorded in the result's ``meta["auto"]``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from dirac.flows.methods import get_method

__all__ = ["AutoChoice", "choose_method", "EXACT_SAMPLE_COST"]

#: Cost of one exact sample (M and R) in units of one Strang sub-step of the splitting
#: kernel (one rotation of M and R). Measured on this project's reference machine:
#: exact state ~ 1.1 us per sample, one rotation sub-step ~ 0.011 us.
EXACT_SAMPLE_COST = 100.0
#: The same for an exact sample of M alone.
EXACT_SAMPLE_COST_M = 40.0


@dataclass(frozen=True)
class AutoChoice:
    """The method ``auto`` chose, its step, why, and the error it expects."""

    method: str
    dt: float | None
    reason: str
    estimated_error: float | None = None


def _state(stepper) -> np.ndarray:  # noqa: ANN001
    if hasattr(stepper, "q"):
        return np.concatenate([stepper.q.ravel(), stepper.p.ravel()])
    parts = [stepper.M.ravel()]
    if stepper.with_R:
        parts.append(stepper.R.ravel())
    return np.concatenate(parts)


def _pilot(method_name: str, problem, outputs, span: float, dt: float, options) -> np.ndarray:  # noqa: ANN001
    stepper = get_method(method_name).start(problem, outputs, options)
    n = max(1, int(round(span / dt)))
    stepper.step(n, span / n)
    return _state(stepper)


def _frequency(problem) -> float:  # noqa: ANN001
    M = np.asarray(problem.M0, dtype=float)
    return float(np.max(np.linalg.norm(M, axis=-1)) * np.max(1.0 / np.asarray(problem.inertia)) + 1e-300)


def choose_method(problem, kind: str, *, t_end: float, samples: int, tolerance: float, dt: float | None,  # noqa: ANN001
                  outputs: tuple[str, ...]) -> AutoChoice:
    """Choose method and step for ``problem`` (see the module docstring)."""
    options = {"t_end": t_end, "tolerance": tolerance, "newton_tolerance": 1e-12, "max_newton_iterations": 50}
    if kind == "rigid_body":
        return _rigid_body(problem, t_end, samples, tolerance, outputs, options)
    if kind == "heavy_top":
        candidates = ("lie-poisson-4", "lie-poisson-8")
        scale = 1.0 / _frequency(problem)
        weight = float(np.linalg.norm(problem.weight_vector))
        if weight > 0:
            scale = min(scale, 1.0 / math.sqrt(weight / float(np.min(problem.inertia))))
        dt0 = dt if dt is not None else 0.05 * scale
    else:
        candidates = ("rattle-2", "rattle-4")
        dt0 = dt if dt is not None else t_end / 1000.0
    best: AutoChoice | None = None
    best_cost = math.inf
    for name in candidates:
        method = get_method(name)
        span = min(t_end, 64 * dt0)
        coarse = _pilot(name, problem, outputs, span, dt0, options)
        fine = _pilot(name, problem, outputs, span, dt0 / 2, options)
        error = float(np.max(np.abs(coarse - fine))) / (1.0 - 2.0 ** (-method.order))
        growth = t_end / span
        if error * growth > 0:
            factor = (tolerance / (error * growth)) ** (1.0 / method.order)
        else:
            factor = 8.0
        step = dt0 * min(8.0, 0.8 * factor)
        stages = len(method.data) if isinstance(method.data, tuple) else len(method.data.coefficients)  # type: ignore[union-attr]
        cost = (t_end / step) * stages
        if cost < best_cost:
            best_cost = cost
            predicted = error * growth * (step / dt0) ** method.order
            best = AutoChoice(name, step, f"pilot Richardson estimate: {name} with dt = {step:.3g} is the cheapest "
                              f"candidate for tolerance {tolerance:g}", predicted)
    assert best is not None
    return best


def _rigid_body(problem, t_end: float, samples: int, tolerance: float, outputs, options) -> AutoChoice:  # noqa: ANN001
    from dirac.flows.lie_poisson import exact_flow, needs_attitude

    with_R = needs_attitude(outputs)
    exact_cost = samples * (EXACT_SAMPLE_COST if with_R else EXACT_SAMPLE_COST_M)
    omega = _frequency(problem)
    dt0 = 0.2 / omega
    span = min(t_end, 200 * dt0)
    name = "lie-poisson-8"
    method = get_method(name)
    numeric = _pilot(name, problem, outputs, span, dt0, options)
    exact_M, exact_R = [], []
    for M0, R0 in zip(problem.M0, problem.R0):
        M, R = exact_flow(problem.inertia, M0, R0).state(np.array([span]))
        exact_M.append(M[0])
        exact_R.append(R[0].ravel())
    exact_state = np.concatenate(exact_M + (exact_R if with_R else []))
    error = float(np.max(np.abs(numeric - exact_state)))
    growth = t_end / span
    floor = 1e-16 * math.sqrt(max(1.0, t_end / dt0)) * 10
    if tolerance <= floor:
        return AutoChoice("exact", None, f"tolerance {tolerance:g} is below the round-off floor of time stepping", 0.0)
    factor = (tolerance / max(error * growth, 1e-300)) ** (1.0 / method.order)
    step = dt0 * min(4.0, 0.8 * factor)
    spacing = t_end / max(1, samples - 1)
    steps = max(samples - 1, math.ceil(t_end / step))
    sequence_length = 4 * len(method.data.coefficients) + 1  # type: ignore[union-attr]
    split_cost = steps * sequence_length
    if split_cost < exact_cost:
        predicted = error * growth * (min(step, spacing) / dt0) ** method.order
        return AutoChoice(name, step, f"dense output: {steps} steps of {name} cost less than {samples} exact samples", predicted)
    return AutoChoice("exact", None, f"the exact flow ({samples} samples) costs less than {steps} steps of {name}", 0.0)
