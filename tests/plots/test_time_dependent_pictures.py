"""Pictures of a driven (time-dependent) system tell the truth.

A bead on a parabola z = a (x^2 + y^2) whose plane turns about the vertical at the rate w
(constraints chi_1 = z - a (x^2 + y^2), chi_2 = -sin(w t) x + cos(w t) y). Its constraint
residuals must be drawn at each sample's own time, and their time derivatives with the
partial derivative d_t chi_2: the plotted curves are then the run's own residuals. Its
energy is not conserved, and the picture says so; the Jacobi integral H - w (x p_y - y p_x)
is (Landau & Lifshitz, Mechanics, §39), and the picture draws it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import dirac
from dirac.plots import result_figure
from dirac.plots.rigid_body import ERROR_FLOOR

SYSTEM = """[system]
name = "bead_on_rotating_parabola"
coordinates = ["x", "y", "z"]
parameters = { m = 1.0, g = 9.81, a = 0.5, w = 2.0 }
lagrangian = "m/2*(x_dot**2 + y_dot**2 + z_dot**2) - m*g*z"
constraints = ["z - a*(x**2 + y**2)", "-sin(w*t)*x + cos(w*t)*y"]
"""

SCENE = """[system]
file = "parabola.toml"

[initial]
q = { x = 1.0, y = 0.0, z = 0.5 }
q_dot = { x = 0.0, y = 2.0, z = 0.0 }

[run]
t_end = 3.0
method = "rattle-2"
dt = 0.002
samples = 61
outputs = ["q", "p", "energy", "constraint_residual"]
"""


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("parabola")
    (folder / "parabola.toml").write_text(SYSTEM, encoding="utf-8")
    (folder / "scene.toml").write_text(SCENE, encoding="utf-8")
    scene = dirac.load_scene(folder / "scene.toml")
    solution = dirac.integrate(scene.problem, **scene.run)
    return scene, solution, result_figure(solution, problem=scene.problem)


def _panel(fig):
    (ax,) = [ax for ax in fig.axes if ax.get_title().startswith("Constraint residuals and conserved quantities")]
    return ax


def _curves(ax) -> dict[str, np.ndarray]:
    return {line.get_label(): np.asarray(line.get_ydata()) for line in ax.get_lines()
            if not line.get_label().startswith("_") and line.get_xdata().size}


def test_the_plotted_residuals_are_the_stored_ones(run):
    _, solution, fig = run
    curves = _curves(_panel(fig))
    chi = np.array([values for label, values in curves.items() if "chi" in label])
    assert chi.shape[0] == 4  # chi_1, chi_2 and their time derivatives
    stored = np.maximum(solution["constraint_residual"], ERROR_FLOOR)
    assert np.max(chi, axis=0) == pytest.approx(stored, rel=0, abs=0)
    assert np.max(chi) < 1e-12  # evaluated at t = 0 the turning constraint would read |chi_2| ~ 1


def test_the_residuals_by_hand_at_each_samples_time(run):
    _, solution, fig = run
    curves = _curves(_panel(fig))
    t, q, p = solution["t"], solution["q"], solution["p"]
    w = 2.0
    chi_2 = -np.sin(w * t) * q[:, 0] + np.cos(w * t) * q[:, 1]
    # d chi_2/dt = grad chi_2 . p/m + d_t chi_2 (m = 1)
    chi_2_dot = (-np.sin(w * t) * p[:, 0] + np.cos(w * t) * p[:, 1]
                 - w * (np.cos(w * t) * q[:, 0] + np.sin(w * t) * q[:, 1]))
    (position,) = [k for k in curves if r"\chi_{2}|$," in k]
    (velocity,) = [k for k in curves if r"\dot\chi_{2}" in k]
    assert curves[position] == pytest.approx(np.maximum(np.abs(chi_2), ERROR_FLOOR), abs=1e-14)
    assert curves[velocity] == pytest.approx(np.maximum(np.abs(chi_2_dot), ERROR_FLOOR), abs=1e-13)


def test_the_energy_is_labelled_not_conserved_and_the_jacobi_integral_is_drawn(run):
    scene, solution, fig = run
    curves = _curves(_panel(fig))
    (energy,) = [k for k in curves if k.startswith("energy")]
    assert "not conserved" in energy
    assert np.max(curves[energy]) > 0.1  # the turning parabola pumps energy in and out
    (jacobi,) = [k for k in curves if k.startswith("Jacobi integral")]
    assert "(conserved)" in jacobi and "H - 2" in jacobi
    q, p, E = solution["q"], solution["p"], solution["energy"]
    J = E - 2.0 * (q[:, 0] * p[:, 1] - q[:, 1] * p[:, 0])
    assert curves[jacobi] == pytest.approx(np.maximum(np.abs(J - J[0]) / abs(J[0]), ERROR_FLOOR), rel=1e-12)
    assert np.max(curves[jacobi]) < 1e-4  # conserved up to RATTLE's O(dt^2) error
    assert not [ax for ax in fig.axes if ax.get_title() == "Conserved quantities: error over time"]


def test_halving_the_step_quarters_the_jacobi_error(run):
    """The Jacobi integral is conserved by the exact motion: RATTLE's error in it is O(dt^2)."""
    scene, _, _ = run
    errors = []
    for dt in (0.004, 0.002):
        solution = dirac.integrate(scene.problem, **dict(scene.run, dt=dt))
        q, p, E = solution["q"], solution["p"], solution["energy"]
        J = E - 2.0 * (q[:, 0] * p[:, 1] - q[:, 1] * p[:, 0])
        errors.append(np.max(np.abs(J - J[0])))
    assert 3.0 < errors[0] / errors[1] < 5.0


def test_a_three_coordinate_system_has_a_3d_path(run):
    _, _, fig = run
    (path,) = [ax for ax in fig.axes if ax.get_title() == "Path in configuration space"]
    assert path.name == "3d"
    assert path.get_zlabel().startswith("$z$")


def test_a_two_coordinate_system_keeps_a_plane_path_and_conserved_energy():
    scene = dirac.load_scene(Path(__file__).resolve().parents[2] / "docs" / "scenes" / "pendulum.toml")
    solution = dirac.integrate(scene.problem, **dict(scene.run, t_end=0.5, samples=11))
    fig = result_figure(solution, problem=scene.problem)
    (path,) = [ax for ax in fig.axes if ax.get_title() == "Path in configuration space"]
    assert path.name == "rectilinear"
    (panel,) = [ax for ax in fig.axes if ax.get_title() == "Conserved quantities: error over time"]
    assert not [line for line in panel.get_lines() if "not conserved" in line.get_label()]


def test_without_a_conserved_combination_the_panel_claims_none():
    """A driven system without a Jacobi integral (say a moving suspension): the energy is
    labelled not conserved, and the panel's title names only the residuals."""
    from dirac.plots.constrained import constrained_figure

    t = np.linspace(0.0, 1.0, 11)
    q = np.column_stack([np.sin(t), -np.cos(t)])
    fig = constrained_figure(t, q, energy=1.0 + t, constraint_residual=1e-15 + 0 * t, energy_conserved=False)
    (panel,) = [ax for ax in fig.axes if "over time" in ax.get_title() and "Coordinates" not in ax.get_title()]
    assert panel.get_title() == "Constraint residuals over time (the energy changes: the system depends on time)"
    (energy,) = [k for k in _curves(panel) if k.startswith("energy")]
    assert energy.endswith("(not conserved: the system depends on time)")
