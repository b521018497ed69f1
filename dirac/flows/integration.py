"""The one integration loop: sampling, counters, CPU time, progress and guard rails.

:func:`integrate` is the only place that loops over output times. Methods
(:mod:`dirac.flows.methods`) only know how to advance a state; here the loop

* samples the requested outputs at ``samples`` uniformly spaced times in ``[0, t_end]``
  (both ends included; ``samples = 1`` means the final time only), computing only the
  requested outputs and nothing in between;
* adapts a fixed step ``dt`` so that it divides the sample spacing exactly;
* counts steps and vector-field evaluations, and measures the CPU time of the loop after
  the kernels have been compiled (``warm_up``);
* draws a tqdm progress bar when asked;
* stops at the first non-finite state, Newton non-convergence or constraint drift beyond
  ``drift_limit`` with an :class:`IntegrationError` that names the time, the step and the
  method, carrying the samples computed so far (``error.partial``, a :class:`Solution`
  with ``complete = False``). Ctrl-C raises :class:`IntegrationInterrupted` the same way.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, Required, TypedDict

import numpy as np

from dirac.errors import CoordinateSingularityError, InputError, IntegrationError, PoleError
from dirac.flows.chart_guard import GUARD_STEPS, STOP_DISTANCE, ChartGuard, chart_guard
from dirac.flows.energy_watch import EnergyWatch, energy_watch
from dirac.flows.methods.base import Method, StepFailure, Stepper
from dirac.flows.methods.registry import METHODS, driven_method_names, get_method, method_names
from dirac.flows.methods.torqued import refuse_undriven
from dirac.flows.methods.whole_span import (
    ENERGY_TRIGGER,
    MAX_REFINEMENTS,
    ORDER_SLACK,
    coarse_check,
    refined_steps,
    sample_spacing,
    state_vector,
)
from dirac.flows.problems import Problem
from dirac.flows.solution import Solution
from dirac.validate import is_real_number, unknown_name_error, validate_integer, validate_positive

if TYPE_CHECKING:
    from dirac.flows.pole_guard import PoleGuard

__all__ = ["integrate", "sample_times", "IntegrationInterrupted", "problem_kind", "DEFAULT_OUTPUTS", "RunOptions"]


class RunOptions(TypedDict, total=False):
    """The keyword arguments of :func:`integrate` that a scene's ``[run]`` table sets."""

    t_end: Required[float]
    method: str
    dt: float
    samples: int
    outputs: list[str]
    tolerance: float
    drift_limit: float
    newton_tolerance: float
    max_newton_iterations: int

#: Steps per call into a compiled kernel between checks (divided by the batch size).
CHUNK_STEPS = 20_000
#: The constraint drift is measured at least this many steps apart (and at the end):
#: it costs more than a step of the compiled kernels.
DRIFT_CHECK_STEPS = 1_000
#: Fewest steps per call, whatever the batch size.
MIN_CHUNK_STEPS = 100
#: Exact-flow samples evaluated per call.
CHUNK_SAMPLES = 2_000

DEFAULT_OUTPUTS = {
    "rigid_body": ("M", "R", "energy"),
    "heavy_top": ("M", "R", "energy"),
    "constrained": ("q", "p", "energy", "constraint_residual"),
    "analysed": ("z", "energy", "constraint_residual"),
    "forced": ("q", "p", "energy", "work", "constraint_residual"),
}


class IntegrationInterrupted(IntegrationError):
    """The run was interrupted (Ctrl-C, SIGTERM); ``partial`` holds what was computed."""


def problem_kind(problem: object) -> str:
    """The kind the problem declares: ``"rigid_body"``, ``"heavy_top"``, ``"constrained"`` or
    ``"analysed"``.

    Raises
    ------
    InputError
        ``problem`` is not a problem (:class:`dirac.flows.problems.Problem`).
    """
    return _as_problem(problem).kind


def _as_problem(problem: object) -> Problem:
    """``problem``, checked to be a :class:`Problem` of a known kind."""
    if isinstance(problem, Problem) and problem.kind in DEFAULT_OUTPUTS:
        return problem
    raise InputError(
        f"cannot integrate a {type(problem).__name__}: give a RigidBodyProblem, HeavyTopProblem, ConstrainedProblem, "
        "ForcedProblem or AnalysedProblem"
    )


