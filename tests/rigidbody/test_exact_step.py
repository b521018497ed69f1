"""One compiled step of the exact free flow (dirac.rigidbody.exact_step) and the heavy top's
exact-free-flow + kick kernel built on it."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from dirac.compositions import COMPOSITIONS
from dirac.errors import DiracWarning
from dirac.rigidbody.euler_poisson import lean_rhs_full
from dirac.rigidbody.exact import ExactRigidBodyFlow
from dirac.rigidbody.exact_step import FreeFlowWork, exact_kick_advance, free_flow_step


def _step(inertia, M0, R0, tau):
    M = np.array(M0, dtype=float)
    R = np.array(R0, dtype=float)
    free_flow_step(M, R, 1.0 / np.asarray(inertia, dtype=float), float(tau), *FreeFlowWork().arrays())
    return M, R


def _bodies():
    """Random bodies and momenta, with the cases the set-up branches on: a symmetric body
    (``m = 0``), a zero component, ``M`` within 1e-7 of the separatrix, both time signs."""
    rng = np.random.default_rng(7)
    cases = []
    for k in range(60):
        inertia = rng.uniform(0.3, 3.0, 3)
        M0 = rng.normal(size=3)
        if k % 6 == 1:
            inertia[1] = inertia[0]
        if k % 6 == 2:
            M0[k % 3] = 0.0
        if k % 6 == 3:  # intermediate axis 1: 2E = |M|^2 / I_1 is the separatrix
            inertia = np.array([1.0, 2.0, 3.0])
            M0 = np.array([1e-7, 1.0, 1e-7 * (1 + k)])
        R0 = Rotation.random(random_state=k).as_matrix()
        cases.append((inertia, M0, R0, rng.uniform(-4.0, 4.0)))
    # on the separatrix: M_1^2 (1 - 1/2) = M_3^2 (1/2 - 1/3), i.e. M_3 = sqrt(3) M_1
    for k, tau in enumerate((-2.5, 0.4, 3.0)):
        cases.append((np.array([1.0, 2.0, 3.0]), np.array([1.0, 0.3 * k, np.sqrt(3.0)]), np.eye(3), tau))
    return cases


@pytest.mark.parametrize(("inertia", "M0", "R0", "tau"), _bodies())
def test_one_step_is_the_exact_flow(inertia, M0, R0, tau):
    """Same closed form as ExactRigidBodyFlow (checked against DOP853 in test_exact_flow.py),
    set up inside the kernel: the two agree to round-off, and the step keeps the first
    integrals of (250)-(251) exactly: ``|M|^2``, ``H_0``, ``R^T R = 1`` and ``m = R M``."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DiracWarning)
        M_ref, R_ref = ExactRigidBodyFlow(inertia, M0, R0).state([tau])
    M, R = _step(inertia, M0, R0, tau)
    scale = float(np.linalg.norm(M0))
    assert np.abs(M - M_ref[0]).max() < 1e-12 * scale
    assert np.abs(R - R_ref[0]).max() < 1e-11
    assert abs(M @ M - M0 @ M0) < 1e-13 * scale**2
    energy0 = 0.5 * float(np.sum(M0 * M0 / inertia))
    assert abs(0.5 * float(np.sum(M * M / inertia)) - energy0) < 1e-13 * energy0 + 1e-300
    assert np.abs(R.T @ R - np.eye(3)).max() < 1e-14 * 10
    assert np.abs(R @ M - R0 @ M0).max() < 1e-13 * scale


def test_steps_compose_to_one_long_step():
    """The flow property ``F(s) F(t) = F(s + t)``: 97 unequal steps (crossing many quarter
    periods, where the phase picks up the complete integral ``D``) land where one step does."""
    inertia, M0, R0 = np.array([1.0, 2.0, 3.0]), np.array([0.6, 0.8, 0.5]), np.eye(3)
    taus = np.random.default_rng(3).uniform(-0.2, 0.9, 97)
    M, R = M0.copy(), R0.copy()
    work = FreeFlowWork()
    for tau in taus:
        free_flow_step(M, R, 1.0 / inertia, float(tau), *work.arrays())
    M_one, R_one = _step(inertia, M0, R0, taus.sum())
    assert np.abs(M - M_one).max() < 1e-12
    assert np.abs(R - R_one).max() < 1e-12


def test_one_step_agrees_with_dop853():
    """Against a tight DOP853 integration of (250)-(251), independent of the closed form."""
    inertia, M0 = np.array([2.0, 1.0, 2.0 / 3.0]), np.array([np.cos(1.1), 0.0, np.sin(1.1)])
    T = 7.3
    y0 = np.concatenate([M0, np.eye(3).ravel()])
    sol = solve_ivp(lean_rhs_full, (0.0, T), y0, method="DOP853", rtol=2.3e-14, atol=1e-15,
                    args=tuple(float(x) for x in inertia))
    M, R = _step(inertia, M0, np.eye(3), T)
    assert np.abs(M - sol.y[:3, -1]).max() < 1e-11
    assert np.abs(R.ravel() - sol.y[3:, -1]).max() < 1e-11


def test_relative_equilibrium_rotates_uniformly():
    """``M`` along a principal axis: ``M`` fixed and ``R(t) = R0 exp(t hat(Omega))``, (165)."""
    inertia = np.array([1.0, 2.0, 3.0])
    M, R = _step(inertia, [0.0, 0.0, 1.5], np.eye(3), 0.7)
    angle = 1.5 / 3.0 * 0.7
    expected = np.array([[np.cos(angle), -np.sin(angle), 0.0], [np.sin(angle), np.cos(angle), 0.0], [0.0, 0.0, 1.0]])
    assert np.array_equal(M, [0.0, 0.0, 1.5])
    assert np.abs(R - expected).max() < 1e-15


@pytest.mark.parametrize("suffix", ["2", "4", "6", "8"])
def test_exact_kick_kernel_without_gravity_is_the_free_flow(suffix):
    """With ``w = 0`` the kicks vanish and the composition of free flows with fractions
    summing to 1 is the free flow over ``n dt``."""
    gammas = np.array([c for c in COMPOSITIONS if c.suffix == suffix][0].coefficients)
    inertia, M0 = np.array([1.0, 2.0, 3.0]), np.array([0.6, 0.8, 0.5])
    M, R = M0.copy(), np.eye(3)
    exact_kick_advance(M, R, 1.0 / inertia, np.zeros(3), gammas, 0.3, 20, *FreeFlowWork().arrays())
    M_one, R_one = _step(inertia, M0, np.eye(3), 6.0)
    assert np.abs(M - M_one).max() < 1e-12
    assert np.abs(R - R_one).max() < 1e-12
