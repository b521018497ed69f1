"""The error of a run chosen by ``auto``, estimated over the whole span after the run.

``auto`` chooses a method and a step from short pilots at the start of the run
(:mod:`dirac.flows.methods.auto`): the error they measure grows as they saw it grow over
``t_end / 32``. A motion that changes later (a spherical pendulum in its angles passing near
the pole ``theta = 0``, a top in Euler angles, a bead on a parabola through the vertex) makes that estimate far too small: the spherical pendulum from ``theta = 1``,
``p_phi = 0.5`` run to ``t = 1`` with ``tolerance = 1e-8`` ended with an error of 4.1e-6
where the pilots predicted 1.6e-10.

So the run is checked over its whole span after it ends: the same method is run again with
about twice the step (``m_c = floor(m / 2)`` steps of ``H = spacing / m_c`` in each sample
interval of ``m`` steps ``h``; one step of ``2 h`` per two intervals when ``m = 1``), and at
the samples where both runs are, Richardson's estimate of the error of the fine run is

    e(h) = max |z_H - z_h| / (r^p - 1),    r = H / h,

for a method of order ``p`` (Hairer, Norsett & Wanner, *Solving Ordinary Differential
Equations I*, 2nd ed., Springer 1993, Sect. II.4: the global error of a method of order ``p``
is ``C(t) h^p + O(h^(p+1))``). Where ``e(h)`` exceeds the tolerance the run is made again with
the step the estimate asks for (:func:`refined_steps`), and that run is checked the same way.
The check costs one run at about twice the step (about half the run's steps) where it runs,
and nothing more unless the run missed.

A refined run's estimate should be about what the order predicts from the run before it,
``e (h' / h)^p``; where it is more than :data:`ORDER_SLACK` times that, the error does not follow
the order (round-off grown by chaotic motion, which no step removes), and the run warns that its
estimate may be far too small, whatever that estimate is. (Richardson's rule between the two
runs themselves would extrapolate by ``r^p`` over their ratio of steps ``r``, past such an error,
to a figure far below it.)

The check is not run where the run's energy shows it is not needed: a conservative system's
exact motion keeps ``H``, and the run's largest change of ``H`` over ``|grad H|_1`` there is, to
first order, a lower bound of its error
(:meth:`~dirac.flows.energy_watch.EnergyWatch.shown_error`). Every run that missed its
tolerance above showed more than a hundredth of the tolerance that way (from 3.7e-10 to 2.3e-7
at ``tolerance = 1e-8``; eight runs, ``t_end = 1`` and ``10``, of five everyday systems), and the
long runs that met it far less (1e-13 to 1e-11 for the pendulums of the latency corpus at
``t_end = 100``): the check runs above :data:`ENERGY_TRIGGER` times the tolerance. A run whose
error is all in its phase (its energy kept) is then not checked; systems whose energy is not
conserved always are.

The estimate holds in the asymptotic regime of both runs; outside it (a coarse run whose step
no longer resolves the motion) it is pessimistic, and the run is refined once more than
needed. Chaotic motion makes every estimate grow with the span: a run that still misses after
:data:`MAX_REFINEMENTS` refinements says so in a warning.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from dirac.flows.methods.base import Method, StepFailure

__all__ = ["ENERGY_TRIGGER", "MAX_REFINEMENTS", "ORDER_SLACK", "WholeSpanCheck", "coarse_check", "refined_steps", "sample_spacing", "state_vector"]

#: runs made again after the first when the estimate exceeds the tolerance
MAX_REFINEMENTS = 2
#: a refined run aims at this fraction of the tolerance (as auto's confirmed step does)
REFINE_SAFETY = 0.1
#: a refined run whose estimate exceeds this many times what the order predicts from the run before
#: it (``e (h' / h)^p``) has an error that does not follow the order: its estimate is not trusted. On
#: five regular motions the estimates came within 1.4 times the prediction; on a double pendulum
#: released from large angles (chaotic), at ``t = 10``, 34 times
ORDER_SLACK = 4.0
#: a conservative system's run is checked when its energy shows an error above this fraction
#: of the tolerance (:meth:`~dirac.flows.energy_watch.EnergyWatch.shown_error`); below it the check is not run
ENERGY_TRIGGER = 0.01


def state_vector(stepper: Any) -> np.ndarray:
    """The whole state of a stepper's batch as one vector: ``(q, p)`` of the constrained
    steppers, ``z`` of the analysed ones, ``(M, R)`` of the rigid-body ones."""
    if hasattr(stepper, "analysed"):
        return np.asarray(stepper.z, dtype=float).ravel().copy()
    if hasattr(stepper, "q"):
        return np.concatenate([np.asarray(stepper.q, dtype=float).ravel(), np.asarray(stepper.p, dtype=float).ravel()])
    parts = [stepper.M.ravel()]
    if stepper.with_R:
        parts.append(stepper.R.ravel())
    return np.concatenate(parts)


@dataclass(frozen=True)
class WholeSpanCheck:
    """Richardson's estimate of a run's error over its whole span.

    Attributes
    ----------
    error : float or None
        ``max |z_H - z_h| / (r^p - 1)`` over the samples both runs share; None when no
        comparison could be made (``why`` says why).
    ratio : float
        ``r = H / h``, the ratio of the steps compared.
    compared : int
        The samples compared.
    why : str
        Why there is no estimate, else empty.
    """

    error: float | None
    ratio: float
    compared: int
    why: str = ""


def sample_spacing(times: np.ndarray) -> float:
    """The spacing of the sample times of a run (the first at ``0``, or at the first spacing)."""
    return float(times[1] - times[0]) if times[0] == 0.0 else float(times[0])


def coarse_check(method: Method, problem: Any, outputs: tuple[str, ...], options: dict, times: np.ndarray,
                 per_interval: int, fine_states: Sequence[np.ndarray]) -> WholeSpanCheck:
    """The estimate of a run of ``per_interval`` steps per sample interval (its states
    ``fine_states`` at ``times``, the first at ``0`` when ``times[0] == 0``) from a run of
    about twice the step (see the module docstring)."""
    starts_at_zero = bool(times[0] == 0.0)
    ends = times[1:] if starts_at_zero else times
    spacing = sample_spacing(times)
    states = list(fine_states[1:]) if starts_at_zero else list(fine_states)
    if per_interval >= 2:
        coarse, every = per_interval // 2, 1
        ratio = per_interval / coarse
    elif len(ends) >= 2:  # one step per interval: one step of 2 h per two intervals
        coarse, every, ratio = 1, 2, 2.0
    else:
        return WholeSpanCheck(None, 1.0, 0, "one step over the whole span: nothing coarser to compare with")
    planned = coarse * len(ends) // every
    stepper = method.start(problem, outputs, {**options, "planned_steps": planned})
    worst = 0.0
    compared = 0
    try:
        for index in range(every - 1, len(ends), every):
            stepper.step(coarse, spacing * every / coarse)
            if hasattr(stepper, "time"):  # the sample's time, as the run's loop sets it
                stepper.time = float(ends[index])
            difference = np.max(np.abs(state_vector(stepper) - states[index]))
            if not math.isfinite(float(difference)):
                return WholeSpanCheck(None, ratio, compared, f"the run at about twice the step left the finite "
                                      f"numbers at t = {float(ends[index]):.6g}")
            worst = max(worst, float(difference))
            compared += 1
    except StepFailure as failure:
        return WholeSpanCheck(None, ratio, compared, f"the run at about twice the step failed ({failure})")
    except (ArithmeticError, ValueError) as error:  # a coarser step that left the domain of the expressions
        return WholeSpanCheck(None, ratio, compared, f"the run at about twice the step left the real domain of the "
                              f"system's expressions ({error})")
    return WholeSpanCheck(worst / (ratio ** method.order - 1.0), ratio, compared)


def refined_steps(per_interval: int, error: float, tolerance: float, order: int) -> int:
    """Steps per sample interval for ``REFINE_SAFETY * tolerance``: ``m (e / (s tol))^(1/p)``,
    rounded up, at least ``3 m / 2`` and at most ``16 m``."""
    factor = (error / (REFINE_SAFETY * tolerance)) ** (1.0 / order) if error > 0 else 1.0
    return int(math.ceil(per_interval * min(16.0, max(1.5, factor))))
