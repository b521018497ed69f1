"""The constraint chain of explicitly time-dependent (rheonomic) systems.

The consistency of a constraint ``Phi(q, p, t)`` is ``d Phi/dt = {Phi, H_T} + d_t Phi = 0``
(Dirac, "Lectures on quantum mechanics"; Gitman–Tyutin). With the multipliers of the
holonomic constraints as coordinates (``L_ext = L - lambda_a chi_a``), the chain is
``p_lambda_a = 0`` -> ``chi_a = 0`` -> ``d chi_a/dt = 0`` -> (fixes ``lambda``); the partial time
derivatives enter from the third stage (the second stage of the constraints ``chi``
themselves).

Bead on a hoop turning at rate ``w`` about the z axis: ``L = m/2 v^2 - m g z``,
``chi_1 = x sin(w t) - y cos(w t)`` (the plane of the hoop), ``chi_2 = x^2 + y^2 + z^2 - R^2``.
With ``H_c = p^2/2m + m g z + lambda_1 chi_1 + lambda_2 chi_2``:

    d chi_1/dt = (p_x sin(w t) - p_y cos(w t))/m + w (x cos(w t) + y sin(w t)),
    d chi_2/dt = 2 (x p_x + y p_y + z p_z)/m                      (no explicit t).

The first has the term from ``d_t chi_1``; without it the chain would be that of a hoop at
rest. Stage 4 fixes ``lambda_1, lambda_2``, then ``u_1, u_2``; all 8 constraints are second
class: ``(10 - 8)/2 = 1`` degree of freedom, the angle of the bead on the hoop.

Pendulum of changing length ``l(t) = l0 + a t``: ``chi = x^2 + y^2 - l(t)^2``,
``H_c = p^2/2m + m g y + lambda chi``:

    stage 3:  d chi/dt = 2 (x p_x + y p_y)/m - 2 a l(t),
    stage 4:  2 p^2/m^2 - 4 lambda (x^2 + y^2)/m - 2 g y - 2 a^2
              ({x p_x + y p_y, H_c} = p^2/m - 2 lambda r^2 - m g y, and d_t(-2 a l) = -2 a^2).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import sympy

import dirac
from dirac.model.lagrangian import Lagrangian

HOOP = Lagrangian.from_strings(
    "rotating_hoop",
    ["x", "y", "z"],
    "m/2*(x_dot**2 + y_dot**2 + z_dot**2) - m*g*z",
    ["x*sin(w*t) - y*cos(w*t)", "x**2 + y**2 + z**2 - R**2"],
    parameters={"m": 1.0, "g": 9.81, "w": 2.0, "R": 1.0},
)

GROWING = Lagrangian.from_strings(
    "growing_pendulum",
    ["x", "y"],
    "m/2*(x_dot**2 + y_dot**2) - m*g*y",
    ["x**2 + y**2 - (l0 + a*t)**2"],
    parameters={"m": 1.0, "g": 9.81, "l0": 1.0, "a": 0.1},
)


def _proportional(expr, target):
    ratio = sympy.simplify(sympy.trigsimp(expr / target))
    return ratio.is_number and ratio != 0


@pytest.fixture(scope="module")
def hoop():
    return dirac.analyze(HOOP)


@pytest.fixture(scope="module")
def growing():
    return dirac.analyze(GROWING)


def test_hoop_chain_has_the_time_derivative_at_the_velocity_stage(hoop):
    x, y, z, p_x, p_y, p_z = (hoop.symbols[n] for n in ("x", "y", "z", "p_x", "p_y", "p_z"))
    m, w = (HOOP.parameter_symbols[n] for n in ("m", "w"))
    t = HOOP.time
    assert [len(stage) for stage in hoop.stages] == [2, 2, 2, 2]
    plane = (p_x * sympy.sin(w * t) - p_y * sympy.cos(w * t)) / m + w * (x * sympy.cos(w * t) + y * sympy.sin(w * t))
    sphere = (x * p_x + y * p_y + z * p_z) / m
    third = hoop.stages[2]
    assert any(_proportional(c, plane) for c in third)
    assert any(_proportional(c, sphere) for c in third)
    frozen = (p_x * sympy.sin(w * t) - p_y * sympy.cos(w * t)) / m  # what a frozen t would give
    assert not any(_proportional(c, frozen) for c in third)


def test_hoop_classes_multipliers_and_degrees_of_freedom(hoop):
    assert hoop.first_class == [] and len(hoop.second_class) == 8
    assert set(hoop.multipliers) == {"u_1", "u_2"} and hoop.undetermined_multipliers == []
    assert hoop.physical_degrees_of_freedom == 1
    assert hoop.time == HOOP.time


def test_growing_pendulum_chain_by_hand(growing):
    x, y, p_x, p_y, lam = (growing.symbols[n] for n in ("x", "y", "p_x", "p_y", "lambda_1"))
    m, g, l0, a = (GROWING.parameter_symbols[n] for n in ("m", "g", "l0", "a"))
    t = GROWING.time
    assert [len(stage) for stage in growing.stages] == [1, 1, 1, 1]
    assert _proportional(growing.stages[1][0], x**2 + y**2 - (l0 + a * t) ** 2)
    assert _proportional(growing.stages[2][0], 2 * (x * p_x + y * p_y) / m - 2 * a * (l0 + a * t))
    fourth = 2 * (p_x**2 + p_y**2) / m**2 - 4 * lam * (x**2 + y**2) / m - 2 * g * y - 2 * a**2
    assert _proportional(growing.stages[3][0], fourth)
    assert len(growing.second_class) == 4 and growing.physical_degrees_of_freedom == 1


def test_growing_pendulum_surface_point_is_at_the_given_time(growing):
    """At t = 2 the length is l0 + 2a = 1.2 and the radial velocity x p_x + y p_y = m a l = 0.12."""
    point = growing.surface_point({"t": 2.0}, seed=3)
    assert point["t"] == 2.0
    assert point["x"] ** 2 + point["y"] ** 2 == pytest.approx(1.44, rel=1e-9)
    assert point["x"] * point["p_x"] + point["y"] * point["p_y"] == pytest.approx(0.12, rel=1e-9)


def test_dirac_bracket_at_a_point_takes_the_time(growing):
    """Second-class set of one circle: {x, p_x}* = 1 - x^2/r^2 = y^2/r^2 on x^2 + y^2 = r^2
    (any t: the bracket matrix does not involve the explicit time here); at x = 0.6, y = -0.8: 0.64."""
    point = {"x": 0.6, "y": -0.8, "p_x": 0.8, "p_y": 0.6, "lambda_1": 0.3, "p_lambda_1": 0.0, "t": 0.0}
    assert growing.dirac_bracket("x", "p_x", at=point) == pytest.approx(0.64, rel=1e-12)


def test_reports_say_time_dependent(growing):
    data = growing.to_json()
    assert data["time_dependent"] is True
    assert json.loads(json.dumps(data))["time_dependent"] is True
    text = growing.to_text()
    assert "time-dependent: t occurs explicitly" in text
    assert any("time-dependent (rheonomic)" in note for note in growing.notes)
    assert r"\partial_t" in growing.to_latex()


def test_t_as_a_coordinate_is_not_time_dependent():
    a = dirac.analyze(dirac.load_system("relativistic_particle"))
    assert a.time is None and a.to_json()["time_dependent"] is False
    assert "time-dependent" not in a.to_text()


def test_constraints_that_hold_at_one_instant_only_are_inconsistent():
    """chi_1 = x - t and chi_2 = x hold together only at t = 0: at a generic time the surface is
    empty, so there is no motion (sampling t per point finds this; a frozen t = 0 would not)."""
    L = Lagrangian.from_strings("clash", ["x", "y"], "(x_dot**2 + y_dot**2)/2", ["x - t", "x"])
    with pytest.raises(dirac.InconsistentSystemError, match="no real solution"):
        dirac.analyze(L)


def test_numeric_points_carry_their_own_time(growing):
    times = [float(point[-1]) for point in growing._points]
    assert len(set(times)) == len(times) and np.all(np.isfinite(times))


@pytest.mark.parametrize("system", ["growing", "hoop"])
def test_motion_stays_on_the_moving_surface(system, growing, hoop, request):
    """z_dot = {z, H}_D - {z, Phi_a} (C^-1)^ab d_t Phi_b, so every second-class constraint obeys
    d Phi/dt = grad Phi . z_dot + d_t Phi = 0 on the surface (the Dirac bracket alone gives
    grad Phi . z_dot = 0, wrong by d_t Phi). Checked at a surface point, exactly and numerically."""
    analysis = {"growing": growing, "hoop": hoop}[system]
    values = analysis.surface_point({"t": 0.7}, seed=5)
    z = list(analysis.phase_space)
    numeric = analysis.equations_of_motion(at=values)
    point = {analysis.symbols[name]: value for name, value in values.items() if name in analysis.symbols}
    point[analysis.time] = values["t"]
    point.update({p: v for p, v in analysis.lagrangian.parameters.items()})
    for phi in analysis.second_class:
        drift = sum(float(sympy.diff(phi, s).subs(point)) * numeric[s] for s in z) + float(sympy.diff(phi, analysis.time).subs(point))
        assert abs(drift) < 1e-9, (phi, drift)
    if system == "growing":
        exact = analysis.equations_of_motion()
        for s in z:
            assert float(exact[s].subs(point)) == pytest.approx(numeric[s], rel=1e-9, abs=1e-12)
        # by hand, x_dot = {x, H_c} = p_x/m on the surface (m = 1 here)
        assert numeric[analysis.symbols["x"]] == pytest.approx(values["p_x"], rel=1e-9)


def test_equations_of_motion_with_time_only_in_the_hamiltonian():
    """Driven oscillator L = x_dot^2/2 - x^2/2 + x cos(t): H_c = p^2/2 + x^2/2 - x cos(t), no
    constraints, so x_dot = p and p_dot = -x + cos(t)."""
    driven = dirac.analyze(Lagrangian.from_strings("driven", ["x"], "x_dot**2/2 - x**2/2 + x*cos(t)"))
    x, p = driven.symbols["x"], driven.symbols["p_x"]
    eom = driven.equations_of_motion()
    assert eom[x] == p
    assert sympy.simplify(eom[p] - (-x + sympy.cos(driven.time))) == 0
