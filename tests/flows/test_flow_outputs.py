"""What ``integrate`` computes and stores: only the requested outputs, at the requested
times; batches; exact cost independent of t_end; step adaptation to the sampling."""

from __future__ import annotations

import numpy as np
import pytest

from dirac.errors import InputError
from dirac.flows import RigidBodyProblem, integrate
from dirac.flows.integration import sample_times

INERTIA = np.array([1.0, 2.0, 3.0])
M0 = np.array([0.6, 0.8, 0.5])


def test_samples_are_uniform_with_both_ends_and_one_means_final_only():
    assert np.array_equal(sample_times(10.0, 6), [0.0, 2.0, 4.0, 6.0, 8.0, 10.0])
    assert np.array_equal(sample_times(10.0, 1), [10.0])
    solution = integrate(RigidBodyProblem(INERTIA, M0), "lie-poisson-4", t_end=10.0, dt=0.01, samples=1, outputs=["M"])
    assert solution.t.tolist() == [10.0]
    assert solution["M"].shape == (1, 3)
    assert solution.steps == 1000


def test_only_requested_outputs_are_stored():
    solution = integrate(RigidBodyProblem(INERTIA, M0), "lie-poisson-4", t_end=1.0, dt=0.01, samples=11,
                         outputs=["energy"])
    assert set(solution.outputs) == {"energy"}
    with pytest.raises(KeyError, match="not requested"):
        solution["M"]


@pytest.mark.parametrize("method", ["lie-poisson-4", "midpoint", "exact", "scipy-DOP853"])
def test_a_scene_asking_only_for_M_never_advances_R(method, monkeypatch):
    from dirac.flows.methods.registry import get_method

    problem = RigidBodyProblem(INERTIA, M0)
    stepper = get_method(method).start(problem, ("M",), {"t_end": 1.0, "tolerance": 1e-8})
    assert stepper.with_R is False
    full = integrate(problem, method, t_end=3.0, dt=0.01, samples=4, outputs=["M", "R"])
    only_M = integrate(problem, method, t_end=3.0, dt=0.01, samples=4, outputs=["M"])
    assert np.abs(only_M["M"] - full["M"]).max() < 1e-9
    if method == "scipy-DOP853":  # 3 components integrated instead of 12
        assert only_M.evaluations <= full.evaluations


def test_exact_costs_the_same_for_short_and_very_long_spans():
    problem = RigidBodyProblem(INERTIA, M0)
    short = integrate(problem, "exact", t_end=1e2, samples=11, outputs=["M", "R"])
    long = integrate(problem, "exact", t_end=1e6, samples=11, outputs=["M", "R"])
    assert short.steps == long.steps == 0
    assert short.evaluations == long.evaluations == 11
    # still exact far out: |M|^2 and the energy are those of t = 0
    M = long["M"]
    assert np.abs(np.sum(M * M, axis=1) - M0 @ M0).max() < 1e-12


def test_fixed_step_is_adapted_to_divide_the_sample_spacing():
    solution = integrate(RigidBodyProblem(INERTIA, M0), "lie-poisson-2", t_end=1.0, dt=0.03, samples=3, outputs=["M"])
    assert solution.dt == pytest.approx(0.5 / 17)
    assert solution.steps == 34


def test_batched_states_match_single_runs():
    rng = np.random.default_rng(3)
    moments = rng.normal(size=(4, 3))
    batch = integrate(RigidBodyProblem(INERTIA, moments), "lie-poisson-4", t_end=2.0, dt=0.01, samples=3,
                      outputs=["M", "R"])
    assert batch["M"].shape == (3, 4, 3)
    assert batch["R"].shape == (3, 4, 3, 3)
    for b in range(4):
        single = integrate(RigidBodyProblem(INERTIA, moments[b]), "lie-poisson-4", t_end=2.0, dt=0.01, samples=3,
                           outputs=["M", "R"])
        assert np.array_equal(single["M"], batch["M"][:, b])
        assert np.array_equal(single["R"], batch["R"][:, b])


def test_counters_and_cpu_time_are_recorded():
    solution = integrate(RigidBodyProblem(INERTIA, M0), "midpoint", t_end=1.0, dt=0.01, samples=2, outputs=["M"])
    assert solution.steps == 100
    assert solution.evaluations >= 100
    assert solution.cpu_seconds >= 0.0
    meta = solution.meta()
    for key in ("system", "parameters", "method", "order", "dt", "steps", "cpu_seconds", "complete", "versions"):
        assert key in meta
    assert meta["complete"] is True and meta["method"] == "midpoint" and meta["order"] == 2


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"t_end": -1.0, "dt": 0.1}, "t_end"),
        ({"t_end": 1.0}, "give dt"),
        ({"t_end": 1.0, "dt": 0.1, "samples": 0}, "samples"),
        ({"t_end": 1.0, "dt": 0.1, "outputs": ["q"]}, r"^unknown output 'q'; known outputs: M, R, casimir, energy, "
                                                    r"lab_momentum, work; these are the outputs of a rigid body problem$"),
        ({"t_end": 1.0, "dt": 0.1, "outputs": ["enrgy"]}, r"unknown output 'enrgy' \(did you mean 'energy'\?\)"),
        ({"t_end": 1.0, "dt": 0.1, "tolerance": 2.0}, "tolerance"),
    ],
)
def test_bad_arguments_are_named(kwargs, match):
    with pytest.raises(InputError, match=match):
        integrate(RigidBodyProblem(INERTIA, M0), "lie-poisson-2", **kwargs)


def test_unknown_and_unsuitable_methods_are_refused(pendulum_system):
    from dirac.flows import ConstrainedProblem

    with pytest.raises(InputError, match="unknown method 'rk4'.*lie-poisson-2"):
        integrate(RigidBodyProblem(INERTIA, M0), "rk4", t_end=1.0, dt=0.1)
    problem = ConstrainedProblem(pendulum_system, [1.0, 0.0], [0.0, 0.0])
    with pytest.raises(InputError, match="cannot integrate a constrained problem.*rattle-2"):
        integrate(problem, "lie-poisson-2", t_end=1.0, dt=0.1)


def test_auto_picks_exact_for_the_free_body_sparse_or_dense(standard_problem):
    """Measured costs: an exact sample (< 1 us) is cheaper than sampling a stepping run."""
    for samples in (11, 100_001):
        solution = integrate(standard_problem, "auto", t_end=1000.0, samples=samples, outputs=["M"], tolerance=1e-6)
        assert solution.method == "exact"
        assert solution.meta()["auto"]["chosen"] == "exact"


def test_auto_meets_the_tolerance_for_a_constrained_system(pendulum_system):
    from test_flow_convergence import pendulum_exact

    from dirac.flows import ConstrainedProblem

    theta = 1.0
    problem = ConstrainedProblem(pendulum_system, [np.sin(theta), -np.cos(theta)], [0.0, 0.0])
    solution = integrate(problem, "auto", t_end=3.0, samples=2, outputs=["q", "p"], tolerance=1e-6)
    assert solution.method.startswith("rattle-")
    q, p = pendulum_exact(theta, 3.0)
    assert np.abs(solution["q"][-1] - q).max() < 1e-6
    assert np.abs(solution["p"][-1] - p).max() < 1e-5
