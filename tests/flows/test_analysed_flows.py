"""Flows on the full phase space of the Dirac–Bergmann analysis (``dirac.analyze``):
the midpoint rule on ``z_dot = {z, H}_D`` for any analysed system, including Lagrangians
RATTLE cannot take (terms linear in the velocities)."""

from __future__ import annotations

import numpy as np
import pytest

from dirac.errors import InputError
from dirac.flows import integrate
from dirac.flows.analysed import AnalysedProblem, AnalysedSystem
from dirac.model.lagrangian import Lagrangian
from dirac.model.systems import load_system


@pytest.fixture(scope="module")
def analysed_pendulum():
    return AnalysedSystem.from_lagrangian(load_system("pendulum"))


def test_pendulum_on_the_full_phase_space_matches_the_elliptic_solution(analysed_pendulum):
    from test_flow_convergence import pendulum_exact

    assert analysed_pendulum.variable_names == ("x", "y", "lambda_1", "p_x", "p_y", "p_lambda_1")
    assert analysed_pendulum.n_constraints == 4  # four stages of one second-class constraint each
    theta = 1.0
    z0 = analysed_pendulum.initial_state({"x": np.sin(theta), "y": -np.cos(theta)}, q_dot={"x": 0.0, "y": 0.0})
    # fourth stage at rest (p = 0, x^2 + y^2 = 1): 4 lambda + 2 g y = 0, so lambda = -g y / 2
    assert z0[2] == pytest.approx(-9.81 * (-np.cos(theta)) / 2.0)
    problem = AnalysedProblem(analysed_pendulum, z0)
    q_ref, p_ref = pendulum_exact(theta, 2.0)
    errors = []
    for dt in (0.01, 0.005):
        solution = integrate(problem, "midpoint", t_end=2.0, dt=dt, samples=2, outputs=["q", "p", "constraint_residual"])
        errors.append(max(np.abs(solution["q"][-1][:2] - q_ref).max(), np.abs(solution["p"][-1][:2] - p_ref).max()))
        assert solution["constraint_residual"].max() < 1e-10
    assert 3.5 < errors[0] / errors[1] < 4.5  # order 2


def test_off_surface_state_is_refused(analysed_pendulum):
    with pytest.raises(InputError, match="off the constraint surface"):
        AnalysedProblem(analysed_pendulum, [0.5, -0.5, 0.0, 0.0, 0.0, 0.0])


def test_velocity_linear_lagrangian_runs_from_a_scene():
    """A charged bead on a vertical ring in a magnetic field: L has B/2 (x y_dot - y x_dot),
    which RATTLE refuses; the scene falls back to the analysed Dirac flow. The magnetic
    term does no work, so the energy is m/2 |v|^2 + m g y."""
    from dirac.io.scene import scene_from_dict

    scene = scene_from_dict({
        "system": {"name": "charged_ring", "coordinates": ["x", "y"],
                   "lagrangian": "m/2*(x_dot**2 + y_dot**2) + B/2*(x*y_dot - y*x_dot) - m*g*y",
                   "constraints": ["x**2 + y**2 - 1"], "parameters": {"m": 1.0, "g": 9.81, "B": 2.0}},
        "initial": {"q": {"x": 0.0, "y": -1.0}, "q_dot": {"x": 2.0, "y": 0.0}},
        "run": {"t_end": 3.0, "method": "midpoint", "dt": 0.002, "samples": 31,
                "outputs": ["q", "energy", "constraint_residual"]},
    })
    assert isinstance(scene.problem, AnalysedProblem)
    solution = integrate(scene.problem, **scene.run)
    assert solution["constraint_residual"].max() < 1e-10
    energy = solution["energy"]
    assert energy[0] == pytest.approx(0.5 * 4.0 - 9.81)
    assert np.abs(energy - energy[0]).max() < 1e-3
    q = solution["q"][:, :2]
    assert np.abs(np.sum(q * q, axis=1) - 1.0).max() < 1e-10
    with pytest.raises(InputError, match="linear in the velocities"):
        from dirac.flows import MechanicalSystem

        MechanicalSystem.from_lagrangian(Lagrangian.from_strings(
            "charged_ring", ["x", "y"], "x_dot**2/2 + y_dot**2/2 + B/2*(x*y_dot - y*x_dot)", ["x**2 + y**2 - 1"],
            {"B": 2.0}))
