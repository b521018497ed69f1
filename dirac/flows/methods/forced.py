"""Methods of forced systems: generalized forces ``Q(q, q_dot, t)`` and impulses.

* ``forced-rattle-2``: RATTLE with the discrete Lagrange–d'Alembert forces (Marsden &
  West, "Discrete mechanics and variational integrators", Acta Numerica 10 (2001),
  Sect. 3.2), symmetric and of order 2; ``forced-rattle-4`` its symmetric composition
  (the coefficients of :data:`dirac.compositions.COMPOSITIONS`), order 4. Any force
  ``Q(q, q_dot, t)``, any mass ``M(q, t)``.
* ``conformal-2``: for linear damping ``Q = -gamma M q_dot`` of a constant-mass system
  (``p_dot = -dH/dq - gamma p``), the conformal-symplectic splitting of McLachlan &
  Perlmutter ("Conformal Hamiltonian systems", J. Geom. Phys. 39 (2001)): the exact damping
  flow for half a step, RATTLE, the damping again. The symplectic form on the constraint
  manifold contracts by exactly ``exp(-gamma t)``, as along the exact flow.
  ``conformal-4`` is its symmetric composition, order 4.

The step loops are generated per system (:mod:`dirac.codegen.forced_source`). Impulses
(:class:`dirac.flows.problems.Impulse`) are applied between steps: a step is cut so that
one ends on each impulse time, ``p`` jumps by the projected impulse
(:meth:`~dirac.flows.mechanics.MechanicalSystem.apply_impulse`) and the run goes on with
the remainder of the cut step, so the steps return to the run's grid. The output
``work`` is ``W(t) = int_0^t Q . q_dot dt`` plus the work of the impulses, so that
``energy - work`` is conserved along the exact motion (Lamb's energy balance
``dT/dt = sum_r Q_r q_dot_r`` with the potential moved to the left).
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple, cast

import numpy as np

from dirac.compositions import COMPOSITIONS
from dirac.errors import InputError
from dirac.flows.dirac_field import constrained_outputs
from dirac.flows.methods.base import Method, Stepper
from dirac.flows.methods.constrained_stepper import ConstrainedStepper, singular_as_step_failure, tiered

__all__ = ["ForcedStepper", "METHODS", "FORCED_METHOD_NAMES", "Advance", "Kick", "plan_call"]

#: a cut of a step shorter than this fraction of the step is no cut (the impulse is on the grid)
_GRID_SLACK = 1e-9


class Advance(NamedTuple):
    """``steps`` steps of size ``size`` from the time ``base`` (the kernel's step times are
    ``base + k size``), then ``adjust`` added to the step count (the pieces of a cut step
    count as one step of the grid)."""

    base: float
    steps: int
    size: float
    adjust: int = 0


class Kick(NamedTuple):
    """The impulse ``impulse`` (an index into the times given to :func:`plan_call`) acting at ``time``."""

    impulse: int
    time: float


def plan_call(start: float, n_steps: int, dt: float, times: list[float]) -> tuple[list[Advance | Kick], int]:
    """The pieces of one call ``step(n_steps, dt)`` of :class:`ImpulsesBetweenSteps` from the
    time ``start``, with the impulses at ``times`` (sorted) still to come: the advances and
    kicks in order, and how many of ``times`` they use.

    A step with impulses inside is cut at each of them: pieces from the grid point
    ``start + done dt`` to the first impulse, between the impulses (none between two at one
    time) and from the last to the next grid point, counted as one step; an impulse on a grid
    point (within ``1e-9 dt``) acts between two steps, at that grid point's time. Every time is
    computed as written here (``start + done dt``, the impulse's own time), so a loop that
    follows the plan steps at a single run's times to the last bit: the forced steppers and
    the member loop of a general ensemble (:mod:`dirac.ensemble.impulse_plan`) both do.
    """
    end = start + n_steps * dt
    slack = _GRID_SLACK * dt
    done = 0
    used = 0
    plan: list[Advance | Kick] = []
    while used < len(times) and times[used] <= end + slack:
        index, t_impulse = used, times[used]
        used += 1
        offset = (t_impulse - (start + done * dt)) / dt  # steps from here to the impulse
        whole = int(math.floor(offset + _GRID_SLACK))
        cut = (offset - whole) * dt
        plan.append(Advance(start + done * dt, whole, dt))
        done += whole
        if cut > slack:
            step_end = start + (done + 1) * dt
            plan.append(Advance(start + done * dt, 1, cut))
            plan.append(Kick(index, t_impulse))
            covered, pieces = cut, 1
            # further impulses inside the same step: each cut from the last (the step's state is
            # now at the last impulse's time, not at a grid point)
            while used < len(times) and times[used] < step_end - slack:
                following = times[used]
                piece = following - t_impulse
                if piece > slack:
                    plan.append(Advance(t_impulse, 1, piece))
                    covered += piece
                    pieces += 1
                plan.append(Kick(used, following))
                used += 1
                t_impulse = following
            plan.append(Advance(t_impulse, 1, dt - covered, -pieces))
            done += 1
        else:
            plan.append(Kick(index, start + done * dt))
    plan.append(Advance(start + done * dt, n_steps - done, dt))
    return plan, used


class ImpulsesBetweenSteps:
    """``step(n_steps, dt)`` of a fixed-step method on a forced problem: the steps are cut so
    that one ends on each impulse time, where ``p`` jumps by the projected impulse and its
    work is added (the pieces of :func:`plan_call`). The stepper provides ``_advance(n_steps,
    dt)`` (no impulse inside), ``pending`` (the impulses still to come), ``work`` and the
    state ``q``, ``p``, ``time``."""

    pending: list
    work: Any
    q: Any
    p: Any
    time: Any
    steps: Any
    mechanics: Any

    def _advance(self, n_steps: int, dt: float, warm_up: bool = False) -> None:  # pragma: no cover - interface
        raise NotImplementedError

    def _kick(self, impulse) -> None:
        for b in range(self.q.shape[0]):
            self.p[b], work = self.mechanics.apply_impulse(self.q[b], self.p[b], impulse.vector, self.time)
            self.work[b] += work

    def step(self, n_steps: int, dt: float) -> None:
        """``n_steps`` steps of the grid ``start + k dt``, cut at the impulses inside
        (:func:`plan_call`)."""
        start = self.time
        plan, used = plan_call(start, n_steps, dt, [impulse.t for impulse in self.pending])
        impulses = self.pending[:used]
        del self.pending[:used]
        for piece in plan:
            if isinstance(piece, Kick):
                self.time = piece.time
                self._kick(impulses[piece.impulse])
            else:
                self.time = piece.base
                self._advance(piece.steps, piece.size)
                self.steps += piece.adjust
        self.time = start + n_steps * dt


class ForcedStepper(ImpulsesBetweenSteps, ConstrainedStepper):
    """Forced RATTLE or the conformal splitting, composed with ``method.data``, with impulses."""

    def __init__(self, method: Method, problem, outputs: tuple[str, ...], options: dict) -> None:
        super().__init__(problem, outputs, options)
        self.name = method.name
        family, coefficients = cast(tuple[str, tuple[float, ...]], method.data)
        self.fractions = np.asarray(coefficients, dtype=float)
        self.conformal = family == "conformal"
        mechanics = self.mechanics
        if self.conformal and mechanics.conformal_rate is None:
            raise InputError(
                f"method {method.name!r} needs linear damping Q = -gamma M q_dot with a constant mass "
                f"(a conformal Hamiltonian system); the forces of {mechanics.name!r} are not of that form: "
                "use forced-rattle-2 or forced-rattle-4 (also by their ordinary names rattle-2 and rattle-4), midpoint, "
                "auto or a scipy method"
            )
        for q in self.q:
            mechanics.mass_matrix(q)  # refuses a singular mass matrix
        self.work = np.zeros(self.q.shape[0])
        self.pending = list(problem.impulses)

    # ------------------------------------------------------------------ kernels
    def _call(self, b: int, n_steps: int, dt: float, time: float, warm_up: bool = False) -> None:
        mechanics = self.mechanics
        work = self.work[b : b + 1]
        if self.conformal:
            kernel = tiered(mechanics.module, "conformal_run")
            args: tuple = (self.q[b], self.p[b], time, mechanics.params, float(mechanics.conformal_rate),
                           self.fractions, dt, n_steps, self.tol, self.max_iter, self.info, work)
        else:
            kernel = tiered(mechanics.module, "forced_rattle_run")
            args = (self.q[b], self.p[b], time, mechanics.params, self.fractions, dt, n_steps,
                    self.tol, self.max_iter, self.info, work)
        self._kernel_call(kernel, n_steps, *args, warm_up=warm_up)

    def _advance(self, n_steps: int, dt: float, warm_up: bool = False) -> None:
        """``n_steps`` steps of size ``dt`` from ``self.time`` for every state (no impulse inside)."""
        if n_steps <= 0 or dt <= 0.0:
            return
        for b in range(self.q.shape[0]):
            with singular_as_step_failure(self.name):
                self._call(b, n_steps, dt, self.time, warm_up)
            self.evaluations += int(self.info[2])
            self._raise_if_failed(self.name)
        self.steps += n_steps
        self.time += n_steps * dt

    def warm_up(self) -> None:
        saved = (self.q.copy(), self.p.copy(), self.work.copy(), self.time, self.steps, self.evaluations)
        self._advance(1, 1e-6, warm_up=True)
        self.q[:], self.p[:], self.work[:] = saved[0], saved[1], saved[2]
        self.time, self.steps, self.evaluations = saved[3], saved[4], saved[5]

    def observe(self) -> dict[str, np.ndarray]:
        names = tuple(name for name in self.outputs if name != "work")
        result = constrained_outputs(self.mechanics, names, self.q, self.p, self.time)
        if "work" in self.outputs:
            result["work"] = self.work.copy()
        return result


def _factory(method: Method, problem, outputs, options) -> Stepper:
    return ForcedStepper(method, problem, outputs, options)


def _coefficients(order: int) -> tuple[str, tuple[float, ...]]:
    for composition in COMPOSITIONS:
        if composition.order == order:
            return composition.suffix, tuple(composition.coefficients)
    raise ValueError(order)  # pragma: no cover - the compositions list orders 2 and 4


def _methods() -> tuple[Method, ...]:
    methods = []
    for order in (2, 4):
        suffix, coefficients = _coefficients(order)
        composed = "" if order == 2 else ", composed symmetrically"
        methods.append(Method(
            name=f"forced-rattle-{suffix}", order=order, kind="fixed", symplectic=False, preserves_casimirs=False,
            description=f"forced constrained systems: RATTLE with discrete Lagrange-d'Alembert forces{composed}, "
            f"order {order}",
            reference="Marsden & West, Acta Numerica 10 (2001), Sect. 3.2; Hairer, Lubich & Wanner VII.1.4",
            factories={"forced": _factory}, data=("rattle", coefficients)))
        methods.append(Method(
            name=f"conformal-{suffix}", order=order, kind="fixed", symplectic=False, preserves_casimirs=False,
            description=f"linear damping Q = -gamma M q_dot, constant mass: conformal-symplectic splitting{composed}, "
            f"order {order}",
            reference="McLachlan & Perlmutter, J. Geom. Phys. 39 (2001)",
            factories={"forced": _factory}, data=("conformal", coefficients)))
    return tuple(methods)


#: ``forced-rattle-2/4`` and ``conformal-2/4``.
METHODS: tuple[Method, ...] = _methods()
FORCED_METHOD_NAMES: tuple[str, ...] = tuple(m.name for m in METHODS)
