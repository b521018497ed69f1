"""Rigid bodies and heavy tops driven by external torques and angular impulses.

References are independent of the kick code: scipy's DOP853 at a tight tolerance on
Euler's equations written out here (``dM/dt = M x Omega + N``, ``dR/dt = R hat(Omega)``),
the exact free flow (:class:`dirac.rigidbody.exact.ExactRigidBodyFlow`) in rescaled time for
linear damping, and the closed form of a symmetric body under a constant body-axis torque.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from dirac.errors import DiracWarning, InputError
from dirac.flows import integrate
from dirac.flows.problems import HeavyTopProblem, RigidBodyProblem
from dirac.rigidbody.exact import ExactRigidBodyFlow

INERTIA = np.array([2.0, 1.0, 2.0 / 3.0])
M0 = np.array([np.cos(1.1), 0.0, np.sin(1.1)])

#: A torque that depends on R and t only (exact kicks) ...
KICKED = ("0.3*sin(2*t)", "0.2*R_31", "-0.1 + 0.1*R_33")
#: ... and one that depends on M and Omega too (implicit midpoint kicks).
DAMPED = ("-0.2*Omega_1 + 0.1*R_31*sin(t)", "-0.2*Omega_2 + 0.05*M_1*M_3", "-0.2*Omega_3")


def _kicked(M, R, t):
    return np.array([0.3 * np.sin(2 * t), 0.2 * R[2, 0], -0.1 + 0.1 * R[2, 2]])


def _damped(M, R, t):
    W = M / INERTIA
    return np.array([-0.2 * W[0] + 0.1 * R[2, 0] * np.sin(t), -0.2 * W[1] + 0.05 * M[0] * M[2], -0.2 * W[2]])


def _hat(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


_REFERENCES: dict = {}


def _reference(torque, t_end, weight=None):
    """Euler's equations with the torque, DOP853 at rtol = atol = 1e-13: M(t_end), R(t_end),
    W(t_end) (computed once per torque, time and weight)."""
    key = (torque.__name__, t_end, None if weight is None else tuple(weight))
    if key not in _REFERENCES:
        _REFERENCES[key] = _tight(torque, t_end, INERTIA, M0, weight)
    return _REFERENCES[key]


def _tight(torque, t_end, inertia, M, weight):

    def rhs(t, y):
        M, R = y[:3], y[3:12].reshape(3, 3)
        omega = M / inertia
        N = torque(M, R, t)
        dM = np.cross(M, omega) + N
        if weight is not None:
            dM = dM + np.cross(R[2], weight)
        return np.concatenate([dM, (R @ _hat(omega)).ravel(), [N @ omega]])

    y0 = np.concatenate([M, np.eye(3).ravel(), [0.0]])
    y = solve_ivp(rhs, (0.0, t_end), y0, method="DOP853", rtol=1e-13, atol=1e-13).y[:, -1]
    return y[:3], y[3:12].reshape(3, 3), y[12]


def _run(problem, method, t_end, dt, outputs=("M", "R", "work")):
    return integrate(problem, method, t_end=t_end, dt=dt, samples=2, outputs=list(outputs))


#: the standard test body violates the triangle inequality (it warns and runs)
pytestmark = pytest.mark.filterwarnings("ignore:inertia = .* violates the triangle inequality")


def _problem(torque, **extra):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DiracWarning)
        return RigidBodyProblem(INERTIA, M0, torque=list(torque), **extra)


@pytest.mark.parametrize("family", ["exact-kick", "lie-poisson"])
@pytest.mark.parametrize("order, dts", [(2, (0.1, 0.05)), (4, (0.2, 0.1)), (6, (0.4, 0.2)), (8, (0.8, 0.4))])
@pytest.mark.parametrize("torque, function", [(KICKED, _kicked), (DAMPED, _damped)], ids=["R-t torque", "damping"])
def test_every_method_has_its_order_on_a_torqued_body(family, order, dts, torque, function):
    """Error against the tight reference at dt and dt/2: the slope is the nominal order."""
    t_end = 4.0
    M_ref, R_ref, W_ref = _reference(function, t_end)
    problem = _problem(torque)
    errors = []
    for dt in dts:
        solution = _run(problem, f"{family}-{order}", t_end, dt)
        M, R, W = (solution.outputs[name][-1] for name in ("M", "R", "work"))
        errors.append(max(np.max(np.abs(M - M_ref)), np.max(np.abs(R - R_ref)), abs(W - W_ref)))
    slope = np.log2(errors[0] / errors[1])
    assert 1e-11 < errors[1] < 1e-2, errors  # asymptotic range, above round-off
    assert abs(slope - order) < 0.6, (errors, slope)


@pytest.mark.parametrize("method", ["exact-kick-8", "lie-poisson-8", "scipy-DOP853"])
def test_torqued_and_damped_bodies_agree_with_an_independent_integration(method):
    for torque, function in ((KICKED, _kicked), (DAMPED, _damped)):
        M_ref, R_ref, W_ref = _reference(function, 10.0)
        solution = integrate(_problem(torque), method, t_end=10.0, dt=0.02, samples=2, tolerance=1e-12,
                             outputs=["M", "R", "work"])
        assert np.max(np.abs(solution.outputs["M"][-1] - M_ref)) < 1e-9
        assert np.max(np.abs(solution.outputs["R"][-1] - R_ref)) < 1e-9
        assert abs(solution.outputs["work"][-1] - W_ref) < 1e-9


def test_linear_damping_decays_as_exp_minus_k_t_along_the_free_flow_in_rescaled_time():
    """N = -k M: with M = exp(-k t) m, dm/ds = m x I^-1 m and dR/ds = R hat(I^-1 m) for
    s = (1 - exp(-k t)) / k, i.e. the free flow run to the time s (derived by hand:
    dM/dt = -k M + exp(-k t) m' ds/dt and M x Omega = exp(-2 k t) m x I^-1 m)."""
    k = 0.3
    t = np.linspace(0.0, 6.0, 7)
    problem = _problem((f"-{k}*M_1", f"-{k}*M_2", f"-{k}*M_3"))
    solution = integrate(problem, "exact-kick-8", t_end=6.0, dt=0.01, samples=7,
                         outputs=["M", "R", "energy", "work", "casimir"])
    s = (1.0 - np.exp(-k * t)) / k
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DiracWarning)
        M_free, R_free = ExactRigidBodyFlow(INERTIA, M0).state(s)
    assert np.max(np.abs(solution.outputs["M"] - np.exp(-k * t)[:, None] * M_free)) < 1e-11
    assert np.max(np.abs(solution.outputs["R"] - R_free)) < 1e-11
    assert np.allclose(np.sqrt(solution.outputs["casimir"]), np.linalg.norm(M0) * np.exp(-k * t), rtol=1e-11, atol=0)
    energy = solution.outputs["energy"]
    assert np.allclose(energy, energy[0] * np.exp(-2 * k * t), rtol=1e-10, atol=0)
    assert np.max(np.abs(energy - solution.outputs["work"] - energy[0])) < 1e-11


