"""``auto``'s run checked over its whole span (:mod:`dirac.flows.methods.whole_span`).

The pilots judge the step over the first ``t_end / 32``; motions that change later missed
the tolerance by orders of magnitude: a spherical pendulum in its angles passing near the
pole (4.1e-6 at ``tolerance = 1e-8``, ``t_end = 1``) and a bead sliding through the vertex
of a parabola (6.2e-7). References: scipy's DOP853 at ``rtol = atol = 1e-13`` on Hamilton's
equations derived by hand.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import dirac
from dirac.flows.integration import integrate
from dirac.flows.methods import whole_span
from dirac.model.lagrangian import Lagrangian

G = 9.81


def _spherical_pendulum() -> dirac.ConstrainedProblem:
    """``L = (th_dot^2 + sin(th)^2 ph_dot^2) / 2 + g cos(th)`` (unit mass and length) from
    ``th = 1``, ``p_th = 0``, ``p_ph = 0.5``: it swings down past the pole ``th = 0``."""
    system = Lagrangian.from_strings("spherical_pendulum", ["th", "ph"],
                                     "(th_dot**2 + sin(th)**2*ph_dot**2)/2 + g*cos(th)", parameters={"g": G})
    return dirac.ConstrainedProblem(system, q0=[1.0, 0.0], p0=[0.0, 0.5])


def _spherical_reference(times: np.ndarray) -> np.ndarray:
    """``(th, ph, p_th, p_ph)`` at ``times``: ``H = p_th^2 / 2 + p_ph^2 / (2 sin^2 th) - g cos th``, so
    ``th' = p_th``, ``ph' = p_ph / sin^2 th``, ``p_th' = p_ph^2 cos th / sin^3 th - g sin th``, ``p_ph' = 0``."""
    def rhs(t, y):
        th, ph, pth, pph = y
        s, c = math.sin(th), math.cos(th)
        return [pth, pph / (s * s), pph * pph * c / s ** 3 - G * s, 0.0]

    solution = solve_ivp(rhs, (0.0, times[-1]), [1.0, 0.0, 0.0, 0.5], method="DOP853", rtol=1e-13, atol=1e-13,
                         t_eval=times)
    return solution.y.T


def _bead_on_parabola() -> dirac.ConstrainedProblem:
    """A bead of unit mass on ``y = x^2`` under gravity, in Cartesian coordinates, from ``x = 1`` at rest."""
    system = Lagrangian.from_strings("bead_on_parabola", ["x", "y"], "(x_dot**2 + y_dot**2)/2 - g*y",
                                     constraints=["y - x**2"], parameters={"g": G})
    return dirac.ConstrainedProblem(system, q0=[1.0, 1.0], p0=[0.0, 0.0])


def _bead_reference(times: np.ndarray) -> np.ndarray:
    """``(x, y, p_x, p_y)`` at ``times``: with ``y = x^2`` the Lagrangian is ``(1 + 4 x^2) v^2 / 2 - g x^2``
    (``v = x'``), whose equation is ``(1 + 4 x^2) v' = -4 x v^2 - 2 g x``; ``p = (v, 2 x v)``."""
    def rhs(t, y):
        x, v = y
        return [v, -(4.0 * x * v * v + 2.0 * G * x) / (1.0 + 4.0 * x * x)]

    solution = solve_ivp(rhs, (0.0, times[-1]), [1.0, 0.0], method="DOP853", rtol=1e-13, atol=1e-13, t_eval=times)
    x, v = solution.y
    return np.stack([x, x * x, v, 2.0 * x * v], axis=1)


@pytest.mark.parametrize(("problem", "reference"), [(_spherical_pendulum, _spherical_reference),
                                                    (_bead_on_parabola, _bead_reference)])
def test_a_run_that_missed_its_tolerance_is_refined_until_it_meets_it(problem, reference) -> None:
    """Both runs missed ``tolerance = 1e-8`` by 60 to 400 times before the check; now the run is
    made again with a smaller step, its largest error over the 101 samples is below the
    tolerance, and the estimate recorded is within a factor 3 of that error."""
    solution = integrate(problem(), t_end=1.0, samples=101)
    times = np.linspace(0.0, 1.0, 101)
    exact = reference(times)
    state = np.concatenate([solution["q"], solution["p"]], axis=1)
    error = float(np.max(np.abs(state - exact)))
    record = solution.meta()["auto"]
    assert error < 1e-8
    assert record["refinements"] >= 1 and record["refined_dt"] == solution.dt
    assert record["whole_span_error"] <= 1e-8
    assert error / 3 < record["whole_span_error"] < 3 * error


def test_a_run_that_meets_its_tolerance_is_the_run_auto_chose() -> None:
    """A pendulum in its angle: the check finds the run within its tolerance and changes nothing;
    the samples are those of the chosen method at the chosen step, bit for bit."""
    system = Lagrangian.from_strings("pendulum", ["th"], "th_dot**2/2 + g*cos(th)", parameters={"g": G})
    problem = dirac.ConstrainedProblem(system, q0=[1.0], p0=[0.0])
    solution = integrate(problem, t_end=1.0, samples=101)
    record = solution.meta()["auto"]
    assert record["refinements"] == 0 and "refined_dt" not in record
    assert record["whole_span_error"] <= 1e-8
    again = integrate(problem, solution.method, dt=solution.dt, t_end=1.0, samples=101,
                      newton_tolerance=record["newton_tolerance"])
    assert np.array_equal(again["q"], solution["q"]) and np.array_equal(again["p"], solution["p"])


def test_a_run_whose_energy_shows_no_error_is_not_checked() -> None:
    """A pendulum in its angle over ``t = 100``: the energy changes by 4.5e-13 (an error of about
    1e-13 in the state, to first order), far below a hundredth of the tolerance; the run is not
    made again at twice the step, and the record says so."""
    system = Lagrangian.from_strings("pendulum", ["th"], "th_dot**2/2 + g*cos(th)", parameters={"g": G})
    solution = integrate(dirac.ConstrainedProblem(system, q0=[1.0], p0=[0.0]), t_end=100.0, samples=101)
    record = solution.meta()["auto"]
    assert record["energy_error_bound"] < whole_span.ENERGY_TRIGGER * 1e-8
    assert record["whole_span_error"] is None and record["refinements"] == 0
    assert record["whole_span_note"].startswith("not checked: the energy shows an error of")


def test_the_energy_shows_an_error_of_at_least_its_change_over_its_gradient() -> None:
    """``H = (q^2 + p^2) / 2``: a state ``(1 + d, 0)`` where the exact one is ``(1, 0)`` changes ``H`` by
    ``d + d^2 / 2``; its gradient there has 1-norm ``1 + d``, so the bound is ``(d + d^2/2) / (1 + d)``,
    about ``d``, the error."""
    def energy(z):
        return 0.5 * float(z @ z)

    from dirac.flows.energy_watch import first_order_error

    d = 1e-3
    start, state = np.array([1.0, 0.0]), np.array([1.0 + d, 0.0])
    bound = first_order_error(energy, abs(energy(state) - energy(start)), state)
    assert bound == pytest.approx((d + d * d / 2) / (1 + d), rel=1e-6)
    assert first_order_error(energy, abs(energy(start) - energy(start)), start) == 0.0


def test_a_run_still_above_its_tolerance_after_the_refinements_warns(monkeypatch) -> None:
    """With no refinement allowed, the spherical pendulum's run keeps its error of about 4e-6: the
    estimate says so in ``meta()["auto"]`` and in a warning that names the tolerance."""
    from dirac.flows import integration

    monkeypatch.setattr(integration, "MAX_REFINEMENTS", 0)
    with pytest.warns(UserWarning, match=r"above the tolerance 1e-08") as caught:
        solution = integrate(_spherical_pendulum(), t_end=1.0, samples=101)
    record = solution.meta()["auto"]
    assert record["refinements"] == 0 and record["whole_span_error"] > 1e-7
    assert record["whole_span_warning"] == str(caught[0].message)


def test_a_refinement_whose_error_does_not_follow_the_order_warns() -> None:
    """A double pendulum released from 2 and -1 rad (chaotic) to ``t = 10``: refined from 11 to 58
    ``rattle-6`` steps per sample interval, its estimate should fall to about 1e-9 and falls only to
    3e-8; the error of such a run is round-off grown by the motion, which no step removes (with a
    fixed step its error against DOP853 grows from 6.5e-7 at 5800 steps to 5.2e-6 at 23200). The run
    warns that its estimate may be far too small, even though the last estimate is below the tolerance."""
    system = Lagrangian.from_strings(
        "double_pendulum", ["a", "b"],
        "(m1 + m2)/2*l1**2*a_dot**2 + m2/2*l2**2*b_dot**2 + m2*l1*l2*a_dot*b_dot*cos(a - b)"
        " + (m1 + m2)*g*l1*cos(a) + m2*g*l2*cos(b)",
        parameters={"m1": 2.0, "m2": 0.5, "l1": 1.0, "l2": 0.7, "g": G})
    problem = dirac.ConstrainedProblem(system, q0=[2.0, -1.0], p0=[0.0, 0.0])
    with pytest.warns(UserWarning, match="may be far too small") as caught:
        solution = integrate(problem, t_end=10.0, samples=101)
    record = solution.meta()["auto"]
    assert record["refinements"] >= 1 and record["whole_span_warning"] == str(caught[0].message)
    assert "did not shrink as the order 6 of rattle-6 predicts" in record["whole_span_warning"]


def test_the_refined_step_aims_at_a_tenth_of_the_tolerance() -> None:
    """``m (e / (tol / 10))^(1/p)`` steps per interval, rounded up, within ``[3 m / 2, 16 m]``."""
    assert whole_span.refined_steps(10, 1e-6, 1e-8, 4) == math.ceil(10 * (1e-6 / 1e-9) ** 0.25)
    assert whole_span.refined_steps(10, 1e-30, 1e-8, 4) == 15  # at least 3/2 as many steps
    assert whole_span.refined_steps(10, 1.0, 1e-8, 2) == 160  # at most 16 times as many


class _Failing:
    """A method whose coarse run leaves the domain of the expressions at its first step."""

    order = 2

    def start(self, problem, outputs, options):
        class Stepper:
            def step(self, n, dt):
                raise ValueError("math domain error")

        return Stepper()


def test_a_check_that_cannot_be_made_says_why_instead_of_an_estimate() -> None:
    """A coarse run that leaves the real domain, and a run of one step over the whole span
    (nothing coarser): no estimate, and the reason."""
    times = np.linspace(0.0, 1.0, 3)
    states = [np.zeros(2)] * 3
    failed = whole_span.coarse_check(_Failing(), None, ("q",), {}, times, 4, states)
    assert failed.error is None and failed.why.startswith("the run at about twice the step left the real domain")
    alone = whole_span.coarse_check(_Failing(), None, ("q",), {}, np.array([1.0]), 1, [np.zeros(2)])
    assert alone.error is None and alone.why == "one step over the whole span: nothing coarser to compare with"
