"""A run of a conservative system that loses its energy says so.

The exact flow of a system whose Hamiltonian does not depend on time, with no forces, keeps
``H``. A resolved run keeps it too, up to ``O(dt^p)`` for a method of order ``p`` (bounded for
the symplectic ones: Hairer, Lubich & Wanner, *Geometric Numerical Integration*, 2nd ed.,
Springer 2006, Sect. IX.8). A run whose steps do not resolve the motion somewhere (a close pass
by a pole, a fast turn) can change ``H`` by a finite amount in one step and finish with no other
sign: ``V = -1/x + 0.01/x^2`` from ``x = 1`` at rest turns at ``x = 0.0101`` (by hand); ``midpoint``
with ``dt = 1e-3`` jumps the turn and ends with ``H = -1.41`` where it started at ``-0.99``, and
``rattle-2`` with ``H = +0.91``, escaping to infinity from a bound orbit.

:class:`EnergyWatch` reads ``H`` and the kinetic part ``K = H(q, p) - H(q, 0)`` at the samples of a
run (``K = p^T M^{-1} p / 2`` of a natural system) and finds the first sample interval across which
``|H - H(0)|`` passed :data:`ENERGY_CHANGE` times the largest ``K`` sampled so far: the energy
exchanged between kinetic and potential, which does not depend on the constant added to ``V``.
The loop then warns (:func:`dirac.errors.warn`) and keeps the figures in the solution's
``extra["energy_change"]``: the numbers stand, and the user reads what they are worth.

The watch also keeps, for each member, the largest change of ``H`` read and the state where it
was read: :meth:`EnergyWatch.shown_error` turns them into the error the energy shows
(:func:`first_order_error`), which decides whether ``auto`` checks its run over its whole span
(:mod:`dirac.flows.methods.whole_span`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["ENERGY_CHANGE", "EnergyWatch", "energy_watch", "first_order_error"]

#: A change of ``H`` beyond this fraction of the largest kinetic energy sampled is reported.
#: Stormer-Verlet (``rattle-2``) changes the energy of a small oscillation by ``(omega dt)^2 / 4`` of
#: it (its modified energy differs from ``H`` by ``dt^2 omega^2 q^2 / 8``): 1.1e-2 at 30 steps per
#: period, 2.5e-2 at 20 (reported); the coarsest runs of the test suite (20 ``rattle-2`` steps of
#: ``dt = 0.05`` from large momenta on a double pendulum, a triple pendulum, a top) change it by 3.0e-2 to
#: 3.8e-2 (reported). The unresolved passes of the module docstring change it by 7.2e-2 (``midpoint``) and
#: 0.33 (``rattle-2``; 1.0 at ``dt = 3e-3``).
ENERGY_CHANGE = 2e-2


@dataclass
class _Change:
    """The first change found: the member, ``|H - H(0)|``, the kinetic scale, the sample interval and ``H`` at its ends."""

    member: int
    change: float
    scale: float
    start: float
    end: float
    before: float
    after: float


class EnergyWatch:
    """``H`` and ``K`` of every member of a run, read at its samples (see the module docstring).

    Parameters
    ----------
    readings
        ``readings(state)`` -> ``(H, K)``, arrays of one entry per member of the batch, from the
        stepper's state, or ``(H, K, rows)`` with each member's whole state (one row each).
    energy
        ``energy(row)`` -> ``H`` of one member's whole state (:meth:`shown_error`), or None.
    """

    def __init__(self, readings: Any, energy: Any = None) -> None:
        self.readings = readings
        self.energy = energy
        self.first: np.ndarray | None = None
        self.scale: np.ndarray | None = None
        self.last: np.ndarray | None = None
        self.t_last = 0.0
        self.found: _Change | None = None
        #: per member, the largest ``|H - H(0)|`` read and the whole state where it was read
        self.largest: np.ndarray | None = None
        self.largest_rows: np.ndarray | None = None

    def read(self, stepper: Any, t: float, energy: np.ndarray | None = None) -> None:
        """Read the state of ``stepper`` at the sample time ``t`` (``energy``: ``H`` if the run computed it)."""
        if self.found is not None:
            return
        values, kinetic, *rows = self.readings(stepper, energy)
        if self.first is None or self.scale is None or self.last is None:
            self.first, self.scale, self.last, self.t_last = values.copy(), np.abs(kinetic), values.copy(), t
            if rows:
                self.largest, self.largest_rows = np.zeros_like(values), np.array(rows[0], dtype=float)
            return
        self.scale = np.maximum(self.scale, np.abs(kinetic))
        change = np.abs(values - self.first)
        if rows and self.largest is not None and self.largest_rows is not None:
            larger = ~(change <= self.largest)  # NaN counts as larger
            self.largest = np.where(larger, change, self.largest)
            self.largest_rows[larger] = np.asarray(rows[0], dtype=float)[larger]
        # the floor keeps rounding at rest (K = 0) from counting: 1e-12 of |H| is far below any step's error
        scale = np.maximum(self.scale, 1e-12 * np.abs(self.first))
        over = np.flatnonzero(~(change <= ENERGY_CHANGE * scale))  # NaN counts: the drift check names it first
        if over.size:
            b = int(over[np.argmax(change[over] / np.maximum(scale[over], 1e-300))])
            self.found = _Change(b, float(change[b]), float(scale[b]), self.t_last, t, float(self.last[b]),
                                float(values[b]))
        self.last, self.t_last = values.copy(), t

    def report(self, system: str, method: str, order: int | None, dt: float | None, batched: bool,
               chosen: bool = False) -> str | None:
        """The warning's text, or None when ``H`` was kept (``chosen``: the method and ``dt`` were chosen by
        ``auto`` for a tolerance, which is then what to tighten)."""
        w = self.found
        if w is None or self.first is None:
            return None
        who = f" (member {w.member} of the batch)" if batched else ""
        step = f" at dt = {dt:.3g}" if dt is not None else ""
        halving = (f"; halving dt should shrink the change about {2 ** order}-fold where the motion is resolved"
                   if dt is not None and order and not chosen else "")
        cure = "reduce dt or use method auto" if dt is not None and not chosen else "give a smaller tolerance"
        return (f"the energy of {system!r}{who} changed by {w.change:.3g} from its start {self.first[w.member]:.6g} "
                f"(from {w.before:.6g} at t = {w.start:.6g} to {w.after:.6g} at t = {w.end:.6g}), "
                f"{100 * w.change / w.scale:.2g} % of the largest kinetic energy sampled ({w.scale:.3g}); the exact motion "
                f"keeps it: the steps of {method}{step} do not resolve the motion there (a close pass by a pole, a "
                f"fast turn); {cure}{halving}")

    def shown_error(self) -> float:
        """The error the energy shows: the largest over the members of :func:`first_order_error` at
        the largest change of ``H`` read; infinity when the watch stopped reading at a change it
        reported (:attr:`found`) or keeps no states."""
        if self.found is not None or self.energy is None or self.largest is None or self.largest_rows is None:
            return math.inf
        try:
            with np.errstate(all="ignore"):
                return max((first_order_error(self.energy, float(change), row)
                            for change, row in zip(self.largest, self.largest_rows)), default=0.0)
        except (ArithmeticError, ValueError):  # H undefined next to a sample: nothing is known
            return math.inf

    def extra(self) -> dict[str, float] | None:
        """The figures of the report, for the solution's ``extra["energy_change"]``."""
        w = self.found
        if w is None:
            return None
        return {"member": w.member, "change": w.change, "kinetic_scale": w.scale, "t_start": w.start,
                "t_end": w.end}


