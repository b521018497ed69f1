"""Each kind of system is drawn with its own conserved quantities (``dirac.plot``).

The free body conserves ``H_0`` (247), ``|M|^2``, ``m = R M`` and ``R^T R``; a heavy top
conserves only its total energy and the vertical lab momentum ``m_z`` (and ``R^T R``), so
its picture must not show ``H_0`` or ``|M|^2`` as errors; a constrained system shows its
energy and one residual curve per constraint.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import dirac
from dirac.plots import heavy_top_errors, result_figure
from dirac.plots.rigid_body import ERROR_FLOOR

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "docs" / "scenes"


def _error_axes(fig):
    (ax,) = [ax for ax in fig.axes if ax.get_title() == "Conserved quantities: error over time"]
    return ax


def _curves(ax) -> dict[str, np.ndarray]:
    """The labelled curves of the error panel (the dashed running maxima carry no label)."""
    return {line.get_label(): np.asarray(line.get_ydata()) for line in ax.get_lines()
            if not line.get_label().startswith("_") and line.get_xdata().size}


def _sleeping_top(n: int = 50):
    """A top spinning about the lab vertical with its centre of mass on the spin axis.

    ``M = (0, 0, L)`` and ``R(t) = rot_z(L t / I_3)`` solve the heavy-top equations exactly
    (the gravity torque ``m g chi x Gamma`` vanishes for ``chi`` parallel to ``Gamma = e_3``),
    so every conserved quantity is exactly constant.
    """
    inertia, L = np.array([1.0, 1.0, 0.5]), 2.0
    t = np.linspace(0.0, 3.0, n)
    angle = L / inertia[2] * t
    c, s = np.cos(angle), np.sin(angle)
    R = np.zeros((n, 3, 3))
    R[:, 0, 0], R[:, 0, 1], R[:, 1, 0], R[:, 1, 1], R[:, 2, 2] = c, -s, s, c, 1.0
    M = np.tile([0.0, 0.0, L], (n, 1))
    return {"t": t, "M": M, "R": R,
            "meta": {"system": "heavy_top",
                     "parameters": {"inertia": inertia.tolist(), "mass_gravity": 1.0,
                                    "center_of_mass": [0.0, 0.0, 0.5]}}}


def test_heavy_top_panels_name_its_own_conserved_quantities() -> None:
    fig = result_figure(_sleeping_top())
    labels = list(_curves(_error_axes(fig)))
    assert any("total energy" in label for label in labels)
    assert any("m_z" in label for label in labels)
    assert any("R^TR" in label for label in labels)
    text = " ".join(labels)
    for free_body_only in ("Casimir", "|M|^2", "E_0", "|m-m_0|"):
        assert free_body_only not in text
    titles = " ".join(ax.get_title() for ax in fig.axes)
    assert "Polhode" not in titles  # the free body's polhode means nothing under gravity
    for values in _curves(_error_axes(fig)).values():  # exact solution: errors at round-off
        assert np.max(values) < 1e-14


def test_heavy_top_errors_follow_the_total_energy_not_the_kinetic_one() -> None:
    """M constant, the body tipped by 90 degrees about x: H changes by m g chi . (Gamma - Gamma_0)."""
    inertia, weight = np.array([1.0, 2.0, 3.0]), np.array([0.0, 0.0, 0.5])
    t = np.array([0.0, 1.0])
    M = np.tile([1.0, 0.0, 1.0], (2, 1))
    tipped = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])  # Gamma = third row = e_2
    R = np.stack([np.eye(3), tipped])
    errors = heavy_top_errors(t, M, R, inertia, weight)
    H0 = 0.5 * (1.0 / 1.0 + 1.0 / 3.0) + 0.5  # kinetic (247) + m g chi . e_3
    energy = errors[r"total energy $|H-H_0|/|H_0|$"]
    assert energy == pytest.approx([0.0, 0.5 / H0], abs=1e-15)  # potential falls from 0.5 to 0
    m_z = errors[r"vertical lab momentum $|m_z-m_{z,0}|/|M_0|$"]
    assert m_z == pytest.approx([0.0, 1.0 / np.sqrt(2.0)], abs=1e-15)  # Gamma . M: 1 -> 0, |M0| = sqrt 2
    assert np.max(errors[r"orthogonality $\|R^TR-1\|_F$"]) < 1e-15


def test_heavy_top_scene_picture_shows_the_integrator_conserving() -> None:
    """The asymmetric heavy-top scene: its picture's errors are small (not the ~0.2 of H_0)."""
    scene = dirac.load_scene(SCENES / "heavy_top_asymmetric.toml")
    solution = dirac.integrate(scene.problem, **scene.run)
    curves = _curves(_error_axes(dirac.plot(solution)))
    assert len(curves) == 2  # energy and m_z: R was not kept by this scene
    for values in curves.values():
        assert np.max(values) < 1e-6


