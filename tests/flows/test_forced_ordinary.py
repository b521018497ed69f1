"""Forced systems through the usual road: ConstrainedProblem and the ordinary method names.

Reference (by hand): a bead of mass m on the line through the origin at the angle a in the
plane, ``chi = x sin a - y cos a``, in the potential ``k/2 (x^2 + y^2)`` with the friction
``Q = -c (x_dot, y_dot)``. Along the line, ``s = x cos a + y sin a`` obeys
``m s'' = -k s - c s'`` (the constraint force is normal to the line), the damped
oscillator: with ``s(0) = 1``, ``s'(0) = 0``, ``gamma = c / (2 m)``,
``w = sqrt(k/m - gamma^2)``,

    s(t) = exp(-gamma t) (cos w t + gamma / w sin w t),

and ``x = s cos a``, ``y = s sin a``. The energy balance ``E - W`` (``W`` the work of the
friction, :mod:`dirac.flows.methods.forced`) is conserved along the exact motion.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import dirac
from dirac.errors import InputError
from dirac.flows.problems import ForcedProblem

MASS, K, C, ANGLE = 1.0, 4.0, 0.6, 0.5
GAMMA = C / (2 * MASS)
OMEGA = math.sqrt(K / MASS - GAMMA**2)
T_END = 2.0


def _s(t: float) -> float:
    return math.exp(-GAMMA * t) * (math.cos(OMEGA * t) + GAMMA / OMEGA * math.sin(OMEGA * t))


@pytest.fixture(scope="module")
def problem():
    bead = dirac.Lagrangian.from_strings(
        "damped_bead", ["x", "y"], "m/2*(x_dot**2 + y_dot**2) - k/2*(x**2 + y**2)",
        constraints=["x*sin(a) - y*cos(a)"], parameters={"m": MASS, "k": K, "c": C, "a": ANGLE},
        forces={"x": "-c*x_dot", "y": "-c*y_dot"})
    return dirac.ConstrainedProblem(bead, [math.cos(ANGLE), math.sin(ANGLE)], [0.0, 0.0])


def _error(problem, method: str, **options) -> float:
    run = dirac.integrate(problem, method, t_end=T_END, samples=2, outputs=["q"], **options)
    q = run.outputs["q"][-1]
    along = q[0] * math.cos(ANGLE) + q[1] * math.sin(ANGLE)
    assert abs(q[0] * math.sin(ANGLE) - q[1] * math.cos(ANGLE)) < 1e-10  # on the line
    return abs(along - _s(T_END))


def test_constrained_problem_of_a_forced_system_is_a_forced_problem(problem):
    assert isinstance(problem, ForcedProblem)
    assert problem.kind == "forced" and problem.impulses == ()


@pytest.mark.parametrize("method", ["rattle-2", "rattle-4", "midpoint"])
def test_ordinary_names_reach_their_nominal_orders(problem, method):
    """Errors at T = 2 against the damped oscillator's closed form at dt = 0.02, 0.01, 0.005:
    the fitted log-log slope is the method's order (2, 4, 2)."""
    steps = (0.02, 0.01, 0.005)
    errors = [_error(problem, method, dt=dt) for dt in steps]
    slope = float(np.polyfit(np.log(steps), np.log(errors), 1)[0])
    order = dirac.flows.get_method(method).order
    assert abs(slope - order) < 0.2, (errors, slope)
    assert errors[-1] < 10.0 ** (-2 * order + 1)  # and small: the forces are in


@pytest.mark.parametrize("method", ["scipy-DOP853", "scipy-RK45", "auto"])
def test_adaptive_and_auto_follow_the_closed_form(problem, method):
    assert _error(problem, method, tolerance=1e-10) < 1e-8


@pytest.mark.parametrize("method, dt", [("midpoint", 0.01), ("scipy-DOP853", None)])
def test_energy_minus_work_is_conserved(problem, method, dt):
    """E - W constant along the motion while E itself falls (friction): to O(dt^2) for the
    midpoint rule's own quadrature of the work, to the tolerance for scipy."""
    options = {"dt": dt} if dt else {"tolerance": 1e-10}
    run = dirac.integrate(problem, method, t_end=T_END, samples=21, outputs=["energy", "work"], **options)
    energy, work = run.outputs["energy"], run.outputs["work"]
    assert energy[0] - energy[-1] > 0.5
    balance = energy - work
    assert np.max(np.abs(balance - balance[0])) < (1e-3 if dt else 1e-8)


@pytest.mark.parametrize("method, dt", [("midpoint", 0.001), ("scipy-DOP853", None)])
def test_impulse_jumps_the_velocity_along_the_line(problem, method, dt):
    """An impulse J at t = 0.5 changes s' by (J . e) / m, e = (cos a, sin a); the later motion
    is the closed form started from the kicked state (compared at T)."""
    kicked = ForcedProblem(problem.mechanics, problem.q0[0], problem.p0[0], impulses=[(0.5, {"x": 0.4, "y": -0.1})])
    options = {"dt": dt} if dt else {"tolerance": 1e-11}
    run = dirac.integrate(kicked, method, t_end=T_END, samples=2, outputs=["q"], **options)
    jump = (0.4 * math.cos(ANGLE) - 0.1 * math.sin(ANGLE)) / MASS
    s0, v0 = _s(0.5), -(GAMMA**2 + OMEGA**2) / OMEGA * math.exp(-GAMMA * 0.5) * math.sin(OMEGA * 0.5) + jump
    tau = T_END - 0.5
    expected = math.exp(-GAMMA * tau) * (s0 * math.cos(OMEGA * tau) + (v0 + GAMMA * s0) / OMEGA * math.sin(OMEGA * tau))
    q = run.outputs["q"][-1]
    assert q[0] * math.cos(ANGLE) + q[1] * math.sin(ANGLE) == pytest.approx(expected, abs=1e-5 if dt else 1e-8)


def test_a_method_without_forces_is_refused_naming_those_with(problem):
    with pytest.raises(InputError) as refused:
        dirac.integrate(problem, "rattle-8", t_end=1.0, dt=0.01)
    message = str(refused.value)
    for name in ("auto", "rattle-2", "rattle-4", "midpoint", "scipy-RK45", "scipy-DOP853", "forced-rattle-2"):
        assert name in message