def test_a_symmetric_body_under_a_constant_axial_torque_follows_the_closed_form():
    """I_1 = I_2, N = (0, 0, c): M_3 = M_3(0) + c t and M_1 + i M_2 turns by
    -(1/I_3 - 1/I_1)(M_3(0) t + c t^2 / 2) (Euler's equations, (M x Omega)_3 = 0)."""
    inertia = np.array([1.5, 1.5, 0.8])
    c = 0.3
    start = np.array([0.4, -0.2, 1.0])
    problem = RigidBodyProblem(inertia, start, torque=["0", "0", str(c)])
    t = np.linspace(0.0, 5.0, 6)
    M = integrate(problem, "lie-poisson-4", t_end=5.0, dt=0.01, samples=6, outputs=["M"]).outputs["M"]
    phase = -(1 / inertia[2] - 1 / inertia[0]) * (start[2] * t + c * t**2 / 2)
    turned = (start[0] + 1j * start[1]) * np.exp(1j * phase)
    assert np.allclose(M[:, 2], start[2] + c * t, atol=1e-13)
    assert np.allclose(M[:, 0] + 1j * M[:, 1], turned, atol=1e-12)


@pytest.mark.parametrize("method, bound", [("exact-kick-4", 1e-13), ("lie-poisson-4", 1e-5)])
def test_energy_minus_work_is_kept_by_the_kick_compositions(method, bound):
    """The exact free flow keeps E exactly (a Lie-Poisson step to its error); an exact kick changes E by d·I^-1(M_0 + d/2) with
    d = h N and adds h N·I^-1(M_0 + d/2) to W; a midpoint kick changes E by
    (M_1 - M_0)·I^-1 X = h N(X)·I^-1 X, what it adds to W. So E - W is conserved to
    round-off by exact-kick-* on a torqued free body, whatever the step (a heavy top, or
    lie-poisson-*: to the method error)."""
    solution = integrate(_problem(DAMPED), method, t_end=20.0, dt=0.1, samples=21, outputs=["energy", "work"])
    energy, work = solution.outputs["energy"], solution.outputs["work"]
    assert energy[-1] < 0.5 * energy[0]  # the energy is not conserved ...
    assert np.max(np.abs(energy - work - energy[0])) < bound  # ... energy - work is