def sample_times(t_end: float, samples: int) -> np.ndarray:
    """``samples`` uniformly spaced times in ``[0, t_end]``, both ends included.

    ``samples = 1`` gives ``[t_end]`` (only the final state is stored).
    """
    if samples == 1:
        return np.array([float(t_end)])
    return np.linspace(0.0, float(t_end), int(samples))


def _validate(t_end: object, samples: object, dt: object, tolerance: object) -> tuple[float, int, float | None, float]:
    end = validate_positive(t_end, "t_end")
    count = validate_integer(samples, "samples", hint="1 stores only the final state")
    step = None if dt is None else validate_positive(dt, "dt")
    if not is_real_number(tolerance) or not (0 < tolerance < 1):
        raise InputError(f"tolerance = {tolerance!r} must be a number in (0, 1)")
    return end, count, step, float(tolerance)


#: Most steps a fixed-step run may take (about a year at 1e8 steps per second); beyond it
#: t_end / dt is a mistake, and near 1e308 it overflows.
MAX_STEPS = 2**62


def _validate_guard_rails(drift_limit: object, newton_tolerance: object, max_newton_iterations: object) -> None:
    """The guard-rail options of :func:`integrate` (the scene reader checks them too)."""
    for name, value in (("drift_limit", drift_limit), ("newton_tolerance", newton_tolerance)):
        if not is_real_number(value) or not value > 0 or math.isnan(value):
            raise InputError(f"{name} = {value!r} must be a number > 0")
    if isinstance(newton_tolerance, float) and not math.isfinite(newton_tolerance):
        raise InputError(f"newton_tolerance = {newton_tolerance!r} must be finite")
    validate_integer(max_newton_iterations, "max_newton_iterations", maximum=10**6)


def _validate_size(samples: int, problem: object) -> None:
    """Refuse a number of samples whose times alone would not fit in this machine's memory."""
    import os

    try:
        memory = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (AttributeError, ValueError, OSError):  # not POSIX: assume 1 TiB
        memory = 2**40
    needed = 8 * samples * (1 + int(getattr(problem, "batch", 1)))  # t and one float per state, at least
    if needed > memory:
        raise InputError(
            f"samples = {samples} needs more than {needed / 2**30:.3g} GiB for the output times alone, more than "
            f"this machine's {memory / 2**30:.3g} GiB; give fewer samples"
        )


def _validate_outputs(outputs: Sequence[str] | None, kind: str, available: Sequence[str]) -> tuple[str, ...]:
    if outputs is None:
        return DEFAULT_OUTPUTS[kind]
    if isinstance(outputs, str):
        outputs = [outputs]
    chosen = tuple(dict.fromkeys(outputs))
    if not chosen:
        raise InputError("outputs is empty: request at least one output, e.g. [\"M\"]")
    for name in chosen:
        if name not in available:
            raise unknown_name_error("output", name, available,
                                     hint=f"these are the outputs of a {kind.replace('_', ' ')} problem")
    return chosen


def integrate(
    problem: object,
    method: str | Method = "auto",
    *,
    t_end: float,
    dt: float | None = None,
    samples: int = 101,
    outputs: Sequence[str] | None = None,
    tolerance: float = 1e-8,
    progress: bool = False,
    drift_limit: float = 1e-6,
    newton_tolerance: float = 1e-12,
    max_newton_iterations: int = 50,
) -> Solution:
    """Integrate ``problem`` with ``method`` and sample the requested outputs.

    Parameters
    ----------
    problem
        A :class:`RigidBodyProblem`, :class:`HeavyTopProblem` or :class:`ConstrainedProblem`
        (initial states may be batched along a leading axis).
    method
        A name from :data:`dirac.flows.methods.registry.METHODS` (``dirac run --help`` lists them)
        or ``"auto"`` (:func:`dirac.flows.methods.auto.choose_method`).
    t_end
        Final time (> 0).
    dt
        Step size of fixed-step methods; reduced to ``spacing / ceil(spacing / dt)`` so
        that it divides the sample spacing.
    samples
        Number of output times, uniformly spaced in ``[0, t_end]`` (both ends); 1 stores
        the final state only.
    outputs
        Names of the outputs to compute and store (default: see ``DEFAULT_OUTPUTS``).
    tolerance
        Target error of ``auto`` and the ``rtol = atol`` of the scipy baselines.
    progress
        Draw a tqdm progress bar on stderr.
    drift_limit
        Stop when a structural constraint (``R^T R = 1``; holonomic constraints and their
        time derivatives) is violated by more than this.
    newton_tolerance
        Tolerance of the Newton iterations of ``rattle-*`` and ``midpoint``.
    max_newton_iterations
        Newton iterations per step before the step is declared failed.

    Returns
    -------
    Solution

    Raises
    ------
    InputError
        Bad arguments (named in the message).
    IntegrationError
        The run had to stop; ``error.partial`` is the :class:`Solution` so far
        (``complete = False``). :class:`IntegrationInterrupted` on Ctrl-C.
    """
    t_end, samples, dt, tolerance = _validate(t_end, samples, dt, tolerance)
    _validate_guard_rails(drift_limit, newton_tolerance, max_newton_iterations)
    _validate_size(samples, problem)
    checked = _as_problem(problem)
    kind = checked.kind
    chosen_outputs = _validate_outputs(outputs, kind, checked.outputs)
    late = [impulse.t for impulse in getattr(checked, "impulses", ()) if impulse.t > t_end] if kind == "forced" else []
    if late:
        from dirac.errors import warn

        warn(f"impulses at t = {', '.join(f'{t:g}' for t in late)} come after t_end = {t_end:g}: they are not applied")
    return _integrate_checked(checked, method, kind, chosen_outputs, t_end, samples, dt, tolerance, progress,
                              drift_limit, newton_tolerance, max_newton_iterations)


