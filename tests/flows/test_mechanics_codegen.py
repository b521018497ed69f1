"""The mechanical split of a Lagrangian (mass matrix, potential, constraints) into
generated numba functions; the code generator itself is tested in tests/codegen."""

from __future__ import annotations

import numpy as np
import pytest

from dirac.errors import InputError
from dirac.flows import ConstrainedProblem, MechanicalSystem, integrate
from dirac.model.lagrangian import Lagrangian


def test_mass_matrix_potential_and_constraints_are_extracted(pendulum_system):
    assert pendulum_system.coordinate_names == ("x", "y")
    assert np.array_equal(pendulum_system.constant_mass, np.eye(2))
    q, p = np.array([0.6, -0.8]), np.array([0.8, 0.6])
    assert pendulum_system.energy(q, p) == pytest.approx(0.5 * 1.0 - 9.81 * 0.8)
    chi, velocity = pendulum_system.residuals(q, p)
    assert chi == pytest.approx([0.0], abs=1e-15) and velocity == pytest.approx([0.0], abs=1e-15)


@pytest.mark.parametrize(
    "lagrangian, match",
    [
        ("x_dot**2/2 + B*x*y_dot + y_dot**2/2", "linear in the velocities"),
        ("x_dot**4/4 + y_dot**2/2", "not quadratic"),
    ],
)
def test_lagrangians_rattle_cannot_take_are_refused(lagrangian, match):
    system = Lagrangian.from_strings("odd", ["x", "y"], lagrangian, parameters={"B": 1.0})
    with pytest.raises(InputError, match=match):
        MechanicalSystem.from_lagrangian(system)


def test_missing_parameter_values_are_named():
    system = Lagrangian.from_strings("spring", ["x"], "x_dot**2/2 - k*x**2/2", parameters={"k": None})
    with pytest.raises(InputError, match="parameters k have no value"):
        MechanicalSystem.from_lagrangian(system)
    assert MechanicalSystem.from_lagrangian(system, {"k": 4.0}).parameter_values == {"k": 4.0}


def test_position_dependent_mass_takes_the_general_rattle_path():
    """Pendulum in polar coordinates, L = m/2 (r_dot^2 + r^2 th_dot^2) + m g r cos th with
    r - l = 0: mass matrix diag(m, m r^2) depends on q. Same motion as the Cartesian
    pendulum (Jacobi-elliptic reference)."""
    from test_flow_convergence import pendulum_exact

    polar = Lagrangian.from_strings("polar_pendulum", ["r", "th"], "m/2*(r_dot**2 + r**2*th_dot**2) + m*g*r*cos(th)",
                                    constraints=["r - l"], parameters={"m": 1.0, "g": 9.81, "l": 1.0})
    system = MechanicalSystem.from_lagrangian(polar)
    assert system.constant_mass is None
    theta = 1.0
    problem = ConstrainedProblem(system, [1.0, theta], [0.0, 0.0])
    errors = []
    for dt in (0.02, 0.01):
        solution = integrate(problem, "rattle-2", t_end=2.0, dt=dt, samples=2, outputs=["q", "constraint_residual"])
        r, th = solution["q"][-1]
        q_ref, _ = pendulum_exact(theta, 2.0)
        errors.append(np.abs([r * np.sin(th), -r * np.cos(th)] - q_ref).max())
        assert solution["constraint_residual"].max() < 1e-11
    assert 3.5 < errors[0] / errors[1] < 4.5  # second order
    midpoint = integrate(problem, "midpoint", t_end=2.0, dt=0.005, samples=2, outputs=["q"])
    r, th = midpoint["q"][-1]
    assert np.abs([r * np.sin(th), -r * np.cos(th)] - q_ref).max() < 1e-3


def test_a_constant_mass_is_checked_once_and_again_when_it_changes(monkeypatch):
    """The positivity of a constant mass matrix is checked at its first use and whenever its values change
    (a matrix set singular afterwards is refused), not at every sample."""
    from dirac.model.systems import load_system

    system = MechanicalSystem.from_lagrangian(load_system("pendulum"))  # its own: the mass is changed below
    calls = []
    eigvalsh = np.linalg.eigvalsh
    monkeypatch.setattr(np.linalg, "eigvalsh", lambda a: calls.append(1) or eigvalsh(a))
    assert system.constant_mass is not None
    q = np.zeros(system.dimension)
    for _ in range(5):
        np.testing.assert_array_equal(system.mass_matrix(q), system.constant_mass)
    assert len(calls) <= 1
    system.constant_mass[0, 0] = 0.0
    with pytest.raises(InputError, match="singular or not positive"):
        system.mass_matrix(q)
