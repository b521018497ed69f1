"""Rheonomic systems (explicit time t in the constraints) through the generated kernels:
RATTLE keeps chi(q, t) = 0 and G M^{-1} p + d chi/dt = 0 to round-off, and the bead on a
rotating hoop keeps its Jacobi integral to O(dt^2)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from dirac.flows import ConstrainedProblem, MechanicalSystem, integrate
from dirac.model.lagrangian import Lagrangian

OMEGA, G_ACC, RADIUS = 5.0, 9.81, 1.0

HOOP = Lagrangian.from_strings(
    "rotating_hoop",
    ["x", "y", "z"],
    "m/2*(x_dot**2 + y_dot**2 + z_dot**2) - m*g*z",
    ["-x*sin(w*t) + y*cos(w*t)", "x**2 + y**2 + z**2 - R**2"],
    parameters={"m": 1.0, "g": G_ACC, "R": RADIUS, "w": OMEGA},
)

GROWING = Lagrangian.from_strings(
    "growing_pendulum",
    ["x", "y"],
    "(x_dot**2 + y_dot**2)/2 - g*y",
    ["x**2 + y**2 - (1 + a*t)**2"],
    parameters={"g": 9.81, "a": 0.1},
)


def _jacobi(q: np.ndarray, p: np.ndarray) -> np.ndarray:
    """E_J = H - w L_z = |p|^2/(2m) + m g z - w (x p_y - y p_x) (m = 1): the energy in the
    frame turning with the hoop, 1/2 (rho_dot^2 + z_dot^2) - 1/2 w^2 rho^2 + g z. The
    Lagrangian is invariant under a rotation by w s about z combined with the time shift
    s, and the Noether charge of that symmetry is E_J."""
    return (np.einsum("ij,ij->i", p, p) / 2 + G_ACC * q[:, 2]
            - OMEGA * (q[:, 0] * p[:, 1] - q[:, 1] * p[:, 0]))


def test_rotating_hoop_keeps_constraints_and_jacobi_integral():
    """rattle-2 on the hoop: both constraints and their hidden (velocity) form, which has
    the d chi/dt term, stay at round-off; the largest deviation of E_J over two seconds
    drops by ~4 when dt is halved (order 2)."""
    system = MechanicalSystem.from_lagrangian(HOOP)
    assert system.time_symbol is not None and system.constant_mass is not None
    theta = 2.0  # start on the hoop at 2 rad from the bottom, carried round at w rho
    rho = RADIUS * math.sin(theta)
    problem = ConstrainedProblem(system, [rho, 0.0, -RADIUS * math.cos(theta)], [0.0, OMEGA * rho, 0.0])
    deviations = []
    for dt in (0.002, 0.001):
        solution = integrate(problem, "rattle-2", t_end=2.0, dt=dt, samples=200,
                             outputs=["q", "p", "constraint_residual"])
        assert np.max(solution["constraint_residual"]) <= 1e-11
        jacobi = _jacobi(solution["q"], solution["p"])
        deviations.append(np.max(np.abs(jacobi - jacobi[0])))
    assert deviations[1] <= 1e-3
    assert 3.2 <= deviations[0] / deviations[1] <= 4.8


def test_pendulum_of_growing_length_follows_its_rod():
    """x^2 + y^2 = (1 + a t)^2: the distance from the pivot is 1 + a t at every sample
    and the radial velocity x_dot x + y_dot y = (1 + a t) a, to round-off."""
    system = MechanicalSystem.from_lagrangian(GROWING)
    theta = 0.5
    q0 = [math.sin(theta), -math.cos(theta)]
    p0 = [0.1 * math.sin(theta), -0.1 * math.cos(theta)]  # the rod grows at a = 0.1
    solution = integrate(ConstrainedProblem(system, q0, p0), "rattle-2", t_end=3.0, dt=0.001, samples=30,
                         outputs=["q", "p", "constraint_residual"])
    length = 1.0 + 0.1 * solution.t
    assert np.hypot(solution["q"][:, 0], solution["q"][:, 1]) == pytest.approx(length, abs=1e-12)
    radial = np.einsum("ij,ij->i", solution["q"], solution["p"])
    assert radial == pytest.approx(length * 0.1, abs=1e-11)
    assert np.max(solution["constraint_residual"]) <= 1e-11


def test_analysed_flow_of_the_growing_pendulum_follows_the_moving_surface():
    """The projected midpoint rule on the Dirac field of the full analysis, with the term
    -{z, Phi_a} (C^-1)^ab d_t Phi_b (Gitman-Tyutin): the rod length stays 1 + a t, the
    second-class constraints at the current time stay at round-off, and the position at
    t = 2 converges at order 2 to that of rattle-4 with a small step (same motion, an
    independent algorithm and code path)."""
    from dirac.flows.analysed import AnalysedProblem, AnalysedSystem

    analysed = AnalysedSystem.from_lagrangian(GROWING)
    theta = 0.5
    z0 = analysed.initial_state({"x": math.sin(theta), "y": -math.cos(theta)},
                                q_dot={"x": 0.1 * math.sin(theta), "y": -0.1 * math.cos(theta)})
    mechanical = ConstrainedProblem(MechanicalSystem.from_lagrangian(GROWING), z0[:2], z0[3:5])
    reference = integrate(mechanical, "rattle-4", t_end=2.0, dt=0.002, samples=1, outputs=["q"])["q"][-1]
    errors = []
    for dt in (0.02, 0.01):
        solution = integrate(AnalysedProblem(analysed, z0), "midpoint", t_end=2.0, dt=dt, samples=10,
                             outputs=["z", "constraint_residual"])
        z = solution["z"]
        assert np.hypot(z[:, 0], z[:, 1]) == pytest.approx(1.0 + 0.1 * solution.t, abs=1e-11)
        assert np.max(solution["constraint_residual"]) <= 1e-10
        errors.append(np.max(np.abs(z[-1, :2] - reference)))
    assert 3.2 <= errors[0] / errors[1] <= 4.8


def test_t_as_a_coordinate_is_not_time_dependence():
    """A coordinate named t (no explicit time): the free particle L = (t_dot^2 + x_dot^2)/2
    compiles without a time argument in its kernels."""
    free = Lagrangian.from_strings("free", ["t", "x"], "(t_dot**2 + x_dot**2)/2")
    system = MechanicalSystem.from_lagrangian(free)
    assert system.name == "free" and system.time_symbol is None
    assert MechanicalSystem.from_lagrangian(GROWING).time_symbol is not None