def test_energy_minus_work_drifts_with_an_rk_method_at_its_tolerance():
    solution = integrate(_problem(DAMPED), "scipy-RK45", t_end=20.0, samples=21, tolerance=1e-6,
                         outputs=["energy", "work"])
    drift = np.max(np.abs(solution.outputs["energy"] - solution.outputs["work"] - solution.outputs["energy"][0]))
    assert 1e-12 < drift < 1e-4


def test_an_angular_impulse_makes_M_jump_at_its_time_and_the_steps_land_there():
    """Free body, impulse J at t = 0.37 (between steps of 0.1): the exact flow to 0.37,
    the jump, the exact flow on; exact-kick-* is exact for a free body, so only if the steps
    land on 0.37 does it agree to round-off."""
    jump = np.array([0.1, -0.2, 0.05])
    problem = _problem(("0", "0", "0"), impulses=[(0.37, jump)])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DiracWarning)
        M_a, R_a = ExactRigidBodyFlow(INERTIA, M0).state(np.array([0.37]))
        M_b, R_b = ExactRigidBodyFlow(INERTIA, M_a[0] + jump, R_a[0]).state(np.array([1.0 - 0.37]))
    energy = lambda M: 0.5 * np.sum(M * M / INERTIA)  # noqa: E731
    for method in ("exact-kick-2", "scipy-DOP853"):
        solution = integrate(problem, method, t_end=1.0, dt=0.1, samples=2, tolerance=1e-13,
                             outputs=["M", "R", "work", "energy"])
        assert np.max(np.abs(solution.outputs["M"][-1] - M_b[0])) < 1e-11, method
        assert np.max(np.abs(solution.outputs["R"][-1] - R_b[0])) < 1e-11, method
        assert solution.outputs["work"][-1] == pytest.approx(energy(M_a[0] + jump) - energy(M_a[0]), abs=1e-12)
        assert solution.outputs["energy"][-1] - solution.outputs["work"][-1] == pytest.approx(energy(M0), abs=1e-11)


