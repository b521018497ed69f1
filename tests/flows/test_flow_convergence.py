"""Observed convergence order of every time-stepping method, through ``integrate``.

The error at a fixed final time is fitted against the step size on a log-log scale; the
slope must be within 0.3 of ``method.order``. References are independent of the method
under test: the exact elliptic flow (rigid body; checked against DOP853 elsewhere), the
pendulum's Jacobi-elliptic solution, and a tight-tolerance DOP853 run (heavy top).
"""

from __future__ import annotations

import numpy as np
import pytest

from dirac.flows import HeavyTopProblem, RigidBodyProblem, integrate
from dirac.flows.methods.registry import METHODS, get_method
from dirac.flows.methods.rigid_body_stepper import exact_flow


def _slope(dts, errors) -> float:
    return float(np.polyfit(np.log(dts), np.log(errors), 1)[0])


STEPS_BY_ORDER = {2: [0.1, 0.05, 0.025], 4: [0.2, 0.1, 0.05], 6: [0.5, 0.4, 0.32, 0.25], 8: [0.5, 0.4, 0.32]}


def _rigid_body_methods() -> list[str]:
    """The fixed-step methods of the free body (``exact-kick-*`` is exact there, its kicks
    being zero: its orders are measured under a torque, tests/flows/test_torqued_rigid_body.py)."""
    return [n for n, m in METHODS.items() if m.accepts("rigid_body") and m.kind == "fixed"
            and not n.startswith("exact-kick-")]


@pytest.mark.parametrize("name", _rigid_body_methods())
def test_rigid_body_methods_reach_their_order(name):
    inertia, M0 = np.array([1.0, 2.0, 3.0]), np.array([0.6, 0.8, 0.5])
    problem = RigidBodyProblem(inertia, M0)
    T = 20.0
    M_ref, R_ref = exact_flow(inertia, M0, np.eye(3)).state([T])
    method = get_method(name)
    dts = STEPS_BY_ORDER[method.order]
    errors = []
    for dt in dts:
        solution = integrate(problem, name, t_end=T, dt=dt, samples=1, outputs=["M", "R"])
        errors.append(max(np.abs(solution["M"][-1] - M_ref[0]).max(), np.abs(solution["R"][-1] - R_ref[0]).max()))
    assert abs(_slope(dts, errors) - method.order) < 0.3, (name, errors)


HEAVY_STEPS = {2: [0.04, 0.02, 0.01], 4: [0.2, 0.1, 0.05], 6: [0.2, 0.1, 0.05], 8: [0.4, 0.3, 0.2]}


@pytest.mark.parametrize("name", ["lie-poisson-2", "lie-poisson-4", "lie-poisson-6", "lie-poisson-8",
                                  "lie-poisson-sym-4", "exact-kick-2", "exact-kick-4"])
def test_heavy_top_methods_reach_their_order(name):
    problem = HeavyTopProblem([1.0, 2.0, 3.0], [1.0, 0.5, 2.0], mass_gravity=0.5, center_of_mass=[0.1, 0.2, 0.5])
    reference = integrate(problem, "scipy-DOP853", t_end=2.0, samples=1, outputs=["M", "R"], tolerance=1e-13)
    method = get_method(name)
    dts = HEAVY_STEPS[method.order]
    errors = []
    for dt in dts:
        solution = integrate(problem, name, t_end=2.0, dt=dt, samples=1, outputs=["M", "R"])
        errors.append(max(np.abs(solution["M"] - reference["M"]).max(), np.abs(solution["R"] - reference["R"]).max()))
    assert min(errors) > 1e-12  # the fit is above round-off
    assert abs(_slope(dts, errors) - method.order) < 0.3, (name, errors)


