"""ConstrainedProblem takes a Lagrangian as it comes from the user (README example)."""

from __future__ import annotations

import numpy as np
import pytest

import dirac


def test_constrained_problem_accepts_a_lagrangian_directly():
    pendulum = dirac.load_system("pendulum")
    problem = dirac.ConstrainedProblem(pendulum, q0=[0.6, -0.8], p0=[0.0, 0.0])
    assert list(problem.mechanics.coordinate_names) == ["x", "y"]
    with pytest.raises(dirac.InputError, match="off the constraint surface"):
        dirac.ConstrainedProblem(pendulum, q0=[0.6, -0.7], p0=[0.0, 0.0])


def test_velocities_are_taken_as_in_scenes(pendulum_system):
    # pendulum m = 1, l = 1: p = m q_dot; a tangent velocity at (0.6, -0.8) is along (0.8, 0.6)
    problem = dirac.ConstrainedProblem(pendulum_system, q0=[0.6, -0.8], qdot0=[0.8 * 1.5, 0.6 * 1.5])
    assert problem.p0[0] == pytest.approx([1.2, 0.9], abs=1e-15)
    with pytest.raises(dirac.InputError, match="p0 or the initial velocities qdot0"):
        dirac.ConstrainedProblem(pendulum_system, q0=[0.6, -0.8])
    with pytest.raises(dirac.InputError, match="one of them"):
        dirac.ConstrainedProblem(pendulum_system, q0=[0.6, -0.8], p0=[0.0, 0.0], qdot0=[0.0, 0.0])


def test_off_surface_data_are_refused_with_python_advice_or_projected(pendulum_system):
    with pytest.raises(dirac.InputError, match="pass project=True") as refused:
        dirac.ConstrainedProblem(pendulum_system, q0=[0.6, -0.7], qdot0=[0.0, 0.0])
    assert "[initial]" not in str(refused.value)  # scene advice only in scenes
    with pytest.raises(dirac.InputError, match="not tangent.*pass project=True"):
        dirac.ConstrainedProblem(pendulum_system, q0=[0.6, -0.8], qdot0=[0.6, -0.8])
    projected = dirac.ConstrainedProblem(pendulum_system, q0=[0.6, -0.7], qdot0=[0.6, -0.8], project=True)
    q, p = projected.q0[0], projected.p0[0]
    assert q @ q == pytest.approx(1.0, abs=1e-13) and q @ p == pytest.approx(0.0, abs=1e-13)
    # M = identity: the closest point of the circle lies along q0, the tangent part of p is kept
    assert q == pytest.approx(np.array([0.6, -0.7]) / np.hypot(0.6, 0.7), abs=1e-12)
    tangent = np.array([q[1], -q[0]])
    assert p == pytest.approx((np.array([0.6, -0.8]) @ tangent) * tangent, abs=1e-12)


def test_scene_off_surface_advice_names_the_scene_option(tmp_path, run_cli):
    scene = tmp_path / "off.toml"
    scene.write_text('[system]\nname = "pendulum"\n[initial]\nq = { x = 0.6, y = -0.7 }\n[run]\nt_end = 1.0\n',
                     encoding="utf-8")
    status, _, stderr = run_cli("run", str(scene), "--no-progress")
    assert status == 2 and "set project = true in [initial]" in stderr and "project=True" not in stderr


def test_a_velocity_linear_lagrangian_is_refused_with_the_python_road_that_runs_it():
    """A charged particle in a uniform field, ``L = m v^2/2 + B (x y' - y x')/2``: ``ConstrainedProblem``
    refuses it naming the Python road (a scene takes it by itself), and that road runs it. By hand,
    ``m x'' = B y'``, ``m y'' = -B x'``: from ``(1, 0)`` with velocity ``(0, 2)``, ``m = 1``, ``B = 2``,
    ``x = 2 - cos 2t``, ``y = sin 2t``. The forced variant names no road that cannot take its forces."""
    import re

    from dirac.flows.analysed import AnalysedProblem, AnalysedSystem
    from dirac.flows.mechanics import NotMechanicalError

    text = "m*(x_dot**2 + y_dot**2)/2 + B*(x*y_dot - y*x_dot)/2"
    L = dirac.Lagrangian.from_strings("cyclotron", ["x", "y"], text, [], parameters={"m": 1.0, "B": 2.0})
    with pytest.raises(NotMechanicalError, match="linear in the velocities") as caught:
        dirac.ConstrainedProblem(L, q0=[1.0, 0.0], qdot0=[0.0, 2.0])
    road = re.search(r"from dirac\.flows\.analysed import AnalysedProblem, AnalysedSystem", str(caught.value))
    assert road is not None and '"midpoint"' in str(caught.value)
    system = AnalysedSystem.from_lagrangian(L)
    problem = AnalysedProblem(system, system.initial_state({"x": 1.0, "y": 0.0}, q_dot={"x": 0.0, "y": 2.0}))
    x, y = dirac.integrate(problem, "midpoint", t_end=1.0, dt=1e-3, samples=2)["z"][-1][:2]
    assert abs(x - (2 - np.cos(2.0))) < 1e-5 and abs(y - np.sin(2.0)) < 1e-5
    F = dirac.Lagrangian.from_strings("cyclotron", ["x", "y"], text, [], parameters={"m": 1.0, "B": 2.0}, forces={"x": "-x_dot"})
    with pytest.raises(NotMechanicalError, match="forces and impulses are integrated for that form only") as caught:
        dirac.ForcedProblem(F, q0=[1.0, 0.0], qdot0=[0.0, 2.0])
    assert "midpoint" not in str(caught.value)
