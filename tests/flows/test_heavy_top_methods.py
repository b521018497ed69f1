"""The heavy top's exact-free-flow + kick methods and ``auto``'s choice between them and the
Lie–Poisson splittings."""

from __future__ import annotations

import numpy as np
import pytest

from dirac.flows import HeavyTopProblem, integrate

INERTIA = [1.0, 2.0, 3.0]
DIRECTION = np.array([1.0, 0.5, 2.0])
MASS_GRAVITY = 0.5
CHI = [0.1, 0.2, 0.5]


def _top(spin_scale: float) -> HeavyTopProblem:
    return HeavyTopProblem(INERTIA, spin_scale * DIRECTION, mass_gravity=MASS_GRAVITY, center_of_mass=CHI)


def _spin_over_gravity(problem: HeavyTopProblem) -> float:
    """``H_0(M0) / (m g |chi|)``: spin energy over the largest gravitational energy."""
    M0 = problem.M0[0]
    return float(0.5 * np.sum(M0 * M0 / problem.inertia) / (problem.mass_gravity * np.linalg.norm(CHI)))


def _reference(problem: HeavyTopProblem, t_end: float):
    return integrate(problem, "scipy-DOP853", t_end=t_end, samples=1, outputs=["M", "R"], tolerance=1e-13)


def _error(solution, reference) -> float:
    return max(np.abs(solution["M"][-1] - reference["M"][-1]).max(),
               np.abs(solution["R"][-1] - reference["R"][-1]).max())


@pytest.mark.parametrize(("name", "dt"), [("exact-kick-2", 0.0005), ("exact-kick-4", 0.02), ("exact-kick-6", 0.05),
                                          ("exact-kick-8", 0.1)])
def test_exact_kick_follows_a_tight_dop853_run_and_keeps_the_invariants(name, dt):
    """Each map is a composition of exact flows (the free flow of H_0 and the kick of V),
    so ``R^T R = 1`` and the vertical lab momentum ``<R M, e_z>`` (which both flows keep:
    the kick changes ``M`` by ``gamma x w``, orthogonal to ``gamma``, and the free flow keeps
    ``m = R M``) hold to round-off (``steps x eps x |m|``, below 1e-11 for 8000 steps); the
    energy ``H_0 + V`` is not conserved exactly but has no drift, and the state follows DOP853
    at tolerance 1e-13 to the method's error (``C dt^p``, below 1e-7 at these steps)."""
    problem = _top(1.0)
    solution = integrate(problem, name, t_end=4.0, dt=dt, samples=41, outputs=["M", "R", "energy", "lab_momentum_z"])
    assert _error(solution, _reference(problem, 4.0)) < 1e-7
    vertical = solution["lab_momentum_z"]
    assert np.abs(vertical - vertical[0]).max() < 1e-11
    R = solution["R"]
    assert np.abs(np.einsum("nki,nkj->nij", R, R) - np.eye(3)).max() < 1e-11
    energy = solution["energy"]
    assert np.abs(energy - energy[0]).max() < 1e-6 * abs(energy[0])


def test_exact_kick_beats_the_splitting_of_the_same_order_on_a_fast_top_at_equal_step():
    """Splitting ``H = H_0 + V`` into two exactly solved parts, the local error of the
    composed step is a sum of nested brackets each containing ``V`` at least once
    (Hairer, Lubich & Wanner, Sect. III.5): of size ``eps = V / H_0`` relative to the
    Lie–Poisson splitting's, whose brackets of the parts of ``H_0`` do not vanish with
    ``V``. At spin energy 1000 x the gravitational energy and equal step the exact-kick
    error is at least 100 x smaller."""
    problem = _top(15.0)
    assert _spin_over_gravity(problem) > 1000.0
    reference = _reference(problem, 2.0)
    split = integrate(problem, "lie-poisson-4", t_end=2.0, dt=0.01, samples=1, outputs=["M", "R"])
    exact_kick = integrate(problem, "exact-kick-4", t_end=2.0, dt=0.01, samples=1, outputs=["M", "R"])
    assert _error(exact_kick, reference) * 100.0 < _error(split, reference)


@pytest.mark.parametrize(("spin_scale", "family"), [(15.0, "exact-kick-"), (0.5, "lie-poisson-")])
def test_auto_picks_by_work_precision_on_fast_and_slow_tops(spin_scale, family):
    """``auto`` weighs each candidate's Richardson step against its cost per stage: on a fast
    top (spin energy 1000 x gravity) the exact-kick error, proportional to ``V / H_0``,
    allows steps large enough to pay for the dearer stage; on a slow top (spin energy about
    gravity) the errors are alike and the cheaper Lie–Poisson stage wins. Either way the
    result meets the tolerance against DOP853."""
    problem = _top(spin_scale)
    ratio = _spin_over_gravity(problem)
    assert ratio > 1000.0 if family == "exact-kick-" else ratio < 2.0
    solution = integrate(problem, "auto", t_end=10.0, samples=2, outputs=["M", "R"], tolerance=1e-6)
    assert solution.meta()["auto"]["chosen"].startswith(family)
    assert _error(solution, _reference(problem, 10.0)) < 1e-6


def test_exact_kick_keeps_the_attitude_orthogonal_without_drift():
    """Each stage ends with a Björck–Bowie step ``R <- R (3 - R^T R) / 2``, which maps an
    error ``e`` of ``R^T R - 1`` to ``O(e^2)`` plus one rounding: ``R^T R - 1`` stays at a few
    ulps however many steps are taken (without it the frames of the exact flow, normalised
    where rounding is biased, add about 4e-16 per step: 4e-11 after 1e5 steps)."""
    problem = _top(5.0)
    solution = integrate(problem, "exact-kick-4", t_end=1000.0, dt=0.01, samples=3, outputs=["R"])
    R = solution["R"]
    assert np.abs(np.einsum("nki,nkj->nij", R, R) - np.eye(3)).max() < 2e-15
