"""The Euler–Poisson vector field (250)–(251) and its invariants (docs/conventions.md)."""

from __future__ import annotations

import numpy as np

from dirac.rigidbody.euler_poisson import (
    casimir,
    energy,
    euler_poisson_rhs,
    lab_momentum,
    lean_rhs_full,
    lean_rhs_M,
)


def _random_state(rng):
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    if np.linalg.det(q) < 0:
        q[:, 0] *= -1
    return rng.normal(size=3), q


def test_energy_of_standard_case_matches_reference():
    # standard test case (docs/conventions.md): H = 0.64712527931383642713
    M0 = np.array([np.cos(1.1), 0.0, np.sin(1.1)])
    assert abs(energy(M0, [2.0, 1.0, 2.0 / 3.0]) - 0.64712527931383642713) < 1e-15


def test_invariants_by_hand_and_stacked():
    M = np.array([[1.0, 2.0, 3.0], [0.0, -1.0, 0.5]])
    np.testing.assert_allclose(casimir(M), [14.0, 1.25])
    np.testing.assert_allclose(energy(M, [1.0, 2.0, 4.0]), [0.5 * (1 + 2 + 2.25), 0.5 * (0.5 + 0.0625)])


def test_rhs_is_euler_poisson_by_hand():
    # I = (1, 2, 4), M = (1, 1, 1): Omega = (1, 1/2, 1/4), M x Omega = (-1/4, 3/4, -1/2)
    y = np.concatenate([[1.0, 1.0, 1.0], np.eye(3).ravel()])
    f = euler_poisson_rhs(y, [1.0, 2.0, 4.0])
    np.testing.assert_allclose(f[:3], [-0.25, 0.75, -0.5])
    # R = 1: dR/dt = hat(Omega) = [[0, -w3, w2], [w3, 0, -w1], [-w2, w1, 0]]
    np.testing.assert_allclose(
        f[3:].reshape(3, 3), [[0, -0.25, 0.5], [0.25, 0, -1.0], [-0.5, 1.0, 0]]
    )


def test_lean_rhs_agree_with_numpy_field_and_conserve_invariants():
    rng = np.random.default_rng(7)
    inertia = np.array([0.7, 1.3, 2.1])
    for _ in range(20):
        M, R = _random_state(rng)
        y = np.concatenate([M, R.ravel()])
        f = euler_poisson_rhs(y, inertia)
        np.testing.assert_allclose(lean_rhs_full(0.0, y, *inertia), f, atol=1e-15)
        np.testing.assert_allclose(lean_rhs_M(0.0, M, *inertia), f[:3], atol=1e-15)
        dM, dR = f[:3], f[3:].reshape(3, 3)
        # d/dt of H, |M|^2, m = R M and R^T R vanish along the field
        assert abs(np.dot(M / inertia, dM)) < 1e-14
        assert abs(np.dot(M, dM)) < 1e-14
        np.testing.assert_allclose(dR @ M + R @ dM, 0.0, atol=1e-14)
        np.testing.assert_allclose(dR.T @ R + R.T @ dR, 0.0, atol=1e-14)


def test_lab_momentum_is_R_times_M():
    rng = np.random.default_rng(3)
    M, R = _random_state(rng)
    np.testing.assert_allclose(lab_momentum(M, R), R @ M)
    np.testing.assert_allclose(lab_momentum(np.stack([M, M]), np.stack([R, R]))[1], R @ M)
