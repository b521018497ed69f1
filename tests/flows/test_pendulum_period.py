"""The pendulum's period from RATTLE and midpoint against the exact elliptic period.

A pendulum released from rest at ``theta0`` has period ``T = 4 K(k^2) sqrt(l/g)``,
``k = sin(theta0/2)`` (complete elliptic integral of the first kind). The period is read
off the crossings of ``x = 0`` (cubic Hermite interpolation of ``x`` and ``x_dot`` between
samples ten steps apart).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.special import ellipk

from dirac.flows import ConstrainedProblem, integrate


def _crossings(t: np.ndarray, x: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Zeros of x(t) from cubic Hermite interpolation of (x, x_dot) on each sign change."""
    roots = []
    for i in np.nonzero(np.sign(x[:-1]) != np.sign(x[1:]))[0]:
        h = t[i + 1] - t[i]
        s = x[i] / (x[i] - x[i + 1])  # linear guess, then Newton on the Hermite cubic
        for _ in range(20):
            h00, h10, h01, h11 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s, -2 * s**3 + 3 * s**2, s**3 - s**2
            d00, d10, d01, d11 = 6 * s**2 - 6 * s, 3 * s**2 - 4 * s + 1, -6 * s**2 + 6 * s, 3 * s**2 - 2 * s
            value = h00 * x[i] + h10 * h * v[i] + h01 * x[i + 1] + h11 * h * v[i + 1]
            slope = d00 * x[i] + d10 * h * v[i] + d01 * x[i + 1] + d11 * h * v[i + 1]
            s -= value / slope
        roots.append(t[i] + s * h)
    return np.array(roots)


@pytest.mark.parametrize("method, tolerance", [("rattle-2", 1e-4), ("rattle-4", 1e-7), ("midpoint", 1e-4)])
@pytest.mark.parametrize("theta0", [0.3, 2.5])
def test_period_matches_the_elliptic_period(method, tolerance, theta0, pendulum_system):
    g, length = 9.81, 1.0
    exact = 4.0 * ellipk(np.sin(theta0 / 2.0) ** 2) * np.sqrt(length / g)
    dt = 0.001
    t_end = 3.2 * exact
    samples = int(round(t_end / (10 * dt))) + 1
    problem = ConstrainedProblem(pendulum_system, [length * np.sin(theta0), -length * np.cos(theta0)], [0.0, 0.0])
    solution = integrate(problem, method, t_end=t_end, dt=dt, samples=samples, outputs=["q", "q_dot"])
    crossings = _crossings(solution.t, solution["q"][:, 0], solution["q_dot"][:, 0])
    assert len(crossings) >= 6
    # crossings alternate direction; two consecutive half-periods make one period
    periods = crossings[2:] - crossings[:-2]
    assert np.abs(periods - exact).max() < tolerance * exact + 2e-7, (periods, exact)
