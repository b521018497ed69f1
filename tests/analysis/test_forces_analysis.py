"""The Dirac-Bergmann chain with generalized forces: analysis.forces, the JSON, the
multipliers solved with the forces, and the forced vector field against the angle equation."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy
from scipy.integrate import solve_ivp

import dirac
from dirac import Lagrangian

M, G, ELL, C = 1.0, 9.81, 1.0, 0.3


@pytest.fixture(scope="module")
def damped():
    system = Lagrangian.from_strings(
        "damped_pendulum", ["x", "y"], "m/2*(x_dot**2 + y_dot**2) - m*g*y", constraints=["x**2 + y**2 - l**2"],
        parameters={"m": M, "g": G, "l": ELL, "c": C}, forces={"x": "-c*x_dot", "y": "-c*y_dot"})
    return dirac.analyze(system)


def test_forces_are_functions_on_phase_space(damped):
    s = damped.symbols
    m, c = damped.lagrangian.parameter_symbols["m"], damped.lagrangian.parameter_symbols["c"]
    assert sympy.simplify(damped.forces["x"] + c * s["p_x"] / m) == 0
    assert sympy.simplify(damped.forces["y"] + c * s["p_y"] / m) == 0
    assert damped.to_json()["forces"] == {"x": "-c*p_x/m", "y": "-c*p_y/m"}


def test_json_forces_is_empty_without_forces():
    assert dirac.analyze(dirac.load_system("pendulum")).to_json()["forces"] == {}


def test_the_fourth_stage_is_the_forced_acceleration_condition(damped):
    # by hand: d/dt (x p_x + y p_y) = p^2/m - 2 lambda (x^2 + y^2) - m g y - c (x p_x + y p_y)/m
    s = damped.symbols
    m, c, g = (damped.lagrangian.parameter_symbols[n] for n in ("m", "c", "g"))
    x, y, px, py, lam = s["x"], s["y"], s["p_x"], s["p_y"], s["lambda_1"]
    hand = (px**2 + py**2) / m - 2 * lam * (x**2 + y**2) - m * g * y - c * (x * px + y * py) / m
    stage4 = damped.stages[3][0]
    ratio = sympy.simplify(stage4 / hand)  # the same condition up to a constant factor (-2/m)
    assert not ratio.free_symbols & set(damped.phase_space)


def test_the_forced_vector_field_moves_like_the_angle_equation(damped):
    f = damped.vector_field()
    theta0, t_end = 1.2, 2.0
    x0, y0 = ELL * math.sin(theta0), -ELL * math.cos(theta0)
    point = damped.surface_point({"x": x0, "y": y0, "p_x": 0.0, "p_y": 0.0})
    state = np.array([point[name] for name in f.names])
    sol = solve_ivp(f, (0.0, t_end), state, method="DOP853", rtol=1e-12, atol=1e-12)
    x, y = sol.y[f.names.index("x"), -1], sol.y[f.names.index("y"), -1]

    def angle(t, s):
        return [s[1], -G / ELL * math.sin(s[0]) - C / M * s[1]]

    reference = solve_ivp(angle, (0.0, t_end), [theta0, 0.0], method="DOP853", rtol=1e-13, atol=1e-13).y[0, -1]
    assert abs(math.atan2(x, -y) - reference) < 1e-8


def test_a_time_dependent_force_enters_the_vector_field_at_its_time():
    """Driven oscillator ``x'' = -x + cos(w t)``: ``f(t, (x, p)) = (p, -x + cos(w t))`` by hand."""
    system = Lagrangian.from_strings("driven", ["x"], "x_dot**2/2 - x**2/2", parameters={"w": 1.7},
                                     forces={"x": "cos(w*t)"})
    analysis = dirac.analyze(system)
    assert analysis.time is not None
    f = analysis.vector_field()
    x, p = f.names.index("x"), f.names.index("p_x")
    state = np.zeros(len(f.names))
    state[x], state[p] = 0.3, -0.4
    for t in (0.0, 0.5, 2.0):
        rate = f(t, state)
        assert rate[x] == pytest.approx(-0.4, abs=1e-14)
        assert rate[p] == pytest.approx(-0.3 + math.cos(1.7 * t), abs=1e-14)