#: what a run that left the real domain of the system's expressions can do
DOMAIN_HINT = ("a square root or logarithm of a negative number, a division by zero, or an overflow; start inside "
               "the domain of the Lagrangian (and forces), or reduce dt if a step jumped out of it")


def is_domain_error(exc: BaseException) -> bool:
    """Whether ``exc`` is an evaluation outside the real domain of an expression.

    The interpreted kernels raise Python's own errors there: ``ValueError('math domain
    error')`` (``math.sqrt(-1)``, ``math.log(0)``), ``ZeroDivisionError``, ``OverflowError``
    and numpy's ``FloatingPointError`` (all :class:`ArithmeticError`); any other
    ``ValueError`` is not one.
    """
    return isinstance(exc, ArithmeticError) or (isinstance(exc, ValueError) and str(exc) == "math domain error")


def _integrate_checked(checked, method, kind, chosen_outputs, t_end, samples, dt, tolerance, progress, drift_limit,
                       newton_tolerance, max_newton_iterations) -> Solution:
    """:func:`integrate` after its arguments are checked: the method chosen and started, the loop run."""
    extra: dict[str, Any] = {}
    if (isinstance(method, str) and method == "auto"):
        from dirac.flows.methods.auto import choose_method

        try:
            choice = choose_method(checked, kind, t_end=t_end, samples=samples, tolerance=tolerance, dt=dt,
                                   outputs=chosen_outputs)
        except (ArithmeticError, ValueError) as exc:
            if not is_domain_error(exc):
                raise
            raise IntegrationError(
                f"method auto: a trial run left the real domain of the system's expressions ({exc}): {DOMAIN_HINT}; "
                "or choose a method and dt"
            ) from None
        method_object, dt = get_method(choice.method), choice.dt
        extra["auto"] = {"chosen": choice.method, "reason": choice.reason, "estimated_error": choice.estimated_error}
        if choice.newton_tolerance is not None and choice.newton_tolerance < newton_tolerance:
            # the Newton floor must lie below the error auto promises (auto.newton_tolerance_for)
            newton_tolerance = choice.newton_tolerance
            extra["auto"]["newton_tolerance"] = newton_tolerance
    else:
        method_object = get_method(method)
    if not method_object.accepts(kind):
        usable = [m for m in _names_for(kind)]
        what = ("a system with forces or impulses (these methods take them)" if kind == "forced"
                else f"a {kind.replace('_', ' ')} problem")
        raise InputError(
            f"method {method_object.name!r} cannot integrate {what}; use one of: {', '.join(usable)}"
        )
    refuse_undriven(checked, method_object.name, driven_method_names(kind))
    if method_object.kind == "fixed" and dt is None:
        raise InputError(f"method {method_object.name!r} takes fixed steps: give dt (the step size)")
    if dt is not None and method_object.kind == "fixed" and not t_end / dt <= MAX_STEPS:
        raise InputError(
            f"t_end / dt = {t_end:.3g} / {dt:.3g} is more than {MAX_STEPS:.3g} steps; give a larger dt or a shorter t_end"
        )
    if method_object.kind != "fixed":
        dt = None
    options = {
        "t_end": t_end,
        "tolerance": tolerance,
        "newton_tolerance": float(newton_tolerance),
        "max_newton_iterations": int(max_newton_iterations),
    }

    def run(step: float | None, record: bool, extra: dict[str, Any]) -> tuple[_Loop, Solution]:
        # steps the run will take (all members of a batch): generated kernels run
        # interpreted for short runs and compile when that pays (dirac.codegen.tiers)
        planned = (int(math.ceil(t_end / step * (1.0 - 1e-12))) * int(getattr(checked, "batch", 1))
                   if step is not None else None)
        try:
            stepper = method_object.start(checked, chosen_outputs, {**options, "planned_steps": planned})
            stepper.warm_up()
            if stepper.kind != "exact":
                stepper.observe()  # compiles what the outputs need before the timed loop
        except (ArithmeticError, ValueError) as exc:
            if not is_domain_error(exc):
                raise
            raise IntegrationError(
                f"the system's expressions have no real value at the initial state ({exc}): {DOMAIN_HINT}"
            ) from None
        loop = _Loop(checked, method_object, stepper, chosen_outputs, t_end, samples, step, progress, drift_limit,
                     extra, record)
        return loop, loop.run()

    if "auto" not in extra or kind not in ("constrained", "analysed") or method_object.kind != "fixed":
        return run(dt, False, extra)[1]
    return _checked_over_the_whole_span(run, dt, method_object, checked, chosen_outputs, options, t_end, samples,
                                        tolerance, extra)


