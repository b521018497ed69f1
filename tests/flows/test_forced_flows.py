"""Forced flows: closed forms, independent minimal-coordinate integrations, orders, the
conformal contraction, the energy balance and impulses (docs/forces.md)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import dirac
from dirac import Lagrangian
from dirac.errors import InputError
from dirac.flows.problems import ForcedProblem

M, G, ELL, C = 1.0, 9.81, 1.0, 0.3
A, W = 1.2, 2.0 / 3.0 * math.sqrt(G / ELL)


def _pendulum(forces: dict[str, str]) -> Lagrangian:
    return Lagrangian.from_strings(
        "forced_pendulum", ["x", "y"], "m/2*(x_dot**2 + y_dot**2) - m*g*y", constraints=["x**2 + y**2 - l**2"],
        parameters={"m": M, "g": G, "l": ELL, "c": C, "A": A, "w": W}, forces=forces)


@pytest.fixture(scope="module")
def damped_pendulum():
    return _pendulum({"x": "-c*x_dot", "y": "-c*y_dot"})


@pytest.fixture(scope="module")
def driven_pendulum():
    # horizontal periodic force A cos(w t) on the bob and linear damping
    return _pendulum({"x": "-c*x_dot + A*cos(w*t)", "y": "-c*y_dot"})


@pytest.fixture(scope="module")
def oscillator():
    return Lagrangian.from_strings("damped_oscillator", ["x"], "m/2*x_dot**2 - k/2*x**2",
                                   parameters={"m": 2.0, "k": 3.0, "c": 0.4}, forces={"x": "-c*x_dot"})


def _angle_reference(theta0: float, t_end: float, samples: np.ndarray, driven: bool, kicks=()) -> np.ndarray:
    """The pendulum in its angle (x = l sin th, y = -l cos th), by hand:
    m l^2 th'' = -m g l sin th - c l^2 th' + A cos(w t) l cos th (driven), solved by scipy
    at tight tolerance; kicks (t, dth_dot) jump the angular velocity."""
    def rhs(t, s):
        th, om = s
        torque = -M * G * ELL * math.sin(th) - C * ELL**2 * om
        if driven:
            torque += A * math.cos(W * t) * ELL * math.cos(th)
        return [om, torque / (M * ELL**2)]

    state, t0, out = np.array([theta0, 0.0]), 0.0, []
    for t_kick, jump in [*kicks, (t_end, 0.0)]:
        inside = samples[(samples >= t0) & (samples <= t_kick)]
        sol = solve_ivp(rhs, (t0, t_kick), state, method="DOP853", rtol=1e-13, atol=1e-13, t_eval=inside)
        out.extend(sol.y[0][k] for k in range(len(inside)) if not (out and inside[k] == t0))
        state = sol.y[:, -1] if len(inside) and inside[-1] == t_kick else solve_ivp(
            rhs, (t0, t_kick), state, method="DOP853", rtol=1e-13, atol=1e-13).y[:, -1]
        state = state + np.array([0.0, jump])
        t0 = t_kick
    return np.array(out)


def _start(theta0: float) -> tuple[list[float], list[float]]:
    return [ELL * math.sin(theta0), -ELL * math.cos(theta0)], [0.0, 0.0]


def test_damped_linear_oscillator_matches_the_closed_form(oscillator):
    m, k, c = 2.0, 3.0, 0.4
    problem = ForcedProblem(oscillator, [1.0], [0.0])
    solution = dirac.integrate(problem, "forced-rattle-4", t_end=10.0, dt=0.01, samples=11, outputs=["q"])
    zeta = c / (2 * m)
    omega = math.sqrt(k / m - zeta**2)
    t = solution.t
    exact = np.exp(-zeta * t) * (np.cos(omega * t) + zeta / omega * np.sin(omega * t))
    assert np.max(np.abs(solution.outputs["q"][:, 0] - exact)) < 1e-8


@pytest.mark.parametrize("method", ["forced-rattle-4", "conformal-4"])
def test_damped_pendulum_matches_the_angle_equation(damped_pendulum, method):
    theta0 = 2.0
    problem = ForcedProblem(damped_pendulum, *_start(theta0))
    # a large swing: the triple jump's error constant makes it 4e-7 at dt = 0.005, 1e-8 at 0.002
    solution = dirac.integrate(problem, method, t_end=5.0, dt=0.002, samples=11, outputs=["q"])
    theta = np.arctan2(solution.outputs["q"][:, 0], -solution.outputs["q"][:, 1])
    reference = _angle_reference(theta0, 5.0, solution.t, driven=False)
    assert np.max(np.abs(theta - reference)) < 2e-8


def test_driven_pendulum_matches_the_angle_equation(driven_pendulum):
    theta0 = 0.2
    problem = ForcedProblem(driven_pendulum, *_start(theta0))
    solution = dirac.integrate(problem, "forced-rattle-4", t_end=5.0, dt=0.005, samples=11, outputs=["q"])
    theta = np.arctan2(solution.outputs["q"][:, 0], -solution.outputs["q"][:, 1])
    reference = _angle_reference(theta0, 5.0, solution.t, driven=True)
    assert np.max(np.abs(theta - reference)) < 1e-8


@pytest.mark.parametrize("method", ["forced-rattle-2", "forced-rattle-4", "conformal-2", "conformal-4"])
def test_measured_order_is_the_methods_order(damped_pendulum, driven_pendulum, method):
    system = damped_pendulum if method.startswith("conformal") else driven_pendulum
    theta0 = 1.0
    order = dirac.flows.get_method(method).order
    reference = _angle_reference(theta0, 2.0, np.array([2.0]), driven=system is driven_pendulum)[-1]
    errors = []
    steps = (0.04, 0.02) if order == 2 else (0.08, 0.04)
    for dt in steps:
        problem = ForcedProblem(system, *_start(theta0))
        q = dirac.integrate(problem, method, t_end=2.0, dt=dt, samples=1, outputs=["q"]).outputs["q"][-1]
        errors.append(abs(math.atan2(q[0], -q[1]) - reference))
    slope = math.log2(errors[0] / errors[1])
    assert abs(slope - order) < 0.3, (errors, slope)


@pytest.mark.parametrize("method", ["conformal-2", "conformal-4"])
def test_conformal_methods_contract_the_symplectic_form_by_exp_minus_gamma_t(oscillator, method):
    # a linear system: the step map is linear, so a difference quotient with a unit
    # perturbation is its matrix up to round-off; in one degree of freedom the symplectic
    # form scales by det
    gamma = 0.4 / 2.0
    t_end = 3.0

    def flow(q0: float, p0: float) -> np.ndarray:
        problem = ForcedProblem(oscillator, [q0], [p0])
        sol = dirac.integrate(problem, method, t_end=t_end, dt=0.05, samples=1, outputs=["q", "p"])
        return np.array([sol.outputs["q"][-1, 0], sol.outputs["p"][-1, 0]])

    base = flow(0.0, 0.0)
    jacobian = np.column_stack([flow(1.0, 0.0) - base, flow(0.0, 1.0) - base])
    assert abs(np.linalg.det(jacobian) - math.exp(-gamma * t_end)) < 1e-13
    assert problem_rate(oscillator) == pytest.approx(gamma, rel=1e-14)


def problem_rate(system: Lagrangian) -> float:
    return ForcedProblem(system, [1.0], [0.0]).mechanics.conformal_rate


def test_conformal_method_refuses_forces_that_are_not_linear_damping(driven_pendulum):
    problem = ForcedProblem(driven_pendulum, *_start(0.3))
    assert problem.mechanics.conformal_rate is None
    with pytest.raises(InputError, match="forced-rattle-2 or forced-rattle-4"):
        dirac.integrate(problem, "conformal-2", t_end=1.0, dt=0.01)


@pytest.mark.parametrize("method", ["forced-rattle-2", "forced-rattle-4"])
def test_energy_minus_work_is_conserved_to_the_methods_order(driven_pendulum, method):
    order = dirac.flows.get_method(method).order
    drifts = []
    for dt in (0.02, 0.01):
        problem = ForcedProblem(driven_pendulum, *_start(1.0))
        sol = dirac.integrate(problem, method, t_end=4.0, dt=dt, samples=41, outputs=["energy", "work"])
        balance = sol.outputs["energy"] - sol.outputs["work"]
        drifts.append(np.max(np.abs(balance - balance[0])))
        assert np.ptp(sol.outputs["energy"]) > 0.1  # the energy itself is not conserved
    assert abs(math.log2(drifts[0] / drifts[1]) - order) < 0.4, drifts


def test_impulse_velocity_jump_is_the_projected_impulse_by_hand(damped_pendulum):
    theta0, J = 0.7, np.array([1.0, 0.5])
    plain = dirac.integrate(ForcedProblem(damped_pendulum, *_start(theta0)), "forced-rattle-2", t_end=0.5, dt=0.01,
                            samples=2, outputs=["q", "q_dot", "work"])
    kicked = dirac.integrate(ForcedProblem(damped_pendulum, *_start(theta0), impulses=[(0.5, {"x": 1.0, "y": 0.5})]),
                             "forced-rattle-2", t_end=0.5, dt=0.01, samples=2, outputs=["q", "q_dot", "work"])
    q = plain.outputs["q"][-1]
    assert np.allclose(kicked.outputs["q"][-1], q, rtol=0, atol=1e-15)
    # by hand: only the tangential part of J acts, dv = (J . e) e / m, e the unit tangent
    e = np.array([-q[1], q[0]]) / np.linalg.norm(q)
    jump = kicked.outputs["q_dot"][-1] - plain.outputs["q_dot"][-1]
    assert np.allclose(jump, (J @ e) * e / M, rtol=0, atol=1e-12)
    before, after = plain.outputs["q_dot"][-1], kicked.outputs["q_dot"][-1]
    impulse_work = kicked.outputs["work"][-1] - plain.outputs["work"][-1]
    assert impulse_work == pytest.approx(J @ (before + after) / 2, abs=1e-13)


def test_impulse_between_grid_points_is_landed_on(damped_pendulum):
    theta0, t_kick = 1.0, 0.37
    problem = ForcedProblem(damped_pendulum, *_start(theta0), impulses=[(t_kick, {"x": 2.0})])
    # dt = 0.005 does not divide 0.37: a step is cut there (a blow one step late would be off by ~1e-2)
    sol = dirac.integrate(problem, "forced-rattle-4", t_end=2.0, dt=0.005, samples=5, outputs=["q"])
    theta = np.arctan2(sol.outputs["q"][:, 0], -sol.outputs["q"][:, 1])
    theta_kick = _angle_reference(theta0, t_kick, np.array([t_kick]), driven=False)[-1]
    jump = 2.0 * math.cos(theta_kick) / (M * ELL)  # J . e / (m l), e = (cos th, sin th)
    reference = _angle_reference(theta0, 2.0, sol.t, driven=False, kicks=[(t_kick, jump)])
    assert np.max(np.abs(theta - reference)) < 3e-8


@pytest.mark.parametrize("method", ["forced-rattle-2", "forced-rattle-4", "midpoint"])
def test_several_impulses_inside_one_step_each_act_at_its_time(method):
    """A free particle (L = m x_dot^2 / 2, the force -c x_dot with c = 0 so that it is a forced
    system): by hand x(T) = x0 + v0 T + sum_i J_i (T - t_i) / m, which these one-step methods
    reproduce to rounding (the velocity is constant between impulses). Impulses at 0.55 and
    0.57 (and a third at 0.57) fall inside one step of dt = 0.1. The step was advanced past its
    end once per extra impulse: x(T) was off by about (J_2 + J_3) dt / m."""
    particle = dirac.Lagrangian.from_strings("free", ["x"], "m/2*x_dot**2", parameters={"m": 2.0, "c": 0.0},
                                             forces={"x": "-c*x_dot"})
    impulses = [(0.55, {"x": 1.0}), (0.57, {"x": 0.5}), (0.57, {"x": -0.25}), (0.8, {"x": 0.125})]
    problem = ForcedProblem(particle, [0.3], [0.4], impulses=impulses)
    sol = dirac.integrate(problem, method, t_end=1.0, dt=0.1, samples=3, outputs=["q", "q_dot"])
    expected = 0.3 + 0.2 * 1.0 + sum(J["x"] * (1.0 - t) for t, J in impulses) / 2.0
    assert sol.outputs["q"][-1][0] == pytest.approx(expected, abs=1e-14)
    assert sol.outputs["q_dot"][-1][0] == pytest.approx(0.2 + sum(J["x"] for _, J in impulses) / 2.0, abs=1e-14)


def test_two_impulses_at_one_time_inside_a_step_act_as_their_sum(damped_pendulum):
    """The projected impulse is linear in J (apply_impulse), so two blows at one time give the
    state of one blow with their sum."""
    two = ForcedProblem(damped_pendulum, *_start(0.7), impulses=[(0.55, {"x": 1.0}), (0.55, {"y": 0.5})])
    one = ForcedProblem(damped_pendulum, *_start(0.7), impulses=[(0.55, {"x": 1.0, "y": 0.5})])
    runs = [dirac.integrate(p, "forced-rattle-2", t_end=1.0, dt=0.1, samples=2, outputs=["q", "p"]) for p in (two, one)]
    assert np.allclose(runs[0].outputs["q"][-1], runs[1].outputs["q"][-1], rtol=0, atol=1e-13)
    assert np.allclose(runs[0].outputs["p"][-1], runs[1].outputs["p"][-1], rtol=0, atol=1e-13)


def test_impulses_before_the_start_are_refused(damped_pendulum):
    with pytest.raises(InputError, match="not after the start"):
        ForcedProblem(damped_pendulum, *_start(0.3), impulses=[(-1.0, {"x": 1.0})])
    with pytest.raises(InputError, match="did you mean 'x'"):
        ForcedProblem(damped_pendulum, *_start(0.3), impulses=[(1.0, {"xx": 1.0})])


def test_impulses_after_t_end_warn(damped_pendulum):
    problem = ForcedProblem(damped_pendulum, *_start(0.3), impulses=[(5.0, {"x": 1.0})])
    with pytest.warns(dirac.DiracWarning, match="after t_end"):
        dirac.integrate(problem, "forced-rattle-2", t_end=1.0, dt=0.01, samples=2)


def test_unforced_methods_are_refused_naming_the_forced_ones(damped_pendulum):
    """A method that cannot take forces (rattle-6 has no forced version) is refused, naming
    those that can, the ordinary names among them; ConstrainedProblem of a forced system is
    a ForcedProblem."""
    problem = ForcedProblem(damped_pendulum, *_start(0.3))
    with pytest.raises(InputError, match="forced-rattle-2") as refused:
        dirac.integrate(problem, "rattle-6", t_end=1.0, dt=0.01)
    for name in ("auto", "rattle-2", "rattle-4", "midpoint", "scipy-DOP853", "conformal-2"):
        assert name in str(refused.value)
    assert isinstance(dirac.flows.ConstrainedProblem(damped_pendulum, *_start(0.3)), ForcedProblem)


def test_auto_chooses_a_forced_method(damped_pendulum):
    problem = ForcedProblem(damped_pendulum, *_start(0.3))
    sol = dirac.integrate(problem, "auto", t_end=2.0, tolerance=1e-8, samples=3)
    assert sol.method in ("forced-rattle-2", "forced-rattle-4", "conformal-2", "conformal-4")


def test_the_flows_of_the_full_phase_space_refuse_forces(damped_pendulum):
    from dirac.flows.analysed import AnalysedSystem

    with pytest.raises(InputError, match="generalized forces"):
        AnalysedSystem.from_analysis(dirac.analyze(damped_pendulum))
