"""`analysis.vector_field()` of time-dependent systems built with `sympy.physics.mechanics`,
started from positions and velocities, against sympy's own `LagrangesMethod`.

Two rheonomic systems: a bead on a hoop of radius R turning about the vertical z axis at
the rate w (constraints depend on t), and a pendulum whose suspension moves as
x_s(t) = a cos(w t), written in the coordinates (u, y) of the bob relative to it (the
Lagrangian depends on t, so p_u = m (u_dot + x_s_dot(t)) does as well). sympy's
`LagrangesMethod` solves its `mass_matrix_full` for the accelerations independently of
the Dirac bracket; the two must agree to round-off.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy
from sympy.physics.mechanics import LagrangesMethod, dynamicsymbols, msubs

import dirac
from dirac.errors import InputError

t = dynamicsymbols._t


def lagranges_numbers(lm: LagrangesMethod, values: dict, time: float) -> np.ndarray:
    """``(q_dot, q_ddot, -lambda)``: ``mass_matrix_full^{-1} forcing_full`` at a point (sympy, exact then float)."""
    solution = lm.mass_matrix_full.LUsolve(lm.forcing_full)
    return np.array([float(sympy.sympify(msubs(e, values)).subs(t, time)) for e in solution])


@pytest.fixture(scope="module")
def hoop():
    x, y, z = dynamicsymbols("x y z")
    m, g, R, w = sympy.symbols("m g R w")
    L = m / 2 * (x.diff(t) ** 2 + y.diff(t) ** 2 + z.diff(t) ** 2) - m * g * z
    lm = LagrangesMethod(L, [x, y, z], hol_coneqs=[x**2 + y**2 + z**2 - R**2,
                                                   -sympy.sin(w * t) * x + sympy.cos(w * t) * y])
    lm.form_lagranges_equations()
    values = {m: 1.5, g: 9.81, R: 0.8, w: 2.0}
    analysis = dirac.analyze(dirac.Lagrangian.from_sympy(lm, parameters=values, name="hoop"))
    return lm, analysis, (x, y, z), values


@pytest.fixture(scope="module")
def suspension():
    u, y = dynamicsymbols("u y")
    m, g, l, a, w = sympy.symbols("m g l a w")
    xs = a * sympy.cos(w * t)
    L = m / 2 * ((u.diff(t) + xs.diff(t)) ** 2 + y.diff(t) ** 2) - m * g * y
    lm = LagrangesMethod(L, [u, y], hol_coneqs=[u**2 + y**2 - l**2])
    lm.form_lagranges_equations()
    values = {m: 1.3, g: 9.81, l: 0.8, a: 0.2, w: 3.0}
    analysis = dirac.analyze(dirac.Lagrangian.from_sympy(lm, parameters=values, name="moving suspension"))
    return lm, analysis, (u, y), values


@pytest.mark.parametrize("time, theta, theta_dot", [(0.0, 0.7, 0.4), (0.3, 2.1, -1.1), (1.7, 0.2, 2.5)])
def test_bead_on_a_rotating_hoop_has_the_accelerations_of_lagranges_method(hoop, time, theta, theta_dot):
    lm, analysis, (x, y, z), values = hoop
    R, w, m = (values[s] for s in sympy.symbols("R w m"))
    c, s = math.cos(w * time), math.sin(w * time)  # the hoop's plane at this time
    q = {"x": R * math.sin(theta) * c, "y": R * math.sin(theta) * s, "z": -R * math.cos(theta)}
    v = {"x_dot": R * math.cos(theta) * theta_dot * c - w * R * math.sin(theta) * s,
         "y_dot": R * math.cos(theta) * theta_dot * s + w * R * math.sin(theta) * c,
         "z_dot": R * math.sin(theta) * theta_dot}
    point = analysis.surface_point({**q, **v, "t": time})
    assert analysis.velocities(point) == pytest.approx(v, abs=1e-13)
    f = analysis.vector_field()
    assert f.time_dependent
    rate = dict(zip(f.names, f(time, np.array([point[n] for n in f.names]))))
    expected = lagranges_numbers(lm, {x: q["x"], y: q["y"], z: q["z"], x.diff(t): v["x_dot"], y.diff(t): v["y_dot"],
                                      z.diff(t): v["z_dot"], **values}, time)
    # L = m/2 |v|^2: q_dot = p/m, q_ddot = p_dot/m
    assert [rate[n] for n in ("x", "y", "z")] == pytest.approx(expected[:3], abs=1e-12)
    assert [rate[f"p_{n}"] / m for n in ("x", "y", "z")] == pytest.approx(expected[3:6], abs=1e-12)
    # sympy's mass_matrix_full solves for -lam (its lam_coeffs = -d chi/dq); lm.eom's lam is dirac's lambda
    assert [point["lambda_1"], point["lambda_2"]] == pytest.approx(-expected[6:], abs=1e-12)
    assert np.max(np.abs(f.residual(np.array([point[n] for n in f.names]), t=time))) < 1e-13


@pytest.mark.parametrize("time, theta, theta_dot", [(0.0, 0.5, -0.7), (0.4, -1.2, 1.9), (2.3, 2.8, 0.3)])
def test_pendulum_with_a_moving_suspension_has_the_accelerations_of_lagranges_method(suspension, time, theta,
                                                                                    theta_dot):
    lm, analysis, (u, y), values = suspension
    l, a, w, m = (values[s] for s in sympy.symbols("l a w m"))
    q = {"u": l * math.sin(theta), "y": -l * math.cos(theta)}
    v = {"u_dot": l * math.cos(theta) * theta_dot, "y_dot": l * math.sin(theta) * theta_dot}
    point = analysis.surface_point({**q, **v, "t": time})
    # p_u = m (u_dot + x_s_dot), x_s_dot = -a w sin(w t): the momentum depends on t
    assert point["p_u"] == pytest.approx(m * (v["u_dot"] - a * w * math.sin(w * time)), abs=1e-13)
    assert analysis.momenta(q, v, t=time)["p_u"] == pytest.approx(point["p_u"], abs=1e-15)
    assert analysis.velocities(point) == pytest.approx(v, abs=1e-13)
    f = analysis.vector_field()
    rate = dict(zip(f.names, f(time, np.array([point[n] for n in f.names]))))
    expected = lagranges_numbers(lm, {u: q["u"], y: q["y"], u.diff(t): v["u_dot"], y.diff(t): v["y_dot"], **values},
                                 time)
    # by hand: u_ddot = p_u_dot/m - x_s_ddot, x_s_ddot = -a w^2 cos(w t); y_ddot = p_y_dot/m
    u_ddot = rate["p_u"] / m + a * w**2 * math.cos(w * time)
    assert [rate["u"], rate["y"]] == pytest.approx(expected[:2], abs=1e-12)
    assert [u_ddot, rate["p_y"] / m] == pytest.approx(expected[2:4], abs=1e-12)
    assert point["lambda_1"] == pytest.approx(-expected[4], abs=1e-12)


def test_the_field_follows_the_moving_suspension_with_solve_ivp(suspension):
    """Integrated with scipy from t = 0.5 for 3 s, the bob stays on its circle around the
    moving suspension, and u_dot from the momenta equals d u/dt of the path."""
    from scipy.integrate import solve_ivp

    _, analysis, _, values = suspension
    l = values[sympy.Symbol("l")]
    point = analysis.surface_point({"u": 0.0, "y": -l, "u_dot": 1.0, "y_dot": 0.0, "t": 0.5})
    f = analysis.vector_field()
    y0 = np.array([point[n] for n in f.names])
    result = solve_ivp(f, (0.5, 3.5), y0, method="DOP853", rtol=1e-11, atol=1e-12, dense_output=True)
    end = dict(zip(f.names, result.y[:, -1]))
    assert abs(end["u"] ** 2 + end["y"] ** 2 - l**2) < 1e-9
    velocity = analysis.velocities({**end, "t": 3.5})
    assert velocity["u_dot"] == pytest.approx(f(3.5, result.y[:, -1])[0], abs=1e-12)


def test_a_time_dependent_field_asks_for_the_time_of_a_batch_or_residual(hoop):
    _, analysis, _, _ = hoop
    f = analysis.vector_field()
    point = analysis.surface_point({"x": 0.0, "y": 0.0, "z": -0.8, "t": 0.0})
    state = np.array([point[n] for n in f.names])
    with pytest.raises(InputError, match="depends on the time t"):
        f.residual(state)
    with pytest.raises(InputError, match="depends on the time t"):
        f.batch(state[None, :])
    assert np.allclose(f.batch(state[None, :], t=0.0)[0], f(0.0, state), rtol=0, atol=0)


def test_velocities_and_momenta_are_refused_with_a_reason(hoop, suspension):
    _, analysis, _, _ = suspension
    with pytest.raises(InputError, match="depend on the time t"):
        analysis.momenta({"u": 0.0, "y": -0.8}, {"u_dot": 1.0})
    with pytest.raises(InputError, match="did you mean 'u_dot'"):
        analysis.momenta({"u": 0.0, "y": -0.8}, {"uu_dot": 1.0}, t=0.0)
    with pytest.raises(InputError, match="give y as well"):
        analysis.momenta({"u": 0.0}, {"u_dot": 1.0}, t=0.0)
    with pytest.raises(InputError, match="not both"):
        analysis.surface_point({"u": 0.0, "y": -0.8, "u_dot": 1.0, "p_u": 1.0})


def test_velocities_of_a_singular_lagrangian_are_refused_not_guessed():
    """The gauge system's L = ((x_dot - y z)^2 + (y_dot + x z)^2)/2 - k r^2/2 has no z_dot:
    the momenta do not fix z_dot (a gauge freedom), so velocities() refuses."""
    analysis = dirac.analyze(dirac.load_system("gauge_system"))
    point = {"x": 1.0, "y": 0.0, "z": 0.0, "p_x": 0.0, "p_y": 0.5, "p_z": 0.0}
    with pytest.raises(InputError, match="singular.*do not determine every velocity"):
        analysis.velocities(point)
    # the momenta themselves are defined: p_x = x_dot - y z, p_y = y_dot + x z, p_z = 0
    assert analysis.momenta({"x": 1.0, "y": 2.0, "z": 0.5}, {"x_dot": 0.3, "y_dot": -0.1, "z_dot": 7.0}) == \
        pytest.approx({"p_x": 0.3 - 2.0 * 0.5, "p_y": -0.1 + 1.0 * 0.5, "p_z": 0.0})