def test_an_impulse_at_a_sample_time_shows_in_that_sample_and_one_at_zero_in_the_first():
    problem = _problem(("0", "0", "0"), impulses=[(0.0, [0.0, 0.5, 0.0]), (0.5, [0.0, 0.0, 1.0])])
    solution = integrate(problem, "exact-kick-2", t_end=1.0, dt=0.05, samples=3, outputs=["M"])
    assert solution.outputs["M"][0] == pytest.approx(M0 + [0.0, 0.5, 0.0])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DiracWarning)
        M_half = ExactRigidBodyFlow(INERTIA, M0 + [0.0, 0.5, 0.0]).M(np.array([0.5]))[0]
    assert np.max(np.abs(solution.outputs["M"][1] - (M_half + [0.0, 0.0, 1.0]))) < 1e-12


def test_a_torqued_heavy_top_agrees_with_an_independent_integration():
    weight = np.array([0.0, 0.3, 1.0]) * 2.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DiracWarning)
        problem = HeavyTopProblem(INERTIA, M0, mass_gravity=2.0, center_of_mass=[0.0, 0.3, 1.0], torque=list(DAMPED))
    M_ref, R_ref, W_ref = _reference(_damped, 5.0, weight=weight)
    for method in ("exact-kick-6", "lie-poisson-6"):
        solution = integrate(problem, method, t_end=5.0, dt=0.01, samples=2, outputs=["M", "R", "work", "energy"])
        assert np.max(np.abs(solution.outputs["M"][-1] - M_ref)) < 1e-9, method
        assert np.max(np.abs(solution.outputs["R"][-1] - R_ref)) < 1e-9, method
        assert abs(solution.outputs["work"][-1] - W_ref) < 1e-9, method
        energy = solution.outputs["energy"]
        assert abs(energy[-1] - solution.outputs["work"][-1] - energy[0]) < 1e-9


def test_auto_chooses_a_method_that_handles_torques():
    solution = integrate(_problem(DAMPED), "auto", t_end=10.0, samples=2, tolerance=1e-8, outputs=["M", "R"])
    chosen = solution.extra["auto"]["chosen"]
    assert chosen.startswith(("exact-kick-", "lie-poisson-"))
    M_ref, R_ref, _ = _reference(_damped, 10.0)
    assert np.max(np.abs(solution.outputs["M"][-1] - M_ref)) < 1e-6


@pytest.mark.parametrize("method", ["exact", "midpoint"])
def test_methods_without_torques_are_refused_naming_those_with(method):
    with pytest.raises(InputError, match=r"cannot integrate an external torque; use one of: auto, .*lie-poisson-4.*"
                       r"exact-kick-4"):
        integrate(_problem(KICKED), method, t_end=1.0, dt=0.1)
    with pytest.raises(InputError, match="cannot integrate angular impulses"):
        integrate(RigidBodyProblem(INERTIA, M0, impulses=[(0.5, [1, 0, 0])]), method, t_end=1.0, dt=0.1)


@pytest.mark.parametrize("torque, match", [
    (["0", "0"], "must be three expressions"),
    (["0", "0", "0", "0"], "must be three expressions"),
    (["0", "Omega1", "0"], "unknown name 'Omega1' \\(did you mean 'Omega_1'"),
    (["0", "0", "M_4"], "unknown name 'M_4'"),
    (["0", "__import__('os')", "0"], "not allowed"),
])
def test_bad_torques_are_refused(torque, match):
    with pytest.raises(InputError, match=match):
        RigidBodyProblem(INERTIA, M0, torque=torque)


