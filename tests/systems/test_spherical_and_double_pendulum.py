"""Particle on a sphere and the Cartesian double pendulum: four stages, all second class.

Hand derivation (docs/conventions.md, Sect. X (205)-(217)): with L = 1/2 q_dot^T M q_dot - V(q)
and holonomic chi_a, the chain is p_lambda_a = 0, chi_a = 0, grad chi_a . M^{-1} p = 0 and
the fourth stage, which is linear in lambda:

    sum_b (grad chi_a^T M^{-1} grad chi_b) lambda_b
        = q_dot^T Hess(chi_a) q_dot - grad chi_a^T M^{-1} grad V,     q_dot = M^{-1} p.

For the sphere (chi = |q|^2 - l^2, V = m g z) this is lambda = (|p|^2/m - m g z)/(2 l^2).
Degrees of freedom: sphere (8 - 4)/2 = 2, double pendulum (12 - 8)/2 = 2.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy

import dirac


@pytest.fixture(scope="module")
def sphere():
    return dirac.analyze(dirac.load_system("spherical_pendulum"))


@pytest.fixture(scope="module")
def double():
    return dirac.analyze(dirac.load_system("double_pendulum"))


def test_sphere_chain(sphere):
    assert [len(s) for s in sphere.stages] == [1, 1, 1, 1]
    assert sphere.first_class == [] and len(sphere.second_class) == 4
    assert sphere.physical_degrees_of_freedom == 2
    assert len(sphere.phase_space) == 8
    x, y, z, l = (sphere.symbols["x"], sphere.symbols["y"], sphere.symbols["z"], sympy.Symbol("l", real=True))
    assert sympy.cancel(sphere.stages[1][0] / (x**2 + y**2 + z**2 - l**2)).is_number
    assert set(sphere.multipliers) == {"u_1"}


def test_sphere_lambda_from_a_hand_made_state(sphere):
    theta, phi, l, m, g = 0.7, -1.2, 1.0, 1.0, 9.81
    q = l * np.array([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)])
    e_theta = np.array([np.cos(theta) * np.cos(phi), np.cos(theta) * np.sin(phi), -np.sin(theta)])
    e_phi = np.array([-np.sin(phi), np.cos(phi), 0.0])
    p = m * (0.8 * e_theta - 1.3 * e_phi)
    values = {"x": q[0], "y": q[1], "z": q[2], "p_x": p[0], "p_y": p[1], "p_z": p[2]}
    point = sphere.surface_point(values)
    assert point["p_lambda_1"] == pytest.approx(0.0, abs=1e-12)
    assert point["lambda_1"] == pytest.approx((p @ p / m - m * g * q[2]) / (2 * l**2), rel=1e-10)


def test_double_pendulum_chain(double):
    assert [len(s) for s in double.stages] == [2, 2, 2, 2]
    assert double.first_class == [] and len(double.second_class) == 8
    assert double.physical_degrees_of_freedom == 2
    assert len(double.phase_space) == 12
    assert set(double.multipliers) == {"u_1", "u_2"}
    assert double.undetermined_multipliers == []
    names = [str(s) for s in double.stages[0]]
    assert names == ["p_lambda_1", "p_lambda_2"]


def _hand_lambdas(q, p, masses, g, l1, l2):
    m1, m2 = masses
    Minv = np.diag([1 / m1, 1 / m1, 1 / m2, 1 / m2])
    x1, y1, x2, y2 = q
    grads = np.array([[2 * x1, 2 * y1, 0, 0], [-2 * (x2 - x1), -2 * (y2 - y1), 2 * (x2 - x1), 2 * (y2 - y1)]])
    H1 = np.diag([2.0, 2.0, 0.0, 0.0])
    H2 = np.array([[2, 0, -2, 0], [0, 2, 0, -2], [-2, 0, 2, 0], [0, -2, 0, 2]], dtype=float)
    grad_v = np.array([0.0, m1 * g, 0.0, m2 * g])
    v = Minv @ p
    A = grads @ Minv @ grads.T
    rhs = np.array([v @ H1 @ v, v @ H2 @ v]) - grads @ Minv @ grad_v
    return np.linalg.solve(A, rhs)


def test_double_pendulum_lambdas_from_a_hand_made_state(double):
    l1, l2, g = 1.0, 1.0, 9.81
    t1, t2, w1, w2 = 0.4, -0.9, 1.1, -0.6
    x1, y1 = l1 * np.sin(t1), -l1 * np.cos(t1)
    x2, y2 = x1 + l2 * np.sin(t2), y1 - l2 * np.cos(t2)
    v1 = np.array([l1 * np.cos(t1) * w1, l1 * np.sin(t1) * w1])
    v2 = v1 + np.array([l2 * np.cos(t2) * w2, l2 * np.sin(t2) * w2])
    q = np.array([x1, y1, x2, y2])
    p = np.concatenate([v1, v2])  # unit masses
    values = dict(zip(["x1", "y1", "x2", "y2", "p_x1", "p_y1", "p_x2", "p_y2"], [*q, *p]))
    point = double.surface_point(values)
    expected = _hand_lambdas(q, p, (1.0, 1.0), g, l1, l2)
    assert [point["lambda_1"], point["lambda_2"]] == pytest.approx(list(expected), rel=1e-9)


def test_state_off_the_surface_is_refused(sphere):
    with pytest.raises(dirac.InputError, match="constraint surface"):
        sphere.surface_point({"x": 2.0, "y": 0.0, "z": 0.0})
    with pytest.raises(dirac.InputError, match="unknown name"):
        sphere.surface_point({"w": 1.0})
