"""``analysis.vector_field()``: the compiled Dirac vector field f(t, y) of an analysed system."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import dirac
from dirac.errors import InputError


@pytest.fixture(scope="module")
def pendulum():
    return dirac.analyze(dirac.load_system("pendulum"))


def pendulum_state(theta: float, omega: float, m: float, g: float, l: float) -> tuple[np.ndarray, np.ndarray]:
    """A surface point of the Cartesian pendulum and the field there, both by hand.

    L = m/2 (x_dot^2 + y_dot^2) - m g y with x^2 + y^2 = l^2 and the multiplier lambda a
    coordinate: H_c = |p|^2/(2m) + m g y + lambda (x^2 + y^2 - l^2) (as the analysis prints it);
    with x = l sin th, y = -l cos th, p = m l om (cos th, sin th), p_lambda = 0 the chain
    p_lambda = 0, x^2 + y^2 = l^2, x p_x + y p_y = 0 holds, and the fourth stage
    2 g y + 4 lambda r^2/m - 2 |p|^2/m^2 = 0 gives lambda = (|p|^2/m - m g y)/(2 l^2).
    The field: x_dot = p_x/m, y_dot = p_y/m, p_x_dot = -2 lambda x,
    p_y_dot = -m g - 2 lambda y, p_lambda_dot = 0, and lambda_dot is the time derivative
    of the solved lambda: d|p|^2/dt = -4 lambda (x p_x + y p_y) - 2 m g p_y = -2 m g p_y and
    d(m g y)/dt = g p_y, so lambda_dot = -3 g p_y / (2 l^2).
    """
    x, y = l * math.sin(theta), -l * math.cos(theta)
    px, py = m * l * omega * math.cos(theta), m * l * omega * math.sin(theta)
    lam = ((px * px + py * py) / m - m * g * y) / (2 * l * l)
    state = np.array([x, y, lam, px, py, 0.0])
    field = np.array([px / m, py / m, -3 * g * py / (2 * l * l), -2 * lam * x, -m * g - 2 * lam * y, 0.0])
    return state, field


def test_pendulum_field_equals_the_closed_form_at_surface_points(pendulum):
    f = pendulum.vector_field()
    rng = np.random.default_rng(11)
    for _ in range(50):
        theta, omega = rng.uniform(-math.pi, math.pi), rng.normal(scale=3.0)
        state, expected = pendulum_state(theta, omega, 1.0, 9.81, 1.0)
        np.testing.assert_allclose(f(0.0, state), expected, rtol=1e-12, atol=1e-12)
        assert np.max(np.abs(f.residual(state))) <= 1e-12 * (1 + omega * omega)


def test_off_the_surface_the_field_keeps_every_second_class_constraint(pendulum):
    """{Phi_a, F}_D = {Phi_a, F} - C_ab C^{-1}_bc {Phi_c, F} = 0 wherever C is invertible
    (240), so grad Phi_a . f = {Phi_a, H}_D = 0 at any state, on the surface or not.
    The gradients come from sympy here, independently of the generated code."""
    import sympy

    f = pendulum.vector_field()
    z = pendulum.phase_space
    values = {p: v for p, v in pendulum.lagrangian.parameters.items()}
    gradients = sympy.lambdify([z], [[sympy.diff(phi.subs(values), s) for s in z] for phi in pendulum.second_class])
    rng = np.random.default_rng(17)
    for _ in range(20):
        state = rng.normal(size=6)
        state[0] += 1.5  # away from x = y = 0, where C is singular
        D = np.array(gradients(state), dtype=float)
        velocity = f(0.0, state)
        assert np.max(np.abs(D @ velocity)) <= 1e-11 * (1 + np.abs(D).max() * np.abs(velocity).max())
        assert np.max(np.abs(f.residual(state))) > 1e-3  # these states are off the surface


def test_parameters_override_the_defaults(pendulum):
    f = pendulum.vector_field(parameters={"m": 2.0, "g": 3.7, "l": 1.5})
    assert f.parameters == {"m": 2.0, "g": 3.7, "l": 1.5}
    state, expected = pendulum_state(0.4, -1.3, 2.0, 3.7, 1.5)
    np.testing.assert_allclose(f(0.0, state), expected, rtol=1e-12, atol=1e-12)
    # the field at the defaults is a different function of the same state
    assert not np.allclose(pendulum.vector_field()(0.0, state), expected)


def test_solve_ivp_keeps_the_pendulum_on_its_circle(pendulum):
    """DOP853 at rtol = atol = 1e-10 on the Dirac field from 1 rad at rest, t = 0..10:
    the field is tangent to the constraint surface, so x^2 + y^2 = l^2 holds to the
    integration error; the energy |p|^2/2 + g y is conserved likewise."""
    f = pendulum.vector_field()
    state, _ = pendulum_state(1.0, 0.0, 1.0, 9.81, 1.0)
    times = np.linspace(0.0, 10.0, 2001)
    result = solve_ivp(f, (0.0, 10.0), state, method="DOP853", rtol=1e-10, atol=1e-10, t_eval=times)
    assert result.success
    x, y, px, py = result.y[0], result.y[1], result.y[3], result.y[4]
    assert np.max(np.abs(x * x + y * y - 1.0)) <= 1e-8
    energy = (px * px + py * py) / 2 + 9.81 * y
    assert np.max(np.abs(energy - energy[0])) <= 1e-8 * 9.81
    assert np.max(np.abs(f.residual(result.y.T))) <= 1e-7


def test_batch_equals_single_calls(pendulum):
    f = pendulum.vector_field()
    rng = np.random.default_rng(5)
    states = np.array([pendulum_state(t, w, 1.0, 9.81, 1.0)[0] for t, w in rng.normal(size=(20, 2))])
    batched = f.batch(states)
    assert batched.shape == states.shape
    for row, state in zip(batched, states):
        assert np.array_equal(row, f(0.0, state))
    residuals = f.residual(states)
    assert residuals.shape == (20, len(pendulum.constraints))
    assert np.array_equal(residuals[3], f.residual(states[3]))


def test_names_are_the_phase_space_in_order(pendulum):
    f = pendulum.vector_field()
    assert f.names == ("x", "y", "lambda_1", "p_x", "p_y", "p_lambda_1")
    assert f.names == tuple(pendulum.symbols)
    assert all(isinstance(name, str) for name in f.names)
    assert f.constraints == tuple(str(c) for c in pendulum.constraints)


def test_inputs_that_are_not_contiguous_float_vectors_are_converted(pendulum):
    f = pendulum.vector_field()
    state, expected = pendulum_state(0.3, 0.8, 1.0, 9.81, 1.0)
    strided = np.repeat(state, 2)[::2]
    assert not strided.flags["C_CONTIGUOUS"]
    np.testing.assert_allclose(f(0, strided), expected, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(f(0.0, list(state)), expected, rtol=1e-12, atol=1e-12)
    frozen = state.copy()
    frozen.flags.writeable = False
    np.testing.assert_allclose(f(0.0, frozen), expected, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(f.batch(frozen[None, :])[0], expected, rtol=1e-12, atol=1e-12)


def test_bad_inputs_are_refused(pendulum):
    f = pendulum.vector_field()
    with pytest.raises(InputError, match="6 floats"):
        f(0.0, np.zeros(5))
    with pytest.raises(InputError, match=r"not an array of shape \(7,\)"):
        f(0.0, np.zeros(7))
    with pytest.raises(InputError, match="6 floats"):
        f(0.0, np.zeros((6, 1)))
    with pytest.raises(InputError, match=r"shape \(B, 6\)"):
        f.batch(np.zeros((3, 5)))
    with pytest.raises(InputError, match="unknown parameter"):
        pendulum.vector_field(parameters={"mass": 1.0})
    with pytest.raises(InputError, match="not finite"):
        pendulum.vector_field(parameters={"l": math.nan})
    with pytest.raises(InputError, match="determined by the constraint chain"):
        pendulum.vector_field(multipliers={"u_1": 0.0})


def test_a_parameter_without_value_is_refused():
    lagrangian = dirac.Lagrangian.from_strings("oscillator", ["x"], "x_dot**2/2 - k*x**2/2", parameters={"k": None})
    analysis = dirac.analyze(lagrangian)
    with pytest.raises(InputError, match="'k' has no value"):
        analysis.vector_field()
    f = analysis.vector_field(parameters={"k": 4.0})
    # no constraints: x_dot = p, p_dot = -k x
    np.testing.assert_allclose(f(0.0, np.array([0.5, 0.25])), [0.25, -2.0], rtol=1e-15)


@pytest.mark.parametrize("system", ["double_pendulum", "rigid_body_matrix"])
def test_field_agrees_with_equations_of_motion_at_surface_points(system):
    """Both sides are {z, H}_D (240) at a surface point; equations_of_motion(at=) solves C
    with numpy from separately generated brackets."""
    analysis = dirac.analyze(dirac.load_system(system))
    f = analysis.vector_field()
    for seed in range(3):
        point = analysis.surface_point(seed=seed)
        state = np.array([point[name] for name in f.names])
        expected = analysis.equations_of_motion(at=point)
        reference = np.array([expected[analysis.symbols[name]] for name in f.names])
        scale = 1.0 + np.max(np.abs(reference))
        assert np.max(np.abs(f(0.0, state) - reference)) <= 1e-10 * scale
        assert np.max(np.abs(f.residual(state))) <= 1e-8 * (1.0 + np.max(np.abs(state)))


def test_gauge_system_with_a_given_multiplier():
    """H_T = H_c + u p_z with H_c = |p|^2/2 + z (y p_x - x p_y) + k (x^2 + y^2)/2 (by hand
    from L = 1/2 [(x_dot - z y)^2 + (y_dot + z x)^2] - k/2 (x^2 + y^2)); both constraints
    p_z and x p_y - y p_x are first class, so the field is the Hamiltonian one of H_T:
    x_dot = p_x + z y, y_dot = p_y - z x, z_dot = u, p_x_dot = z p_y - k x,
    p_y_dot = -z p_x - k y, p_z_dot = x p_y - y p_x (zero on the surface)."""
    analysis = dirac.analyze(dirac.load_system("gauge_system"))
    assert [u.name for u in analysis.undetermined_multipliers] == ["u_1"]
    x, y, z, px, py, k = 0.8, -0.3, 0.45, 0.6, -0.225, 1.0  # x p_y - y p_x = 0
    state = np.array([x, y, z, px, py, 0.0])
    for u in (None, 0.7):
        f = analysis.vector_field() if u is None else analysis.vector_field(multipliers={"u_1": u})
        assert f.multipliers == {"u_1": 0.0 if u is None else u}
        expected = [px + z * y, py - z * x, 0.0 if u is None else u, z * py - k * x, -z * px - k * y, 0.0]
        np.testing.assert_allclose(f(0.0, state), expected, rtol=1e-14, atol=1e-15)
        assert np.max(np.abs(f.residual(state))) <= 1e-15
