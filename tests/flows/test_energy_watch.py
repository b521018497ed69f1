"""A run that changes the energy of a conservative system by a finite amount says so.

``L = x_dot^2/2 - V``, ``V = -1/x + 0.01/x^2``, from ``x = 1`` at rest: ``E = -0.99`` and
``E - V = (-0.99 x^2 + x - 0.01) / x^2`` vanish at ``x = 1`` and at
``x_min = (1 - sqrt(1 - 0.0396)) / 1.98 = 1/99`` (by hand), where the motion turns. The time of the
pass is

    t_pass = integral_{x_min}^{1} x dx / sqrt(1.98 (x - x_min)(1 - x)) = pi (1 + x_min) / (2 sqrt(1.98))
           = 1.12765...

(``integral_a^b x dx / sqrt((x - a)(b - x)) = pi (a + b) / 2``). The speed at the pass is about 7, so
the pass takes a few thousandths of a time unit: a fixed step of ``1e-3`` jumps it, and used to finish
with the energy off by 0.42 (``midpoint``) or with the orbit escaping (``rattle-2``), complete and with
no word.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import dirac
from dirac.errors import DiracWarning
from dirac.flows import ConstrainedProblem, integrate
from dirac.flows.energy_watch import ENERGY_CHANGE, EnergyWatch

X_MIN = 1.0 / 99.0
T_PASS = math.pi * (1.0 + X_MIN) / (2.0 * math.sqrt(1.98))


def _close_pass(road: str = "constrained"):
    L = dirac.Lagrangian.from_strings("close_pass", ["x"], "x_dot**2/2 - (-1/x + 0.01/x**2)", [], parameters={})
    if road == "constrained":
        return ConstrainedProblem(L, q0=[1.0], qdot0=[0.0])
    from dirac.flows.analysed import AnalysedProblem, AnalysedSystem

    analysed = AnalysedSystem.from_analysis(dirac.analyze(L))
    return AnalysedProblem(analysed, analysed.initial_state({"x": 1.0}, q_dot={"x": 0.0}))


def test_the_hand_time_of_the_pass_agrees_with_a_quadrature():
    """``t_pass`` (module docstring) against the quadrature of ``dx / sqrt(2 (E - V))`` over ``(x_min, 1)``."""
    from scipy.integrate import quad

    assert (1.0 - math.sqrt(1.0 - 0.0396)) / 1.98 == pytest.approx(X_MIN, rel=1e-12)
    value, error = quad(lambda x: 1.0 / math.sqrt(2.0 * (-0.99 + 1.0 / x - 0.01 / x**2)), X_MIN, 1.0, limit=200)
    assert error < 1e-7
    assert value == pytest.approx(T_PASS, rel=1e-7)


@pytest.mark.parametrize("method", ["midpoint", "rattle-2"])
def test_an_unresolved_pass_warns_and_names_the_interval_of_the_pass(method):
    """``dt = 1e-3`` jumps the pass: the run completes, warns, and names the sample interval that holds
    ``t_pass``; the solution keeps the figures and the text."""
    with pytest.warns(DiracWarning, match=r"the energy of 'close_pass' changed by .* do not resolve") as caught:
        solution = integrate(_close_pass(), method, t_end=3.0, dt=1e-3, samples=31)
    assert solution.complete
    record = solution.extra["energy_change"]
    assert record["t_start"] <= T_PASS <= record["t_end"] and record["t_end"] - record["t_start"] == pytest.approx(0.1)
    energy = solution.outputs["energy"]
    assert record["change"] == pytest.approx(np.max(np.abs(energy[energy.size // 2:] + 0.99)), rel=0.5)
    assert record["change"] > ENERGY_CHANGE * record["kinetic_scale"]
    assert solution.message == str(caught[-1].message)
    assert "energy_change" in solution.meta()


def test_a_resolved_pass_keeps_the_energy_and_says_nothing():
    """``dt = 1e-4`` resolves the pass: the energy is kept to 1e-5 and nothing is said."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", DiracWarning)
        solution = integrate(_close_pass(), "midpoint", t_end=3.0, dt=1e-4, samples=31)
    assert solution.complete and "energy_change" not in solution.extra and solution.message == ""
    assert np.max(np.abs(solution.outputs["energy"] + 0.99)) < 1e-5


def test_the_analysed_road_warns_the_same():
    """The same pass on the road through the Dirac analysis (state ``z``, ``H`` the canonical Hamiltonian,
    its kinetic part ``H(q, p) - H(q, 0)``)."""
    with pytest.warns(DiracWarning, match=r"changed by .* do not resolve"):
        solution = integrate(_close_pass("analysed"), "midpoint", t_end=3.0, dt=1e-3, samples=31)
    record = solution.extra["energy_change"]
    assert record["t_start"] <= T_PASS <= record["t_end"]


