"""``method = "auto"``: pick the cheapest method that meets the tolerance.

* Free rigid body: ``exact`` costs a fixed amount per output sample, whatever ``t_end``;
  a splitting ``lie-poisson-p`` costs per step plus the sampling overhead of the loop.
  For each ``p`` a short pilot run against the exact flow measures the error constant;
  assuming linear growth in time (phase error of an integrable system) gives the step
  that meets ``tolerance`` at ``t_end``. The cheapest wins, with the measured unit costs
  below. With these costs the exact flow (about 0.2-0.5 us per sample) is cheaper than
  sampling any stepping run (about 15 us per sample), so ``auto`` picks ``exact`` for the
  free body at every sampling density; the splittings would win only if sampling were
  moved into the compiled loop.
* Heavy top: the same work–precision logic as for the free body, with Richardson's
  estimate in place of the exact reference (there is none): each candidate
  (``lie-poisson-4/6/8``, ``exact-kick-4/6/8``) is run over a pilot span with steps ``h``
  and ``h/2``, ``|y_h - y_{h/2}| / (1 - 2^-p)`` with linear growth in time gives the step
  for ``tolerance`` (the pilot is repeated at that step while it grows more than
  twofold, so a method whose error at the first pilot step is round-off is judged at
  its own step), and the measured cost of a stage below turns steps into microseconds.
  ``exact-kick-*`` costs more per stage but its error is proportional to the gravity
  torque, so it wins for a fast top (gravity a perturbation of the free motion) and
  ``lie-poisson-*`` for a slow one.
* A rigid body or heavy top driven by an external torque or angular impulses: the same
  candidates and the same Richardson logic, with torque kicks
  (:mod:`dirac.flows.methods.torqued`).
* Forced systems: ``forced-rattle-2/4`` (and ``conformal-2/4`` for linear damping of a
  constant-mass system) by the same Richardson estimate, costed by the evaluations per
  step of a short pilot.
* General and analysed systems: each candidate of order ``p`` (``rattle-2/4/6/8``, resp.
  ``midpoint``) is run over a short pilot span with steps ``h`` and ``h/2``; Richardson's
  estimate with linear growth in time gives the step for ``tolerance / 2`` at ``t_end``,
  and the pilots are repeated at that step until it agrees with ``h`` within a factor 2
  (:func:`_accurate_step`: an estimate made far from the asymptotic regime is not
  trusted). The cost is steps times stages (all candidates share one kernel), with at
  least one step per output sample; the cheapest candidate wins, and a candidate that
  cannot beat the best even at one step per sample is not piloted at all. The winner's
  step is then checked over a span of ``t_end / 32``, where its error's growth in time is
  measured rather than assumed (:func:`_confirmed_step`).

The estimates are a-priori models, recorded in the result's ``meta["auto"]``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from dirac.errors import InputError
from dirac.flows.methods.base import Method, StepFailure
from dirac.flows.methods.registry import get_method
from dirac.flows.methods.rigid_body_stepper import exact_flow, needs_attitude
from dirac.flows.methods.whole_span import state_vector as _state
from dirac.rigidbody.schemes import CompositionScheme

__all__ = ["AutoChoice", "choose_method"]

#: Measured costs (microseconds; the per-step and per-sample figures of ``dirac bench`` on
#: the reference machine, 2 cores): one exact sample of ``(M, R)`` / of ``M`` alone (vectorised
#: elliptic functions), one rotation sub-step of the splitting kernel, and the sampling
#: overhead of the fixed-step loop per output time (kernel call, guard rails, copy).
EXACT_SAMPLE_US = 0.5
EXACT_SAMPLE_M_US = 0.2
SUBSTEP_US = 0.11
LOOP_SAMPLE_US = 15.0
#: Heavy top, per stage of a composition (kick + free step), same machine: the 3-term
#: Lie–Poisson Strang step, and the exact free flow set up and evaluated in the kernel
#: (``dirac bench``'s heavy-top per-step figures, 0.59 and 1.45 us per 3-stage step).
SPLIT_STAGE_US = 0.2
EXACT_KICK_STAGE_US = 0.48
#: General and analysed systems: the candidates (RATTLE and its compositions up to order 8,
#: each costed by its base steps, which share one kernel), and the pilots that judge them.
GENERAL_CANDIDATES = ("rattle-2", "rattle-4", "rattle-6", "rattle-8")
ANALYSED_CANDIDATES = ("midpoint",)
PILOT_STEPS = 16
PILOT_ROUNDS = 4
CONFIRM_FRACTION = 32
CONFIRM_SAFETY = 0.1
HEAVY_TOP_CANDIDATES = ("lie-poisson-4", "lie-poisson-6", "lie-poisson-8", "exact-kick-4", "exact-kick-6", "exact-kick-8")


@dataclass(frozen=True)
class AutoChoice:
    """The method ``auto`` chose, its step, why, and the error it expects; ``newton_tolerance``:
    the tightest Newton tolerance the run needs to reach the error (None: the caller's)."""

    method: str
    dt: float | None
    reason: str
    estimated_error: float | None = None
    newton_tolerance: float | None = None


def newton_tolerance_for(tolerance: float) -> float:
    """Newton tolerance of an implicit run that must reach ``tolerance``: ``tolerance * 1e-6``
    within ``[1e-14, 1e-12]``.

    Each implicit step stops its Newton iteration at a residual of about this tolerance
    times ``1 + |x|^2`` (:mod:`dirac.codegen.kernel_templates`), and ``1e5`` base steps add
    these up; the motion may amplify them. Richardson's estimate does not see this floor (the
    coarse and the fine pilot have it alike): a double pendulum in its angles run to
    ``t = 100`` with ``rattle-8`` reached 1.2e-7 in its angles with ``1e-12``, whatever the
    step, and 2.4e-9 with ``1e-14``, the error ``tolerance = 1e-8`` asks for (against DOP853
    at ``rtol = 1e-13``).
    """
    return min(1e-12, max(1e-14, tolerance * 1e-6))


def _stages(method: Method) -> int:
    """Base steps per step: the length of the composition (1 for an uncomposed method)."""
    if isinstance(method.data, CompositionScheme):
        return len(method.data.coefficients)
    if isinstance(method.data, tuple):
        return len(method.data)
    return 1


def _pilot(method_name: str, problem, outputs, span: float, dt: float, options) -> np.ndarray:
    n = max(1, int(round(span / dt)))
    # a pilot of known length: a generated kernel stays interpreted unless n steps of it
    # would take longer than compiling (dirac.codegen.tiers); unknown, it compiled at once
    stepper = get_method(method_name).start(problem, outputs, {**options, "planned_steps": n})
    stepper.step(n, span / n)
    return _state(stepper)


def _working_step(method_name: str, problem, outputs, dt0: float, t_end: float,
                  options, steps: int = 64) -> tuple[float, np.ndarray]:
    """``dt0`` halved until a pilot of ``steps`` steps runs without a failed step: that step and
    the pilot's final state (the coarse run of the Richardson estimate).

    A first guess such as ``t_end / 1000`` can be far beyond the system's own time scale
    (a pendulum run to ``t = 1000``), where RATTLE's Newton iteration cannot converge.
    """
    dt = dt0
    for _ in range(60):
        try:
            span = min(t_end, steps * dt)
            return dt, _pilot(method_name, problem, outputs, span, dt, options)
        except StepFailure:
            dt /= 2
    raise InputError(f"method auto: {method_name} fails even with dt = {dt:.3g}; choose a method and dt in [run]")


def _frequency(problem) -> float:
    M = np.asarray(problem.M0, dtype=float)
    return float(np.max(np.linalg.norm(M, axis=-1)) * np.max(1.0 / np.asarray(problem.inertia)) + 1e-300)


def choose_method(problem, kind: str, *, t_end: float, samples: int, tolerance: float, dt: float | None,
                  outputs: tuple[str, ...]) -> AutoChoice:
    """Choose method and step for ``problem`` (see the module docstring)."""
    # "pilot": every run made here is a pilot of the run that follows over [0, t_end] on the same
    # loop (its step loop buys its tape at once: TieredFunction.expect_longer_run)
    options = {"t_end": t_end, "tolerance": tolerance, "newton_tolerance": 1e-12, "max_newton_iterations": 50,
               "pilot": True}
    if kind in ("rigid_body", "heavy_top") and problem.driven:
        return _heavy_top(problem, t_end, tolerance, dt, outputs, options)
    if kind == "rigid_body":
        return _rigid_body(problem, t_end, samples, tolerance, outputs, options)
    if kind == "heavy_top":
        return _heavy_top(problem, t_end, tolerance, dt, outputs, options)
    if kind == "forced":
        return _forced(problem, t_end, tolerance, dt, outputs, options)
    options["newton_tolerance"] = newton_tolerance_for(tolerance)
    candidates = ANALYSED_CANDIDATES if kind == "analysed" else GENERAL_CANDIDATES
    dt_start = dt if dt is not None else t_end / 1000.0
    spacing = t_end / (samples - 1) if samples > 1 else t_end  # the loop's step divides the sample spacing
    best: AutoChoice | None = None
    best_cost = math.inf
    for name in candidates:  # in order of increasing order and stages
        method = get_method(name)
        stages = _stages(method)
        if best is not None and math.ceil(t_end / spacing * (1.0 - 1e-12)) * stages >= best_cost:
            continue  # even one step per sample costs more than the best so far: no pilot needed
        step, predicted = _accurate_step(name, problem, outputs, dt_start, t_end, tolerance, options)
        used = spacing / math.ceil(spacing / step * (1.0 - 1e-12))
        steps = math.ceil(t_end / used * (1.0 - 1e-12))
        cost = steps * stages
        dt_start = max(dt_start, step)  # a higher order takes larger steps: its pilots start there
        if cost < best_cost:
            best_cost = cost
            best = AutoChoice(name, step, "", predicted)
    assert best is not None
    # the winner is judged once more over a longer span, where the growth of its error shows
    name, method = best.method, get_method(best.method)
    step, predicted, growth = _confirmed_step(name, problem, outputs, float(best.dt or 0.0), t_end, tolerance, options)
    used = spacing / math.ceil(spacing / step * (1.0 - 1e-12))
    steps = math.ceil(t_end / used * (1.0 - 1e-12))
    return AutoChoice(name, used, f"pilot Richardson estimate: {name} with dt = {used:.3g} ({steps} steps of "
                      f"{_stages(method)} stages) is the cheapest candidate for tolerance {tolerance:g} (error growing "
                      f"as t^{growth:.2g})", predicted * (used / step) ** method.order,
                      newton_tolerance=float(options["newton_tolerance"]))


def _pilot_halves(method_name: str, problem, outputs, span: float, dt: float, options) -> tuple[np.ndarray, np.ndarray]:
    """The states of a pilot at ``span / 2`` and at ``span``."""
    n = 2 * max(1, int(round(span / dt / 2)))
    stepper = get_method(method_name).start(problem, outputs, {**options, "planned_steps": n})
    stepper.step(n // 2, span / n)
    middle = _state(stepper)
    stepper.step(n // 2, span / n)
    return middle, _state(stepper)


def _confirmed_step(name: str, problem, outputs, step: float, t_end: float, tolerance: float,
                    options) -> tuple[float, float, float]:
    """The step of :func:`_accurate_step` checked over a span of ``t_end /`` :data:`CONFIRM_FRACTION`
    (at least :data:`PILOT_STEPS` steps): step, predicted error at ``t_end``, growth exponent.

    Linear growth of the error (a regular orbit) is what the short pilots assume; where the
    error grows faster (a chaotic or nearly chaotic motion, or a pilot that started at rest
    and saw only the slow start), that assumption promised too much. Richardson's estimate at
    ``S / 2`` and at ``S`` gives the exponent ``k = log2(e(S) / e(S / 2))``, clamped to
    ``[1, 2]``, and ``E(t_end) = e(S) (t_end / S)^k``: a double pendulum in its angles has
    ``k`` about 1.3 (its error at ``t = 100`` is 30 times the linear extrapolation of the
    first 0.4 s). The step is then set for ``CONFIRM_SAFETY * tolerance`` (a tenth: the
    growth measured over ``[S / 2, S]`` is still a local figure; the same double pendulum at
    ``tolerance = 1e-6`` reached 2.2e-6 at the step set for half the tolerance, and an
    error ten times smaller costs only ``10^(1/8) = 1.33`` times the steps of ``rattle-8``),
    never above the step measured (a step beyond it may leave the asymptotic regime: the
    double pendulum's error at ``1.5 h`` is 100 times that at ``h``, not ``1.5^8 = 26``), and
    checked once more when it shrinks by more than a factor 2.
    """
    order = get_method(name).order
    predicted, growth = math.inf, 1.0
    for _ in range(2):
        span = min(t_end, max(PILOT_STEPS * step, t_end / CONFIRM_FRACTION))
        try:
            coarse = _pilot_halves(name, problem, outputs, span, step, options)
            fine = _pilot_halves(name, problem, outputs, span, step / 2, options)
        except StepFailure:
            return step / 2, predicted, growth
        first, second = (float(np.max(np.abs(c - f))) / (1.0 - 2.0 ** (-order)) for c, f in zip(coarse, fine))
        growth = min(2.0, max(1.0, math.log2(second / first))) if first > 0 and second > 0 else 1.0
        at_end = second * (t_end / span) ** growth
        if not math.isfinite(at_end):
            return step / 2, predicted, growth
        factor = (CONFIRM_SAFETY * tolerance / at_end) ** (1.0 / order) if at_end > 0 else 1.0
        new = step * min(1.0, max(1.0 / 16.0, factor))
        predicted = at_end * (new / step) ** order
        step = new
        if factor >= 0.5:
            break
    return min(step, t_end), predicted, growth


def _accurate_step(name: str, problem, outputs, dt_start: float, t_end: float, tolerance: float,
                   options) -> tuple[float, float]:
    """Step of ``name`` whose error at ``t_end`` is ``tolerance / 2`` by Richardson's estimate, and
    that estimate.

    A pilot of :data:`PILOT_STEPS` steps ``h`` and one of ``2 PILOT_STEPS`` steps ``h / 2`` over
    the same span ``S`` differ by ``e(h) (1 - 2^-p)``, where ``e(h) = C S h^p`` is the error of
    the coarse one (order ``p``; Hairer, Norsett & Wanner I, Sect. II.4). Linear growth in time
    (the phase error of a symplectic method on a regular orbit) gives the error at ``t_end``:
    ``E(h) = e(h) t_end / S``, and ``E(h*) = tolerance / 2`` gives ``h* = h (tolerance / (2
    E(h)))^(1/p)``. The estimate holds only in the asymptotic regime, where ``e`` scales as
    ``h^p``: far above it (a first guess beyond the system's time scale) it is pessimistic, far
    below it round-off hides the error. So while ``h*`` differs from ``h`` by more than a factor
    ``2`` the pilots are repeated at ``h*`` (clipped to ``[h / 16, 8 h]``), at most
    :data:`PILOT_ROUNDS` times; the step of the last round is at most ``2 h``.
    """
    method = get_method(name)
    order = method.order
    dt0, coarse = _working_step(name, problem, outputs, dt_start, t_end, options, PILOT_STEPS)
    step, predicted = dt0, math.inf
    for attempt in range(PILOT_ROUNDS):
        span = min(t_end, PILOT_STEPS * dt0)
        fine = _pilot(name, problem, outputs, span, dt0 / 2, options)
        error = float(np.max(np.abs(coarse - fine))) / (1.0 - 2.0 ** (-order))
        at_end = error * t_end / span
        if not math.isfinite(at_end):
            factor = 0.5
        elif at_end > 0:
            factor = (0.5 * tolerance / at_end) ** (1.0 / order)
        else:
            factor = 8.0
        last = attempt == PILOT_ROUNDS - 1
        step = dt0 * min(2.0 if last else 8.0, max(1.0 / 16.0, factor))
        predicted = at_end * (step / dt0) ** order
        if 0.5 <= factor <= 2.0 or last or step >= t_end:
            break
        try:
            coarse = _pilot(name, problem, outputs, min(t_end, PILOT_STEPS * step), step, options)
        except StepFailure:  # beyond the step the method can take: judge it at the last working step
            step = dt0 * min(factor, 1.0)
            break
        dt0 = step
    return min(step, t_end), predicted


def _rigid_body(problem, t_end: float, samples: int, tolerance: float, outputs, options) -> AutoChoice:
    with_R = needs_attitude(outputs)
    batch = problem.M0.shape[0]
    exact_cost = batch * samples * (EXACT_SAMPLE_US if with_R else EXACT_SAMPLE_M_US)
    floor = batch * samples * LOOP_SAMPLE_US  # no fixed-step run can cost less than its sampling
    if floor >= exact_cost:
        return AutoChoice("exact", None, f"the exact flow ({samples} samples, ~{exact_cost * 1e-6:.2g} s) costs less "
                          "than sampling any time-stepping run", 0.0)
    omega = _frequency(problem)
    dt0 = 0.2 / omega
    span = min(t_end, 200 * dt0)
    exact_M, exact_R = [], []
    for M0, R0 in zip(problem.M0, problem.R0):
        M, R = exact_flow(problem.inertia, M0, R0).state(np.array([span]))
        exact_M.append(M[0])
        exact_R.append(R[0].ravel())
    exact_state = np.concatenate(exact_M + (exact_R if with_R else []))
    best = AutoChoice("exact", None, "the exact flow is the cheapest", 0.0)
    best_cost = exact_cost
    for name in ("lie-poisson-2", "lie-poisson-4", "lie-poisson-6", "lie-poisson-8"):
        method = get_method(name)
        error = float(np.max(np.abs(_pilot(name, problem, outputs, span, dt0, options) - exact_state)))
        growth = t_end / span
        factor = (tolerance / max(error * growth, 1e-300)) ** (1.0 / method.order)
        step = dt0 * min(4.0, 0.5 * factor)
        steps = max(samples - 1, math.ceil(t_end / step))
        substeps = 4 * _stages(method)
        cost = floor + batch * steps * substeps * SUBSTEP_US
        if cost < best_cost:
            best_cost = cost
            best = AutoChoice(name, step, f"{steps} steps of {name} cost less than {samples} exact samples",
                              error * growth * (step / dt0) ** method.order)
    return best


def _richardson_step(name: str, problem, outputs, dt_start: float, t_end: float, tolerance: float,
                     options) -> tuple[float, float]:
    """Step of ``name`` for ``tolerance`` at ``t_end`` and the error it predicts there.

    Richardson's estimate at a pilot step ``h`` gives the step; while that step is more
    than twice ``h`` (the error at ``h`` was near round-off, or far below the tolerance) the
    pilot is repeated there, at most three times.
    """
    method = get_method(name)
    dt0, coarse = _working_step(name, problem, outputs, dt_start, t_end, options)
    step, predicted = dt0, math.inf
    for attempt in range(4):
        span = min(t_end, 64 * dt0)
        fine = _pilot(name, problem, outputs, span, dt0 / 2, options)
        error = float(np.max(np.abs(coarse - fine))) / (1.0 - 2.0 ** (-method.order))
        growth = t_end / span
        factor = (tolerance / (error * growth)) ** (1.0 / method.order) if error * growth > 0 else 8.0
        step = dt0 * min(8.0, 0.5 * factor)
        predicted = error * growth * (step / dt0) ** method.order
        if step <= 2.0 * dt0 or attempt == 3 or not math.isfinite(error):
            break
        dt0 = step
        coarse = _pilot(name, problem, outputs, min(t_end, 64 * dt0), dt0, options)
    return step, predicted


def _heavy_top(problem, t_end: float, tolerance: float, dt: float | None, outputs, options) -> AutoChoice:
    """The heavy top, and a rigid body driven by a torque or impulses: the cheapest of
    :data:`HEAVY_TOP_CANDIDATES` in microseconds (the time scale of the pilot also takes
    the torque's rate ``|N| / |M|`` at the start into account)."""
    scale = 1.0 / _frequency(problem)
    if problem.kind == "heavy_top":
        weight = float(np.linalg.norm(problem.weight_vector))
        if weight > 0:
            scale = min(scale, 1.0 / math.sqrt(weight / float(np.min(problem.inertia))))
    if problem.torque is not None:
        M0, R0 = problem.M0[0], problem.R0[0]
        rate = float(np.linalg.norm(problem.torque.evaluate(M0, R0, 0.0, problem.inertia)))
        size = float(np.linalg.norm(M0))
        if rate > 0 and math.isfinite(rate):
            scale = min(scale, size / rate if size > 0 else 1.0 / math.sqrt(rate / float(np.min(problem.inertia))))
    dt_start = dt if dt is not None else 0.05 * scale
    batch = problem.M0.shape[0]
    best: AutoChoice | None = None
    best_cost = math.inf
    for name in HEAVY_TOP_CANDIDATES:
        step, predicted = _richardson_step(name, problem, outputs, dt_start, t_end, tolerance, options)
        unit = EXACT_KICK_STAGE_US if name.startswith("exact-kick-") else SPLIT_STAGE_US
        cost = batch * math.ceil(t_end / step) * _stages(get_method(name)) * unit
        if cost < best_cost:
            best_cost = cost
            best = AutoChoice(name, step, f"pilot Richardson estimate: {name} with dt = {step:.3g} is the cheapest "
                              f"candidate for tolerance {tolerance:g} (~{cost * 1e-6:.2g} s)", predicted)
    assert best is not None
    return best


def _forced(problem, t_end: float, tolerance: float, dt: float | None, outputs, options) -> AutoChoice:
    """A forced system: the cheapest of ``forced-rattle-2/4`` (and ``conformal-2/4`` for
    linear damping of a constant-mass system), each judged by Richardson's estimate as the
    other general systems, its cost the evaluations per step its pilot measured."""
    candidates = ["forced-rattle-2", "forced-rattle-4"]
    if problem.mechanics.conformal_rate is not None:
        candidates = ["conformal-2", "conformal-4", *candidates]
    dt_start = dt if dt is not None else t_end / 1000.0
    best: AutoChoice | None = None
    best_cost = math.inf
    for name in candidates:
        step, predicted = _richardson_step(name, problem, outputs, dt_start, t_end, tolerance, options)
        stepper = get_method(name).start(problem, outputs, {**options, "planned_steps": 4})
        stepper.step(4, step)
        cost = math.ceil(t_end / step) * max(1.0, stepper.evaluations / 4.0)
        if cost < best_cost:
            best_cost = cost
            best = AutoChoice(name, step, f"pilot Richardson estimate: {name} with dt = {step:.3g} is the cheapest "
                              f"forced method for tolerance {tolerance:g}", predicted)
    assert best is not None
    return best
