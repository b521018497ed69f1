"""``exact`` through ``integrate`` against an independent tight-tolerance DOP853 run.

Ten and more bodies over t in [0, 50]: random inertias and momenta, two near-separatrix
starts (intermediate axis), extreme inertia ratios and a nearly symmetric body. The
reference integrates the Euler–Poisson equations (250)–(251), written out here, with
scipy's DOP853 at rtol = 2.3e-14 (scipy's floor), atol = 1e-15.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from dirac.flows import RigidBodyProblem, integrate


def euler_poisson(t, y, i1, i2, i3):
    """dM/dt = M x Omega, dR/dt = R hat(Omega), Omega = I^{-1} M, in plain floats (speed)."""
    m1, m2, m3, a, b, c, d, e, f, g, h, k = y
    w1, w2, w3 = m1 / i1, m2 / i2, m3 / i3
    return [m2 * w3 - m3 * w2, m3 * w1 - m1 * w3, m1 * w2 - m2 * w1,
            b * w3 - c * w2, c * w1 - a * w3, a * w2 - b * w1,
            e * w3 - f * w2, f * w1 - d * w3, d * w2 - e * w1,
            h * w3 - k * w2, k * w1 - g * w3, g * w2 - h * w1]


def _random_rotation(rng: np.random.Generator) -> np.ndarray:
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def _bodies() -> list[tuple[str, np.ndarray, np.ndarray, np.ndarray]]:
    rng = np.random.default_rng(20240611)
    bodies = []
    for k in range(6):
        g = rng.uniform(0.2, 2.0, size=3)  # principal values of the mass matrix: physical body
        inertia = np.array([g[1] + g[2], g[0] + g[2], g[0] + g[1]])
        bodies.append((f"random-{k}", inertia, rng.normal(size=3), _random_rotation(rng)))
    bodies.append(("separatrix-1e-3", np.array([1.0, 2.0, 3.0]), np.array([1e-3, 1.0, 1e-3]), np.eye(3)))
    bodies.append(("separatrix-1e-4", np.array([3.0, 2.0, 1.5]), np.array([-1e-4, 1.2, 2e-4]), _random_rotation(rng)))
    bodies.append(("flat-ratio-100", np.array([0.02, 1.0, 1.02]), np.array([0.05, 0.6, 0.7]), np.eye(3)))
    bodies.append(("needle-ratio-1e3", np.array([1000.0, 1000.5, 1.0]), np.array([2.0, 3.0, 0.05]), _random_rotation(rng)))
    bodies.append(("nearly-symmetric", np.array([1.0, 1.0 + 1e-7, 2.0]), np.array([0.3, 0.4, 0.5]), np.eye(3)))
    return bodies


@pytest.mark.parametrize("label, inertia, M0, R0", _bodies(), ids=[b[0] for b in _bodies()])
def test_exact_flow_matches_dop853(label, inertia, M0, R0):
    times = np.linspace(0.0, 50.0, 26)
    solution = integrate(RigidBodyProblem(inertia, M0, R0), "exact", t_end=50.0, samples=26, outputs=["M", "R"])
    assert solution.steps == 0
    reference = solve_ivp(euler_poisson, (0.0, 50.0), np.concatenate([M0, R0.ravel()]), method="DOP853",
                          t_eval=times, rtol=2.3e-14, atol=1e-15, args=tuple(inertia))
    assert reference.success
    M_ref = reference.y[:3].T
    R_ref = reference.y[3:].T.reshape(-1, 3, 3)
    scale = max(1.0, np.linalg.norm(M0))
    assert np.abs(solution["M"] - M_ref).max() < 1e-11 * scale, label
    assert np.abs(solution["R"] - R_ref).max() < 1e-11, label
