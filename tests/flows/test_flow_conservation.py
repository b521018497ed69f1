"""Conservation through the ``integrate`` loop.

* Symplectic / Poisson methods: the energy error stays bounded (no drift) over 10^6
  steps (``@pytest.mark.slow``; CI runs a bounded 10^4-step version, see
  ``tests/conftest.py``): the error over the last tenth of the run is no larger than
  over the first tenth, up to a factor.
* Splittings and midpoint keep ``|M|^2`` and ``R^T R = 1`` to 1e-12; RATTLE keeps the
  constraint residuals at its Newton tolerance.
"""

from __future__ import annotations

import numpy as np
import pytest

from dirac.flows import ConstrainedProblem, RigidBodyProblem, integrate

INERTIA = np.array([1.0, 2.0, 3.0])
M0 = np.array([0.6, 0.8, 0.5])


def _no_drift(energy: np.ndarray, tolerance: float) -> None:
    error = np.abs(energy - energy[0])
    tenth = max(1, len(error) // 10)
    early, late = error[:tenth].max(), error[-tenth:].max()
    assert error.max() < tolerance
    assert late < 3.0 * early + 1e-12  # bounded oscillation, not a drift (1e-12: round-off)


def _energy_run(method: str, steps: int, dt: float) -> np.ndarray:
    solution = integrate(RigidBodyProblem(INERTIA, M0), method, t_end=steps * dt, dt=dt, samples=201,
                         outputs=["energy", "casimir", "R"])
    assert solution.steps == steps
    casimir = solution["casimir"]
    R = solution["R"]
    assert np.abs(casimir - casimir[0]).max() < 1e-12
    assert np.abs(np.einsum("nki,nkj->nij", R, R) - np.eye(3)).max() < 1e-12
    return solution["energy"]


@pytest.mark.parametrize("method", ["lie-poisson-2", "lie-poisson-4", "midpoint"])
def test_energy_bounded_bounded_run(method):
    _no_drift(_energy_run(method, 10_000, 0.05), 5e-3)


@pytest.mark.slow
@pytest.mark.parametrize("method", ["lie-poisson-2", "lie-poisson-4", "midpoint"])
def test_energy_bounded_over_a_million_steps(method, stress):
    steps = int(1_000_000 * stress)
    steps = max(steps, 10_000)
    _no_drift(_energy_run(method, steps, 0.05), 5e-3)


def _pendulum_run(system, method: str, steps: int, dt: float):
    theta = 1.2
    problem = ConstrainedProblem(system, [np.sin(theta), -np.cos(theta)], [0.3, 0.3 * np.tan(theta)])
    return integrate(problem, method, t_end=steps * dt, dt=dt, samples=201,
                     outputs=["energy", "constraint_residual"], newton_tolerance=1e-12)


@pytest.mark.parametrize("method", ["rattle-2", "rattle-4", "midpoint"])
def test_constrained_energy_bounded_and_constraints_kept(method, pendulum_system):
    solution = _pendulum_run(pendulum_system, method, 5_000, 0.01)
    _no_drift(solution["energy"], 5e-2)
    assert solution["constraint_residual"].max() < 1e-11  # Newton tolerance 1e-12 times the scale 1 + |q|^2


@pytest.mark.slow
def test_rattle_energy_bounded_over_a_million_steps(pendulum_system, stress):
    steps = max(int(1_000_000 * stress), 10_000)
    solution = _pendulum_run(pendulum_system, "rattle-2", steps, 0.01)
    _no_drift(solution["energy"], 5e-2)
    assert solution["constraint_residual"].max() < 1e-11


def test_lab_momentum_is_conserved_by_splitting_and_exact():
    for method in ("lie-poisson-6", "exact"):
        solution = integrate(RigidBodyProblem(INERTIA, M0), method, t_end=100.0, dt=0.05, samples=51,
                             outputs=["lab_momentum"])
        lab = solution["lab_momentum"]
        assert np.abs(lab - lab[0]).max() < 1e-12, method


def test_heavy_top_keeps_vertical_momentum_and_bounded_energy():
    from dirac.flows import HeavyTopProblem

    problem = HeavyTopProblem([1.0, 2.0, 3.0], [1.0, 0.5, 2.0], mass_gravity=0.5, center_of_mass=[0.1, 0.2, 0.5])
    solution = integrate(problem, "lie-poisson-4", t_end=200.0, dt=0.02, samples=201,
                         outputs=["energy", "lab_momentum_z", "R"])
    assert np.abs(solution["lab_momentum_z"] - solution["lab_momentum_z"][0]).max() < 1e-12
    R = solution["R"]
    assert np.abs(np.einsum("nki,nkj->nij", R, R) - np.eye(3)).max() < 1e-12
    _no_drift(solution["energy"], 1e-4)