def pendulum_exact(theta0: float, t: float, g: float = 9.81, length: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Pendulum released from rest at angle ``theta0`` (unit mass): with ``k = sin(theta0/2)``,
    ``omega = sqrt(g/l)``, ``u = K(k^2) - omega t``: ``theta = 2 asin(k sn u)``,
    ``theta_dot = -2 k omega cn u``; ``x = l sin theta``, ``y = -l cos theta``, ``p = q_dot``."""
    from scipy.special import ellipj, ellipk

    k = np.sin(theta0 / 2.0)
    omega = np.sqrt(g / length)
    sn, cn, _dn, _ph = ellipj(ellipk(k * k) - omega * t, k * k)
    theta = 2.0 * np.arcsin(k * sn)
    theta_dot = -2.0 * k * omega * cn
    q = length * np.array([np.sin(theta), -np.cos(theta)])
    p = length * theta_dot * np.array([np.cos(theta), np.sin(theta)])
    return q, p


CONSTRAINED_STEPS = {"rattle-2": [0.02, 0.01, 0.005], "rattle-4": [0.04, 0.02, 0.01], "rattle-6": [0.08, 0.04, 0.02],
                     "rattle-8": [0.1, 0.08, 0.064, 0.05], "midpoint": [0.02, 0.01, 0.005]}
#: the order-8 composition needs a longer span to leave round-off behind
CONSTRAINED_SPAN = {"rattle-8": 10.0}


@pytest.mark.parametrize("name", sorted(CONSTRAINED_STEPS))
def test_constrained_methods_reach_their_order(name, pendulum_system):
    from dirac.flows import ConstrainedProblem

    theta = 1.0
    problem = ConstrainedProblem(pendulum_system, [np.sin(theta), -np.cos(theta)], [0.0, 0.0])
    span = CONSTRAINED_SPAN.get(name, 2.0)
    q_ref, p_ref = pendulum_exact(theta, span)
    method = get_method(name)
    dts = CONSTRAINED_STEPS[name]
    errors = []
    for dt in dts:
        solution = integrate(problem, name, t_end=span, dt=dt, samples=1, outputs=["q", "p"])
        errors.append(max(np.abs(solution["q"][-1] - q_ref).max(), np.abs(solution["p"][-1] - p_ref).max()))
    assert min(errors) > 1e-11
    assert abs(_slope(dts, errors) - method.order) < 0.3, (name, errors)


@pytest.mark.parametrize("name", ["scipy-RK45", "scipy-DOP853"])
def test_scipy_baselines_reach_their_order_with_pinned_steps(name):
    """The baselines integrate the same vector field as the stepper; with the step pinned
    (``first_step = max_step = h`` and a tolerance that accepts every step) scipy's pair
    shows its propagated order (5 for RK45, 8 for DOP853)."""
    from scipy import integrate as scipy_integrate

    inertia, M0 = np.array([1.0, 2.0, 3.0]), np.array([0.6, 0.8, 0.5])
    problem = RigidBodyProblem(inertia, M0)
    method = get_method(name)
    stepper = method.start(problem, ("M", "R"), {"t_end": 4.0, "tolerance": 1e-8})
    T = 4.0
    M_ref, R_ref = exact_flow(inertia, M0, np.eye(3)).state([T])
    exact = np.concatenate([M_ref[0], R_ref[0].ravel()])
    dts = [0.4, 0.2, 0.1] if name == "scipy-RK45" else [0.8, 0.4, 0.2]
    errors = []
    for h in dts:
        solver = getattr(scipy_integrate, name[6:])(
            lambda t, y: stepper._fun(t, y, *stepper._args), 0.0, stepper.y[0].copy(), T,
            first_step=h, max_step=h, rtol=1e3, atol=1e3)
        while solver.status == "running":
            solver.step()
        errors.append(np.abs(solver.y - exact).max())
    expected = 5 if name == "scipy-RK45" else 8
    assert abs(_slope(dts, errors) - expected) < 0.3, errors


@pytest.mark.parametrize("name", ["scipy-RK45", "scipy-DOP853"])
def test_scipy_baselines_error_follows_tolerance(name, standard_problem):
    """Adaptive baselines: the error at t = 10 against the 40-digit M(10) of docs/conventions.md
    shrinks with the tolerance and stays within a modest factor of it."""
    reference = np.array([0.40706613658804081, 0.28300742681284408, 0.86844916766156164])
    errors = []
    for tolerance in (1e-6, 1e-10):
        solution = integrate(standard_problem, name, t_end=10.0, samples=2, outputs=["M"], tolerance=tolerance)
        errors.append(np.abs(solution["M"][-1] - reference).max())
        assert errors[-1] < 1e3 * tolerance
    assert errors[1] < 1e-2 * errors[0]
