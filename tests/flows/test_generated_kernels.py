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