@pytest.mark.parametrize("steps_per_period", [30, 15])
def test_a_coarse_pendulum_is_judged_by_its_order(steps_per_period):
    """``L = x_dot^2/2 - (1 - cos x)`` from ``x = 0.1`` at rest with ``rattle-2`` (Stormer-Verlet): on a small
    oscillation its modified energy differs from ``H`` by ``dt^2 x^2 / 8`` (``omega = 1``), so ``H`` changes by
    ``dt^2 / 4`` of the energy exchanged (by hand): 1.1e-2 at 30 steps per period, below
    :data:`ENERGY_CHANGE` (nothing said), and 4.4e-2 at 15, above it (reported)."""
    L = dirac.Lagrangian.from_strings("pendulum", ["x"], "x_dot**2/2 - (1 - cos(x))", [], parameters={})
    dt = 2.0 * math.pi / steps_per_period
    problem = ConstrainedProblem(L, q0=[0.1], qdot0=[0.0])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", DiracWarning)
        solution = integrate(problem, "rattle-2", t_end=20 * math.pi, dt=dt, samples=10 * steps_per_period + 1)
    energy = solution.outputs["energy"]
    change = np.max(np.abs(energy - energy[0])) / energy[0]  # from rest: the energy exchanged is E - V_min = E
    assert change == pytest.approx(dt**2 / 4.0, rel=0.05)
    reported = [w for w in caught if "the energy of 'pendulum' changed" in str(w.message)]
    assert (change > ENERGY_CHANGE) == bool(reported) == ("energy_change" in solution.extra)


def test_a_time_dependent_system_is_not_watched():
    """A driven oscillator (``V = x^2/2 - x cos t``) does not keep its energy: the watch stays away."""
    from dirac.flows.energy_watch import energy_watch
    from dirac.flows.methods.registry import get_method

    L = dirac.Lagrangian.from_strings("driven", ["x"], "x_dot**2/2 - x**2/2 + x*cos(t)", [], parameters={})
    problem = ConstrainedProblem(L, q0=[0.0], qdot0=[0.0])
    stepper = get_method("rattle-2").start(problem, ("q",), {"t_end": 1.0, "tolerance": 1e-8,
                                                            "newton_tolerance": 1e-12, "max_newton_iterations": 50,
                                                            "planned_steps": 10})
    assert energy_watch(problem, stepper) is None


def test_rounding_at_rest_is_not_a_change():
    """At rest in an equilibrium ``K = 0``: a change of ``H`` at the rounding level (1e-17 of ``|H| = 1``) is
    not reported (the floor of the scale is 1e-12 of ``|H|``); a change of 1e-3 of ``|H|`` is."""

    class _State:
        def __init__(self, energy: float) -> None:
            self.energy = energy

    def readings(state, energy):
        return np.array([state.energy]), np.array([0.0])

    watch = EnergyWatch(readings)
    watch.read(_State(1.0), 0.0)
    watch.read(_State(1.0 + 1e-16), 1.0)
    assert watch.report("rest", "rattle-2", 2, 0.1, False) is None
    watch.read(_State(1.0 + 1e-3), 2.0)
    text = watch.report("rest", "rattle-2", 2, 0.1, False)
    assert text is not None and "between" not in text and "from 1 at t = 1 to 1.001 at t = 2" in text


def test_an_adaptive_method_at_a_loose_tolerance_is_told_to_tighten_it():
    """``scipy-RK45`` at ``tolerance = 1e-3`` steps over the pass too (the energy ends off by more than 0.1,
    measured 0.65): the warning names the tolerance, not ``dt``; at ``1e-8`` it keeps the energy to 1e-5."""
    with pytest.warns(DiracWarning, match=r"changed by .* give a smaller tolerance$"):
        solution = integrate(_close_pass(), "scipy-RK45", t_end=3.0, tolerance=1e-3, samples=31)
    assert np.max(np.abs(solution.outputs["energy"] + 0.99)) > 0.1
    record = solution.extra["energy_change"]
    assert record["t_start"] <= T_PASS <= record["t_end"]
    with warnings.catch_warnings():
        warnings.simplefilter("error", DiracWarning)
        solution = integrate(_close_pass(), "scipy-RK45", t_end=3.0, tolerance=1e-8, samples=31)
    assert np.max(np.abs(solution.outputs["energy"] + 0.99)) < 1e-5


def test_a_step_across_the_pole_of_a_repelling_core_is_hedged():
    """``rattle-4`` at ``dt = 1e-3``: a stage lands across ``x = 0`` (from ``x = 0.01``, inside the turning point
    ``x_min = 1/99``); ``V -> +inf`` there, above the energy ``-0.99`` of the start, so the motion of that energy
    cannot reach the pole: the PoleError says that a smaller ``dt`` resolves the turn, with the potential met on
    the step's way. ``V = log(x)`` (``V -> -inf``) keeps its plain verdict (``tests/flows/test_pole_guard.py``)."""
    from dirac.errors import PoleError

    with pytest.raises(PoleError, match=r"stepped across the pole x = 0") as caught:
        integrate(_close_pass(), "rattle-4", t_end=3.0, dt=1e-3, samples=31)
    text = str(caught.value)
    assert "a smaller dt resolves the turn" in text
    rose = float(text.split("rose to V = ")[1].split(",")[0])
    assert rose > -0.99 and "above the energy of the start E = -0.99" in text