def test_free_body_keeps_its_four_quantities_and_polhode() -> None:
    problem = dirac.RigidBodyProblem(inertia=[2.0, 1.5, 1.0], M0=[0.3, 0.6, -0.9])
    fig = dirac.plot(dirac.integrate(problem, t_end=2.0, dt=0.05, method="lie-poisson-4"))
    labels = " ".join(_curves(_error_axes(fig)))
    for name in ("energy", "Casimir", "lab momentum", "R^TR"):
        assert name in labels
    assert any("Polhode" in ax.get_title() for ax in fig.axes)


def test_error_panel_shows_the_error_itself_not_only_its_running_maximum() -> None:
    """An oscillating error must go down again in the picture (the running maximum never does)."""
    scene = dirac.load_scene(SCENES / "pendulum.toml")
    solution = dirac.integrate(scene.problem, **scene.run)
    energy = next(v for k, v in _curves(_error_axes(dirac.plot(solution))).items() if "energy" in k)
    E = solution["energy"]
    assert energy == pytest.approx(np.maximum(np.abs(E - E[0]) / abs(E[0]), ERROR_FLOOR), rel=1e-12)
    assert energy[-1] < 0.5 * np.max(energy)  # RATTLE's energy error oscillates, it does not drift


def test_constrained_picture_has_one_residual_curve_per_constraint() -> None:
    """Pendulum: chi = x^2 + y^2 - l^2 and its velocity form 2 (x p_x + y p_y)/m (m = l = 1)."""
    scene = dirac.load_scene(SCENES / "pendulum.toml")
    solution = dirac.integrate(scene.problem, **scene.run)
    curves = _curves(_error_axes(dirac.plot(solution, scene.problem)))
    chi = [k for k in curves if "chi" in k]
    assert len(chi) == 2  # one position constraint and its tangency condition
    (position,) = [k for k in chi if "dot" not in k]
    q, p = solution["q"], solution["p"]
    by_hand = np.abs(q[:, 0] ** 2 + q[:, 1] ** 2 - 1.0)
    assert curves[position] == pytest.approx(np.maximum(by_hand, ERROR_FLOOR), abs=1e-15)
    (velocity,) = [k for k in chi if "dot" in k]
    by_hand = np.abs(2.0 * (q[:, 0] * p[:, 0] + q[:, 1] * p[:, 1]))
    assert curves[velocity] == pytest.approx(np.maximum(by_hand, ERROR_FLOOR), abs=1e-14)


def test_double_pendulum_has_two_constraint_curves() -> None:
    scene = dirac.load_scene(SCENES / "double_pendulum.toml")
    run = dict(scene.run, t_end=0.2, samples=11)
    solution = dirac.integrate(scene.problem, **run)
    curves = _curves(_error_axes(dirac.plot(solution, scene.problem)))
    assert len([k for k in curves if "chi" in k]) == 2  # two rods; p was not kept, so no velocity curves


def test_plot_returns_a_matplotlib_figure() -> None:
    from matplotlib.figure import Figure

    assert isinstance(dirac.plot(_sleeping_top()), Figure)
    assert "plot" in dirac.__all__


def test_constrained_picture_speaks_of_one_kind_of_unit() -> None:
    """A general system has no fixed units: its axes say "system units", and its title gives dt without seconds."""
    scene = dirac.load_scene(SCENES / "double_pendulum.toml")
    run = dict(scene.run, t_end=0.2, samples=11)
    figure = dirac.plot(dirac.integrate(scene.problem, **run), scene.problem)
    title = figure.texts[0].get_text() if figure.texts else figure._suptitle.get_text()
    assert "dt = " in title and " s," not in title.split("dt = ")[1]
    labels = [ax.get_xlabel() for ax in figure.axes if ax.get_xlabel()]
    assert labels and all("[s]" not in label for label in labels)