@pytest.mark.parametrize("method", ["lie-poisson-2", "lie-poisson-4", "exact-kick-4"])
def test_several_impulses_inside_one_step_each_act_at_its_time(method):
    """A sphere (I_1 = I_2 = I_3 = I) spinning about e_3 with impulses along e_3: M stays on e_3
    and the body turns about e_3 by, by hand, (M_3(0) T + sum_i J_i (T - t_i)) / I. Impulses at
    0.55, 0.57 (two) and 0.8 with dt = 0.1: three fall inside one step. The later ones of that
    step acted at its end (the angle was off by 0.0075 / I)."""
    impulses = [(0.55, [0, 0, 1.0]), (0.57, [0, 0, 0.5]), (0.57, [0, 0, -0.25]), (0.8, [0, 0, 0.125])]
    problem = RigidBodyProblem(inertia=[2.0, 2.0, 2.0], M0=[0.0, 0.0, 0.4], impulses=impulses)
    sol = integrate(problem, method, t_end=1.0, dt=0.1, samples=3, outputs=["M", "R"])
    R = sol.outputs["R"][-1]
    angle = (0.4 * 1.0 + sum(J[2] * (1.0 - t) for t, J in impulses)) / 2.0
    assert np.allclose(sol.outputs["M"][-1], [0.0, 0.0, 1.775], rtol=0, atol=1e-14)
    assert math.atan2(R[1, 0], R[0, 0]) == pytest.approx(angle, abs=1e-13)


def test_an_impulse_before_the_start_is_refused():
    with pytest.raises(InputError, match="before the start"):
        RigidBodyProblem(INERTIA, M0, impulses=[(-0.1, [1.0, 0.0, 0.0])])


def test_a_midpoint_kick_that_does_not_converge_stops_the_run_with_a_message():
    from dirac.errors import IntegrationError

    with pytest.raises(IntegrationError, match="implicit midpoint kick of the torque did not converge in 1 Newton") as info:
        integrate(_problem(DAMPED), "lie-poisson-2", t_end=1.0, dt=0.1, max_newton_iterations=1)
    assert info.value.partial is not None and not info.value.partial.complete


def test_impulses_on_a_torqued_body_agree_with_scipy_restarted_at_the_impulse():
    """Impulse at t = 1.234 (off the grid of dt = 0.05) on the damped body: the kick
    compositions against the independent DOP853 integration stopped there and restarted."""
    jump = np.array([0.3, 0.0, -0.2])
    problem = _problem(DAMPED, impulses=[(1.234, jump)])
    M_a, R_a, W_a = _reference(_damped, 1.234)

    def rhs(t, y):
        M, R = y[:3], y[3:12].reshape(3, 3)
        omega = M / INERTIA
        N = _damped(M, R, t)
        return np.concatenate([np.cross(M, omega) + N, (R @ _hat(omega)).ravel(), [N @ omega]])

    energy = lambda M: 0.5 * np.sum(M * M / INERTIA)  # noqa: E731
    y0 = np.concatenate([M_a + jump, R_a.ravel(), [W_a + energy(M_a + jump) - energy(M_a)]])
    y = solve_ivp(rhs, (1.234, 3.0), y0, method="DOP853", rtol=1e-13, atol=1e-13).y[:, -1]
    for method in ("exact-kick-6", "lie-poisson-6"):
        solution = integrate(problem, method, t_end=3.0, dt=0.05, samples=2, outputs=["M", "R", "work"])
        assert np.max(np.abs(solution.outputs["M"][-1] - y[:3])) < 1e-9, method
        assert np.max(np.abs(solution.outputs["R"][-1] - y[3:12].reshape(3, 3))) < 1e-9, method
        assert abs(solution.outputs["work"][-1] - y[12]) < 1e-9, method


def test_a_free_body_run_does_not_import_the_expression_parser():
    """The torque parser (sympy) is imported only for a torque: the free body's start-up
    is unchanged."""
    import subprocess
    import sys

    code = ("import sys; from dirac import RigidBodyProblem, integrate; "
            "integrate(RigidBodyProblem([1.0, 2.0, 3.0], [1.0, 0.0, 0.1]), 'lie-poisson-4', t_end=1.0, dt=0.1); "
            "integrate(RigidBodyProblem([1.0, 2.0, 3.0], [1.0, 0.0, 0.1]), 'scipy-DOP853', t_end=1.0); "
            "print('sympy' in sys.modules)")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert result.stdout.strip() == "False"