def _state(stepper: Any, half: int) -> tuple[np.ndarray, np.ndarray, float]:
    """``(coordinate half, momentum half, time)`` of a stepper's batch: ``q, p`` of RATTLE, ``z`` of an
    analysed stepper, ``y`` of the scipy methods."""
    if hasattr(stepper, "q") and hasattr(stepper, "p"):
        return np.asarray(stepper.q, dtype=float), np.asarray(stepper.p, dtype=float), float(stepper.time)
    z = np.asarray(stepper.z if hasattr(stepper, "z") else stepper.y, dtype=float)
    return z[:, :half], z[:, half:], float(getattr(stepper, "time", getattr(stepper, "t", 0.0)))


def first_order_error(energy: Any, change: float, row: np.ndarray) -> float:
    """The error of a state ``row`` of a conservative system whose ``H`` is off by ``change``, to first order.

    The exact motion keeps ``H``; a numerical state ``z`` with ``|H(z) - H(z_0)| = change`` is at least
    ``change / |grad H(z)|_1`` away from the exact one in its largest component
    (``|H(z) - H(z*)| <= |grad H|_1 |z - z*|_max`` along the short segment between them); the gradient by
    central differences. A zero gradient gives infinity (nothing is known), no change zero."""
    if change == 0.0:
        return 0.0
    if not math.isfinite(change):
        return math.inf
    z = np.asarray(row, dtype=float)
    gradient = 0.0
    for i in range(z.size):
        h = 1e-6 * (1.0 + abs(float(z[i])))
        up, down = z.copy(), z.copy()
        up[i] += h
        down[i] -= h
        gradient += abs(energy(up) - energy(down)) / (2.0 * h)
    return float(change / gradient) if gradient > 0.0 else math.inf


