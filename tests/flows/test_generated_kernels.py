"""The per-system generated kernels on the configuration-dependent-mass path: RATTLE's
compositions keep their orders there too (the constant-mass path is covered by
test_flow_convergence)."""

from __future__ import annotations

import numpy as np
import pytest

from dirac.flows import ConstrainedProblem, MechanicalSystem, integrate
from dirac.flows.methods.registry import get_method
from dirac.model.lagrangian import Lagrangian


@pytest.fixture(scope="module")
def polar_pendulum():
    polar = Lagrangian.from_strings("polar_pendulum", ["r", "th"], "m/2*(r_dot**2 + r**2*th_dot**2) + m*g*r*cos(th)",
                                    constraints=["r - l"], parameters={"m": 1.0, "g": 9.81, "l": 1.0})
    system = MechanicalSystem.from_lagrangian(polar)
    assert system.constant_mass is None
    return system


@pytest.mark.parametrize("name, dts", [("rattle-2", [0.02, 0.01, 0.005]), ("rattle-4", [0.04, 0.02, 0.01])])
def test_configuration_dependent_mass_reaches_the_order(polar_pendulum, name, dts):
    """Pendulum in polar coordinates, M = diag(m, m r^2), r - l = 0: the same motion as the
    Cartesian pendulum, whose exact solution is the Jacobi-elliptic one (pendulum_exact).
    Halving dt divides the error at t = 2 by 2^order."""
    from test_flow_convergence import _slope, pendulum_exact

    theta = 1.0
    problem = ConstrainedProblem(polar_pendulum, [1.0, theta], [0.0, 0.0])
    q_ref, _ = pendulum_exact(theta, 2.0)
    errors = []
    for dt in dts:
        solution = integrate(problem, name, t_end=2.0, dt=dt, samples=1, outputs=["q", "constraint_residual"])
        r, th = solution["q"][-1]
        errors.append(np.abs([r * np.sin(th), -r * np.cos(th)] - q_ref).max())
        assert solution["constraint_residual"][-1] <= 1e-10
    assert min(errors) > 1e-11
    assert abs(_slope(dts, errors) - get_method(name).order) < 0.3, errors


def test_three_constraints_take_the_elimination_path():
    """A triple pendulum in Cartesian coordinates (unit masses and rods, m = 3 constraints:
    the unrolled constant-mass kernel solves its 3 x 3 multiplier systems by elimination):
    positions and velocities stay on the constraints to the Newton tolerance
    1e-12 (1 + |q|^2) <= 1.5e-11 (|q|^2 <= 1 + 4 + 9), and the energy error of
    rattle-2 (symplectic, order 2) drops by ~4 when dt is halved."""
    triple = Lagrangian.from_strings(
        "triple_pendulum", ["x1", "y1", "x2", "y2", "x3", "y3"],
        "(x1_dot**2 + y1_dot**2 + x2_dot**2 + y2_dot**2 + x3_dot**2 + y3_dot**2)/2 - g*(y1 + y2 + y3)",
        constraints=["x1**2 + y1**2 - 1", "(x2 - x1)**2 + (y2 - y1)**2 - 1", "(x3 - x2)**2 + (y3 - y2)**2 - 1"],
        parameters={"g": 9.81})
    angles = np.array([1.0, 0.5, -0.3])
    q0 = np.ravel(np.column_stack([np.cumsum(np.sin(angles)), -np.cumsum(np.cos(angles))]))
    problem = ConstrainedProblem(MechanicalSystem.from_lagrangian(triple), q0, np.zeros(6))
    drifts = []
    for dt in (0.002, 0.001):
        solution = integrate(problem, "rattle-2", t_end=1.0, dt=dt, samples=50,
                             outputs=["energy", "constraint_residual"])
        assert np.max(solution["constraint_residual"]) <= 1.5e-11
        drifts.append(np.max(np.abs(solution["energy"] - solution["energy"][0])))
    assert 3.2 <= drifts[0] / drifts[1] <= 4.8