def _checked_over_the_whole_span(run, dt: float | None, method_object: Method, checked, chosen_outputs, options, t_end: float,
                                 samples: int, tolerance: float, extra: dict[str, Any]) -> Solution:
    """A run of ``auto`` on a constrained or analysed system, its error estimated over the whole
    span by Richardson's rule and the run made again with a smaller step while the estimate exceeds
    ``tolerance`` (:mod:`dirac.flows.methods.whole_span`); the estimate, the refinements and the
    step are recorded in ``meta()["auto"]``; a run that still misses after
    :data:`~dirac.flows.methods.whole_span.MAX_REFINEMENTS` refinements warns."""
    from dirac.errors import warn

    times = sample_times(t_end, samples)
    loop, solution = run(dt, True, dict(extra, auto=dict(extra["auto"])))
    assert loop.states is not None and loop.per_interval is not None
    record = solution.extra["auto"]
    if loop.energy is not None:  # a conservative system: what its energy shows decides whether to check
        bound = loop.energy.shown_error()
        record["energy_error_bound"] = bound
        if bound <= ENERGY_TRIGGER * tolerance:
            record["whole_span_error"] = None
            record["refinements"] = 0
            record["whole_span_note"] = (f"not checked: the energy shows an error of {bound:.2g} at most to first order, "
                                         f"below {ENERGY_TRIGGER:g} of the tolerance")
            return solution
    check = coarse_check(method_object, checked, chosen_outputs, options, times, loop.per_interval, loop.states)
    refinements = 0
    order = method_object.order or 1
    erratic = ""  # a refinement whose error did not shrink as the order predicts
    while check.error is not None and check.error > tolerance and refinements < MAX_REFINEMENTS:
        per_interval = refined_steps(loop.per_interval, check.error, tolerance, order)
        predicted = check.error * (loop.per_interval / per_interval) ** order
        loop, solution = run(sample_spacing(times) / per_interval, True, dict(extra, auto=dict(extra["auto"])))
        assert loop.states is not None and loop.per_interval is not None
        # the refined run is checked as the first was (at about twice its step), not by Richardson's rule
        # between the two runs: that extrapolates by r^p over the ratio r of their steps, past an error that
        # does not shrink with the step (round-off grown by chaotic motion) to a figure far below it
        check = coarse_check(method_object, checked, chosen_outputs, options, times, loop.per_interval, loop.states)
        refinements += 1
        if check.error is not None and check.error > ORDER_SLACK * predicted and not erratic:
            erratic = (f"{predicted:.2g} expected after refinement {refinements}, {check.error:.2g} estimated: the error did "
                       f"not shrink as the order {order} of {method_object.name} predicts")
    record = solution.extra["auto"]
    record["whole_span_error"] = check.error
    record["refinements"] = refinements
    if refinements:
        record["refined_dt"] = solution.dt
        if loop.energy is not None:  # of the run whose samples the solution holds
            record["energy_error_bound"] = loop.energy.shown_error()
    if check.error is None:
        record["whole_span_note"] = check.why
    elif check.error > tolerance or erratic:
        what = (f"is {check.error:.2g}, above the tolerance {tolerance:g}" if not erratic else
                f"is {check.error:.2g}, but that estimate may be far too small ({erratic}; round-off grown by the "
                "motion does not shrink with the step)")
        text = (f"method auto: the error of the run of {str(checked.system)!r} with {method_object.name} at dt = "
                f"{solution.dt:.3g}, estimated over the whole span after {refinements} refinement(s) (Richardson's "
                f"rule against a run of steps {check.ratio:.3g} times as long), {what}: the motion may be chaotic (its "
                "error then grows exponentially with time) or pass close to a singularity of the coordinates; compare "
                "runs at two tolerances")
        record["whole_span_warning"] = text
        warn(text)
    return solution