def _mechanical_energy(mechanics: Any) -> Any:
    """``H`` of one whole state ``(q, p)`` of a mechanical system (its generated ``energy``; no time)."""
    kernel, params, n = mechanics.module.function("energy"), mechanics.params, mechanics.dimension

    def energy(row: np.ndarray) -> float:
        return float(kernel(np.ascontiguousarray(row[:n]), np.ascontiguousarray(row[n:]), 0.0, params))

    return energy


def _analysed_energy(analysed: Any) -> Any:
    """``H`` of one whole state ``z`` of an analysed system (its generated ``energy``; no time)."""
    kernel, params = analysed.module.function("energy"), analysed.params

    def energy(row: np.ndarray) -> float:
        return float(kernel(np.ascontiguousarray(row), 0.0, params))

    return energy


def _mechanical_readings(mechanics: Any) -> Any:
    energy_kernel = mechanics.module.function("energy")
    potential = mechanics.module.function("potential")

    def readings(stepper: Any, energy: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        q, p, t = _state(stepper, mechanics.dimension)
        c = mechanics.params
        q, p = np.ascontiguousarray(q), np.ascontiguousarray(p)
        if energy is None:
            energy = np.array([energy_kernel(a, b, t, c) for a, b in zip(q, p)])
        rest = np.array([float(potential(a, t, c)) for a in q])
        return np.asarray(energy, dtype=float), np.asarray(energy, dtype=float) - rest, np.concatenate([q, p], axis=1)

    return readings


def _analysed_readings(analysed: Any) -> Any:
    energy_kernel = analysed.module.function("energy")
    half = analysed.dimension // 2

    def readings(stepper: Any, energy: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        coordinates, momenta, t = _state(stepper, half)
        c = analysed.params
        z = np.ascontiguousarray(np.concatenate([coordinates, momenta], axis=1))
        at_rest = z.copy()
        at_rest[:, half:] = 0.0  # H(q, 0): the momenta set to zero
        if energy is None:
            energy = np.array([energy_kernel(x, t, c) for x in z])
        with np.errstate(all="ignore"):
            rest = np.array([energy_kernel(x, t, c) for x in at_rest])
        kinetic = np.asarray(energy, dtype=float) - rest
        # H(q, 0) may be undefined where H(q, p) is not (a division by a momentum): no kinetic scale then
        return np.asarray(energy, dtype=float), np.where(np.isfinite(kinetic), kinetic, 0.0), z

    return readings


def energy_watch(problem: Any, stepper: Any) -> EnergyWatch | None:
    """The watch of a run of a conservative constrained or analysed system; None for any other run.

    Conservative: a Hamiltonian free of the time, no forces, constraints that do not turn
    (a turning frame keeps the Jacobi integral instead), and a stepper whose state the watch reads.
    """
    mechanics = getattr(problem, "mechanics", None)
    if problem.kind == "constrained" and mechanics is not None and _reads_state(stepper, "field"):
        if (getattr(mechanics, "time_symbol", None) is not None or getattr(mechanics, "forced", False)
                or getattr(mechanics, "rotation", None) is not None or getattr(mechanics, "module", None) is None):
            return None
        return EnergyWatch(_mechanical_readings(mechanics), _mechanical_energy(mechanics))
    analysed = getattr(problem, "analysed", None)
    if problem.kind == "analysed" and analysed is not None and _reads_state(stepper, "analysed"):
        lagrangian = getattr(getattr(analysed, "analysis", None), "lagrangian", None)
        if lagrangian is None or lagrangian.is_time_dependent:
            return None
        return EnergyWatch(_analysed_readings(analysed), _analysed_energy(analysed))
    return None


def _reads_state(stepper: Any, scipy_mark: str) -> bool:
    """Whether the watch can read the stepper's state (see :func:`_state`); a scipy stepper keeps ``y`` and,
    for these problems, a ``field`` (constrained) or the ``analysed`` system."""
    return (hasattr(stepper, "q") and hasattr(stepper, "p")) or hasattr(stepper, "z") or (
        hasattr(stepper, "y") and hasattr(stepper, scipy_mark))
