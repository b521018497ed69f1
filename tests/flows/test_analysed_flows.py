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


def _refuse_to_analyse(monkeypatch):
    """Make every entry point of the Dirac-Bergmann analysis raise."""
    import dirac.analysis.constraint_analysis as constraint_analysis

    def refuse(*args, **kwargs):
        raise AssertionError("the system was analysed again")

    monkeypatch.setattr(constraint_analysis, "analyze", refuse)
    monkeypatch.setattr(constraint_analysis.ConstraintAnalysis, "__init__", refuse)


def test_from_analysis_hands_on_the_analysis_and_gives_the_flow_of_from_lagrangian(analysed_pendulum, monkeypatch):
    """``Lagrangian -> analyze -> AnalysedSystem.from_analysis``: the analysis a user holds is
    used as it is (not run again) and gives the same flow as ``from_lagrangian``."""
    import dirac

    analysis = dirac.analyze(load_system("pendulum").with_defaults())
    _refuse_to_analyse(monkeypatch)
    flow = AnalysedSystem.from_analysis(analysis)
    assert flow.analysis is analysis
    assert flow.variable_names == analysed_pendulum.variable_names
    assert flow.n_constraints == analysed_pendulum.n_constraints
    assert flow.parameter_values == analysed_pendulum.parameter_values == {"m": 1.0, "g": 9.81, "l": 1.0}
    q, q_dot = {"x": np.sin(0.7), "y": -np.cos(0.7)}, {"x": 0.3 * np.cos(0.7), "y": 0.3 * np.sin(0.7)}
    z0 = flow.initial_state(q, q_dot=q_dot)  # Gauss-Newton from a random start: equal up to round-off
    assert np.allclose(z0, analysed_pendulum.initial_state(q, q_dot=q_dot), rtol=1e-13, atol=1e-13)
    assert flow.module is analysed_pendulum.module  # the same generated code
    assert np.array_equal(flow.field(z0), analysed_pendulum.field(z0))
    assert flow.energy(z0) == analysed_pendulum.energy(z0)
    assert flow.constraint_residual(z0) == analysed_pendulum.constraint_residual(z0)


def test_from_analysis_with_symbolic_parameters_runs_them_at_their_defaults(analysed_pendulum, monkeypatch):
    """Parameters left symbolic in the analysis are given their defaults at run time: the
    same field as the analysis at fixed values, up to round-off."""
    import dirac

    analysis = dirac.analyze(load_system("pendulum", l=1.0))  # m and g stay symbolic
    without_default = dirac.analyze(
        Lagrangian.from_strings("spring", ["x"], "x_dot**2/2 - k*x**2/2", parameters={"k": None}))
    _refuse_to_analyse(monkeypatch)
    flow = AnalysedSystem.from_analysis(analysis)
    assert flow.parameter_values == {"l": 1.0, "m": 1.0, "g": 9.81}
    assert sorted(flow.params.tolist()) == [1.0, 9.81]
    q, q_dot = {"x": np.sin(0.7), "y": -np.cos(0.7)}, {"x": 0.3 * np.cos(0.7), "y": 0.3 * np.sin(0.7)}
    z0 = flow.initial_state(q, q_dot=q_dot)
    assert np.allclose(z0, analysed_pendulum.initial_state(q, q_dot=q_dot), rtol=1e-13, atol=1e-13)
    assert np.allclose(flow.field(z0), analysed_pendulum.field(z0), rtol=1e-12, atol=1e-12)
    assert flow.energy(z0) == pytest.approx(analysed_pendulum.energy(z0), rel=1e-13)
    with pytest.raises(InputError, match="parameters k have no value"):
        AnalysedSystem.from_analysis(without_default)


def test_mechanical_system_from_analysis_is_the_one_from_its_lagrangian(monkeypatch):
    import dirac
    from dirac.flows import MechanicalSystem

    analysis = dirac.analyze(load_system("pendulum"))
    _refuse_to_analyse(monkeypatch)
    mechanics = MechanicalSystem.from_analysis(analysis, {"l": 2.0})
    reference = MechanicalSystem.from_lagrangian(load_system("pendulum"), {"l": 2.0})
    assert mechanics.coordinate_names == reference.coordinate_names
    assert mechanics.parameter_values == reference.parameter_values
    q, p = np.array([0.6, -np.sqrt(4.0 - 0.36)]), np.array([0.2, 0.1])
    assert mechanics.energy(q, p) == reference.energy(q, p)
    assert np.array_equal(mechanics.residuals(q, p)[0], reference.residuals(q, p)[0])


@pytest.mark.parametrize("not_an_analysis", [load_system("pendulum"), None, "pendulum"])
def test_from_analysis_refuses_anything_but_an_analysis(not_an_analysis):
    from dirac.flows import MechanicalSystem

    for build in (AnalysedSystem.from_analysis, MechanicalSystem.from_analysis):
        with pytest.raises(InputError, match="from_analysis needs the result of dirac.analyze"):
            build(not_an_analysis)


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
    from dirac.flows import MechanicalSystem
    from dirac.flows.mechanics import NotMechanicalError

    with pytest.raises(NotMechanicalError, match="linear in the velocities"):  # an InputError the scene catches
        MechanicalSystem.from_lagrangian(Lagrangian.from_strings(
            "charged_ring", ["x", "y"], "x_dot**2/2 + y_dot**2/2 + B/2*(x*y_dot - y*x_dot)", ["x**2 + y**2 - 1"],
            {"B": 2.0}))