def _names_for(kind: str) -> list[str]:
    return ["auto"] + [n for n in method_names() if n in METHODS and METHODS[n].accepts(kind)]


class _NoBar:
    """What the loop uses of a tqdm bar, doing nothing (``progress=False``)."""

    def update(self, n: int = 1) -> None:
        """Nothing to draw."""

    def close(self) -> None:
        """Nothing to close."""


class _Loop:
    """One run of the loop (keeps the bookkeeping out of :func:`integrate`)."""

    def __init__(self, problem: Problem, method: Method, stepper: Stepper, outputs, t_end, samples, dt, progress,
                 drift_limit, extra, record: bool = False) -> None:
        self.problem = problem
        self.method = method
        self.stepper = stepper
        self.outputs = outputs
        self.times = sample_times(t_end, samples)
        self.t_end = t_end
        self.dt = dt
        self.progress = progress
        self.drift_limit = float(drift_limit)
        self.extra = extra
        self.store: dict[str, np.ndarray] = {}
        self.stored = 0
        self.t_now = 0.0
        self.cpu = 0.0
        self._checked_at = 0
        self.energy: EnergyWatch | None = None
        #: the whole state at each sample kept (``record``: the check of auto's run over its span)
        self.states: list[np.ndarray] | None = [] if record else None
        #: steps per sample interval of a fixed-step run (set by :meth:`_intervals`)
        self.per_interval: int | None = None

    # ------------------------------------------------------------------ storage
    def _keep(self, index: int, values: dict[str, np.ndarray]) -> None:
        for name in self.outputs:
            value = np.asarray(values[name])
            if name not in self.store:
                self.store[name] = np.empty((len(self.times),) + value.shape, dtype=float)
            self.store[name][index] = value
        self.stored = index + 1
        if self.states is not None:
            self.states.append(state_vector(self.stepper))

    def _solution(self, complete: bool, message: str = "") -> Solution:
        """The samples kept so far; ``message`` says why the run stopped, or what a complete run warned."""
        n = self.stored
        outputs = {}
        for name in self.outputs:
            array = self.store.get(name)
            if array is None:
                continue
            array = array[:n]
            if not self.problem.batched:
                array = array[:, 0]
            outputs[name] = np.ascontiguousarray(array)
        extra = dict(self.extra)
        if not complete:
            extra["t_reached"] = self.t_now
        return Solution(
            t=self.times[:n].copy(),
            outputs=outputs,
            system=str(self.problem.system),
            method=self.method.name,
            order=self.method.order,
            dt=self.dt,
            steps=int(self.stepper.steps),
            evaluations=int(self.stepper.evaluations),
            cpu_seconds=self.cpu,
            complete=complete,
            message=message,
            parameters=self.problem.parameters(),
            extra=extra,
        )

    def _where(self) -> str:
        return f"at t = {self.t_now:.6g} (step {self.stepper.steps}) with method {self.method.name}"

    def _check(self, final: bool = False) -> None:
        if not self.stepper.finite():
            raise _Stop(f"non-finite values (inf or nan) appeared in the state {self._where()}; reduce dt or check the initial data")
        if not final and self.stepper.steps - self._checked_at < DRIFT_CHECK_STEPS:
            return
        self._checked_at = self.stepper.steps
        drift = self.stepper.drift()
        if not drift <= self.drift_limit:
            raise _Stop(
                f"constraint drift {drift:.3g} exceeds the limit {self.drift_limit:.3g} {self._where()}; "
                "reduce dt, tighten the Newton tolerance, or raise drift_limit"
            )

    # ------------------------------------------------------------------ the loop
    def run(self) -> Solution:
        kind = self.stepper.kind
        intervals = self._intervals() if kind == "fixed" else []
        total = sum(n for _, _, n in intervals) if kind == "fixed" else len(self.times)
        bar: Any
        if self.progress:
            from tqdm import tqdm

            bar = tqdm(total=total, unit=("step" if kind == "fixed" else "sample"), file=sys.stderr, leave=False,
                       dynamic_ncols=True, desc=self.method.name)
        else:  # no bar asked: tqdm is not imported (a few hundredths of a second of every fresh run)
            bar = _NoBar()
        start = time.process_time()
        try:
            if kind != "exact":
                self.energy = energy_watch(self.problem, self.stepper)
                self._watch_energy(None)
            if kind == "exact":
                self._run_exact(bar)
            elif kind == "fixed":
                self._run_fixed(bar, intervals)
            else:
                self._run_adaptive(bar)
        except _Pole as stop:
            self.cpu = time.process_time() - start
            raise PoleError(str(stop), partial=self._solution(False, str(stop))) from None
        except _Singular as stop:
            self.cpu = time.process_time() - start
            raise CoordinateSingularityError(str(stop), partial=self._solution(False, str(stop))) from None
        except _Stop as stop:
            self.cpu = time.process_time() - start
            raise IntegrationError(str(stop), partial=self._solution(False, str(stop))) from None
        except StepFailure as failure:
            self.cpu = time.process_time() - start
            message = f"{failure} {self._where()}"
            raise IntegrationError(message, partial=self._solution(False, message)) from None
        except (ArithmeticError, ValueError) as exc:
            if not is_domain_error(exc):
                raise
            self.cpu = time.process_time() - start
            # the loop's time is that of the last finished call: the step that failed is in the call after it
            message = (f"a step left the real domain of the system's expressions ({exc}) in the steps after "
                       f"t = {self.t_now:.6g} (step {self.stepper.steps}) with method {self.method.name}: {DOMAIN_HINT}")
            raise IntegrationError(message, partial=self._solution(False, message)) from None
        except KeyboardInterrupt:
            self.cpu = time.process_time() - start
            message = f"interrupted {self._where()}"
            raise IntegrationInterrupted(message, partial=self._solution(False, message)) from None
        finally:
            bar.close()
        self.cpu = time.process_time() - start
        return self._solution(True, self._energy_report())

    def _watch_energy(self, values: dict[str, np.ndarray] | None) -> None:
        """Read the energy of a conservative run at a sample (``values``: the sample's outputs; None at the
        start, before the first step)."""
        if self.energy is not None:
            energy = None if values is None else values.get("energy")
            self.energy.read(self.stepper, self.t_now, None if energy is None else np.atleast_1d(energy))

    def _energy_report(self) -> str:
        """Warn when the run changed the energy of a conservative system by a finite amount
        (:mod:`dirac.flows.energy_watch`); the text is also the solution's message."""
        if self.energy is None:
            return ""
        text = self.energy.report(str(self.problem.system), self.method.name, self.method.order, self.dt,
                                  self.problem.batched, chosen="auto" in self.extra)
        if text is None:
            return ""
        from dirac.errors import warn

        self.extra["energy_change"] = self.energy.extra()
        warn(text)
        return text

    def _intervals(self) -> list[tuple[float, float, int]]:
        """(start, end, steps) of each sampling interval (one for ``samples = 1``); sets
        ``self.dt`` to the step that divides the spacing."""
        starts = np.concatenate([[0.0], self.times[:-1]]) if self.times[0] != 0.0 else self.times[:-1]
        ends = self.times if self.times[0] != 0.0 else self.times[1:]
        spacing = float(ends[0] - starts[0])
        per_interval = max(1, int(math.ceil(spacing / self.dt * (1.0 - 1e-12))))
        self.dt = spacing / per_interval
        self.per_interval = per_interval
        return [(float(a), float(b), per_interval) for a, b in zip(starts, ends)]

    def _run_fixed(self, bar, intervals: list[tuple[float, float, int]]) -> None:
        if self.times[0] == 0.0:
            self._keep(0, self.stepper.observe())
        first = 1 if self.times[0] == 0.0 else 0
        batch = self.problem.batch
        # at least MIN_CHUNK_STEPS steps per call, so that large batches are not advanced
        # (and checked) one step at a time
        chunk = max(MIN_CHUNK_STEPS, CHUNK_STEPS // max(1, batch))
        guard = self._chart_guard()
        poles = self._pole_guard()
        limit = chunk
        if guard is not None or poles is not None:
            # near a coordinate singularity or a pole the guards are read often (dirac.flows.chart_guard, .pole_guard)
            chunk = min(chunk, GUARD_STEPS)
        if poles is not None:
            self._read_poles(poles, 0, start=True)
        dt = float(self.dt)
        for index, (a, _b, n_steps) in enumerate(intervals):
            done = 0
            while done < n_steps:
                n = min(chunk, n_steps - done)
                try:
                    self.stepper.step(n, dt)
                except StepFailure as failure:
                    self.t_now = a + (done + failure.steps_done) * dt
                    self._pole_at_failure(poles, failure.steps_done)
                    self._near_singularity(guard)
                    raise
                done += n
                self.t_now = a + done * dt
                if poles is not None:  # a chunk never spans a sample: a crossing is found before the sample is kept
                    chunk = min(limit, self._read_poles(poles, n))
                if guard is not None:
                    chunk = min(limit if poles is None else chunk, self._near_singularity(guard, n))
                self._check()
                bar.update(n)
            self.t_now = float(self.times[first + index])
            if hasattr(self.stepper, "time"):  # the state's time is the sample's, not a sum of steps that drifts
                self.stepper.time = self.t_now
            if index == len(intervals) - 1:
                self._check(final=True)
            values = self.stepper.observe()
            self._keep(first + index, values)
            self._watch_energy(values)

    def _chart_guard(self) -> ChartGuard | None:
        """The coordinate-singularity guard of a constrained system's stepper, if its ``det W`` can vanish."""
        mechanics = getattr(self.problem, "mechanics", None)
        if mechanics is None or not hasattr(self.stepper, "q") or not hasattr(mechanics, "symbolic"):
            return None
        return chart_guard(mechanics)

    def _pole_guard(self) -> PoleGuard | None:
        """The pole guard of a constrained or an analysed system's stepper, if its equations of motion have
        denominators that can vanish."""
        analysed = getattr(self.problem, "analysed", None)
        if analysed is not None and hasattr(self.stepper, "z") and hasattr(analysed, "analysis"):
            from dirac.flows.pole_guard import analysed_pole_guard  # read at the whole state z

            return analysed_pole_guard(analysed)
        mechanics = getattr(self.problem, "mechanics", None)
        if mechanics is None or not hasattr(self.stepper, "q") or not hasattr(mechanics, "symbolic"):
            return None
        from dirac.flows.pole_guard import pole_guard  # only runs of a mechanical system need it

        return pole_guard(mechanics)

    def _read_poles(self, poles: PoleGuard, steps: int, start: bool = False) -> int:
        """Stop at or across a pole of the equations of motion; else the steps until the guard is read again."""
        from dirac.flows.pole_guard import PoleCrossing
        from dirac.flows.pole_guard import message as pole_message

        q, t = getattr(self.stepper, poles.state), getattr(self.stepper, "time", self.t_now)
        try:
            if start:
                poles.start(q, t, self.stepper.steps)
                return GUARD_STEPS
            following = poles.check(q, t, self.stepper.steps, steps, at=self.t_now)
        except PoleCrossing as crossing:
            if not crossing.turn and poles.state == "q":
                crossing = self._barrier(poles, crossing, np.array(q, dtype=float), t)
            raise _Pole(pole_message(str(self.problem.system), crossing, self.method.name)) from None
        return following

    def _barrier(self, poles: PoleGuard, crossing: Any, q: np.ndarray, t: float) -> Any:
        """A crossing hedged when the potential rises above the energy of the start on the step's way to the pole.

        The exact motion of a conservative system keeps ``V(q) <= E``; where ``V`` exceeds ``E`` between the
        state before the crossing and the pole (``V = -1/x + 0.01/x^2``: ``V -> +inf`` at ``x = 0``), that motion
        cannot have come there along the step, and a turn before the pole that a smaller step resolves is likely
        (``rattle-4`` at ``dt = 1e-3`` jumps the pass at ``x_min = 1/99`` from ``x = 0.01`` to ``x = -0.025``).
        The step's chord from the last reading, cut at the factor's zero by bisection, is sampled at ``10^-k``
        of its length before that zero, ``k = 1 .. 6``. Hedged only (the exact path is not the chord).
        """
        from dirac.flows.pole_guard import barrier_before

        if self.energy is None or self.energy.first is None:
            return crossing
        found = barrier_before(poles, getattr(self.problem, "mechanics"), q, t, self.energy.first)  # noqa: B009
        if found is None:
            return crossing
        return type(crossing)(f"{crossing}; the potential on the step's way there rose to V = {found[0]:.3g}, above "
                              f"the energy of the start E = {found[1]:.6g}", turn=True)

    def _pole_at_failure(self, poles: PoleGuard | None, steps: int) -> None:
        """After a failed step: stop with the pole when the state is across it, or when the last readings had it
        within a few steps (a Newton iteration fails next to a pole, where the force is unbounded)."""
        if poles is None:
            return
        from dirac.flows.pole_guard import COLLAPSE_EXPONENT, READINGS_PER_APPROACH, PoleCrossing
        from dirac.flows.pole_guard import message as pole_message

        if steps > 0:  # a new state since the last reading: read it (and the rate); else the last prediction stands
            self._read_poles(poles, steps)
        if poles.steps_to_pole <= READINGS_PER_APPROACH:
            where = f"{poles.nearest()}, reached within about {max(poles.steps_to_pole, 1.0):.0f} more steps at the rate " \
                    "of the last steps"
        elif poles.steps_to_collapse <= READINGS_PER_APPROACH:
            # the rate of the last steps is a secant, which lags a fall that speeds up toward the pole (V = -1/x from
            # x = 1 at rest, midpoint, dt = 0.01: the Newton iteration failed at t = 1.1, x = 0.078, 1.07 steps before
            # t* = pi/(2 sqrt 2) by hand; the fall as (t* - t)^(2/3) gave 1.17 steps, the secant over the 10 steps
            # since the reading before 2.85)
            where = (f"{poles.nearest(collapsing=True)}, reached within about {max(poles.steps_to_collapse, 1.0):.0f} "
                     f"more steps if it falls as (t* - t)^{COLLAPSE_EXPONENT:.2g}, as into a 1/r pole")
        else:
            return
        # hedged: a failed step next to a pole does not tell a fall into it from a close pass that a smaller step
        # resolves (V = -1/x + 0.01/x**2 from x = 1 at rest turns at x = 0.0101, by hand; midpoint failed at x = 0.053
        # with dt = 0.01, "within about 2 more steps" of x = 0, and completes with dt = 1e-4)
        crossing = PoleCrossing(f"a step failed at t = {self.t_now:.6g} (step {self.stepper.steps}) next to a pole of "
                                f"the equations of motion ({where})", turn=True)
        raise _Pole(pole_message(str(self.problem.system), crossing, self.method.name))

    def _near_singularity(self, guard: ChartGuard | None, steps: int = GUARD_STEPS) -> int:
        """Stop near a coordinate singularity; else the steps until the guard is read again (1 when close)."""
        if guard is None:
            return GUARD_STEPS
        distance = guard.distance(getattr(self.stepper, "q"), getattr(self.stepper, "time", 0.0))  # noqa: B009 (a constrained stepper)
        if distance < STOP_DISTANCE:
            raise _Singular(guard.message(str(self.problem.system), distance, self._where()))
        return guard.next_reading(distance, steps)

    def _run_adaptive(self, bar) -> None:
        for index, t in enumerate(self.times):
            if t > 0.0:
                self.stepper.advance_to(float(t))
                self.t_now = float(t)
                self._check(final=index == len(self.times) - 1)
            values = self.stepper.observe()
            self._keep(index, values)
            if t > 0.0:
                self._watch_energy(values)
            bar.update(1)

    def _run_exact(self, bar) -> None:
        for begin in range(0, len(self.times), CHUNK_SAMPLES):
            chunk = self.times[begin : begin + CHUNK_SAMPLES]
            values = self.stepper.evaluate(chunk)
            for name in self.outputs:
                array = np.asarray(values[name])
                if name not in self.store:
                    self.store[name] = np.empty((len(self.times),) + array.shape[1:], dtype=float)
                self.store[name][begin : begin + len(chunk)] = array
            self.stored = begin + len(chunk)
            self.t_now = float(chunk[-1])
            if not all(np.all(np.isfinite(values[name])) for name in self.outputs):
                raise _Stop(f"non-finite values (inf or nan) in the exact solution {self._where()}")
            bar.update(len(chunk))


class _Stop(Exception):
    """A guard rail fired (internal; becomes an IntegrationError)."""


class _Pole(_Stop):
    """The motion reached or stepped across a pole of its equations of motion (internal; becomes a PoleError)."""


class _Singular(_Stop):
    """The run came near a coordinate singularity (internal; becomes a CoordinateSingularityError)."""
