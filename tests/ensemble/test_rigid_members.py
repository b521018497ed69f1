"""The free rigid body's member loop (dirac.ensemble.rigid_members) against single runs and hand rules."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from dirac.ensemble.chunk import compute_chunk
from dirac.ensemble.scene import parse_ensemble_scene
from dirac.rigidbody.batch import BLOCK

INERTIA = [1.0, 2.0, 3.0]


def _scene(run: dict, ensemble: dict, inertia=INERTIA):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return parse_ensemble_scene(
            {"system": {"name": "rigid_body", "inertia": inertia}, "initial": {"M": [0.0, 1.0, 0.0]},
             "run": run, "ensemble": ensemble}
        )


def test_members_equal_one_batched_run_of_integrate_to_the_last_bit():
    """300 members (two blocks of the loop) against one ``dirac.integrate`` run of a
    RigidBodyProblem holding the same 300 bodies: that run advances them by
    ``advance_batch`` (the same sub-flow kernel) in calls of ``max(100, 20000 // 300)``
    steps, and a sample interval here has 50 steps, so both merge the same half-steps and
    every sample of ``M`` and ``R`` must agree bit for bit."""
    from dirac import RigidBodyProblem, integrate

    count = 300
    assert count > BLOCK
    scene = _scene(
        {"method": "lie-poisson-4", "dt": 0.01, "t_end": 2.0, "samples": 5, "outputs": ["M", "R"]},
        {"count": count, "seed": 4, "reductions": ["initial_state", "final_state"],
         "M": {"distribution": "sphere", "norm": 1.5}, "R": {"distribution": "uniform"}},
    )
    result = compute_chunk(scene, 0, count)
    single = integrate(RigidBodyProblem(INERTIA, result["initial_M"], result["initial_R"]), "lie-poisson-4",
                       t_end=2.0, dt=0.01, samples=5, outputs=["M", "R"])
    assert np.array_equal(np.moveaxis(np.asarray(single["M"]), 0, 1), result["M"])
    assert np.array_equal(np.moveaxis(np.asarray(single["R"]), 0, 1), result["R"])
    assert np.array_equal(result["final_M"], result["M"][:, -1])
    assert np.array_equal(result["final_R"], result["R"][:, -1])


def test_flip_time_is_the_interpolated_sign_change_of_the_stored_samples():
    """flip_time is, by its definition, ``t_{k-1} + (t_k - t_{k-1}) a_{k-1} / (a_{k-1} - a_k)``
    at the first ``k`` with ``a_k a_0 < 0`` (``a = M_2``, the intermediate axis here):
    recomputed in numpy from the stored trajectory of ``M`` it must agree to the last bit."""
    scene = _scene(
        {"method": "lie-poisson-2", "dt": 0.05, "t_end": 30.0, "samples": 301, "outputs": ["M", "energy"]},
        {"count": 40, "seed": 9, "reductions": ["flip_time", "max_energy_error"],
         "M": {"distribution": "gaussian", "std": 0.05, "norm": 1.0}},
    )
    result = compute_chunk(scene, 0, 40)
    times = scene.times()
    flipped = 0
    for i in range(40):
        a = result["M"][i, :, 1]
        later = np.nonzero(a[1:] * a[0] < 0.0)[0]
        if later.size == 0:
            assert np.isnan(result["flip_time"][i])
            continue
        k = int(later[0]) + 1
        expected = times[k - 1] + (times[k] - times[k - 1]) * (a[k - 1] / (a[k - 1] - a[k]))
        assert result["flip_time"][i] == expected
        flipped += 1
        energy = result["energy"][i]
        assert result["max_energy_error"][i] == pytest.approx(np.max(np.abs(energy - energy[0]) / energy[0]),
                                                              rel=1e-15, abs=0.0)
    assert 0 < flipped


def test_the_attitude_is_not_needed_for_the_momentum():
    """Each sub-flow turns ``M`` using ``M`` alone (``theta = h M_k / I_k``), so a scene that
    does not advance ``R`` must give the same bits of ``M`` as one that does."""
    run = {"method": "lie-poisson-6", "dt": 0.02, "t_end": 4.0, "samples": 9, "outputs": ["M"]}
    members = {"count": 20, "seed": 1, "M": {"distribution": "sphere", "norm": 3.0}, "R": {"distribution": "uniform"}}
    without = _scene(run, {**members, "reductions": ["flip_time"]})
    with_attitude = _scene(run, {**members, "reductions": ["flip_time", "final_state"]})
    assert not without.with_R and with_attitude.with_R
    a, b = compute_chunk(without, 0, 20), compute_chunk(with_attitude, 0, 20)
    assert np.array_equal(a["M"], b["M"]) and np.array_equal(a["flip_time"], b["flip_time"], equal_nan=True)
    R = b["final_R"]  # and the attitude that was advanced stays a rotation
    assert np.abs(np.einsum("nki,nkj->nij", R, R) - np.eye(3)).max() < 1e-13


def test_lab_momentum_and_casimir_are_conserved_by_each_sub_flow():
    """``m = R M`` and ``|M|^2`` (248) are invariants of every exact sub-flow (the rotations
    of ``M`` and ``R`` cancel in ``R M``): the stored samples keep their initial values to
    round-off, for members with their own inertia."""
    scene = _scene(
        {"method": "lie-poisson-4", "dt": 0.05, "t_end": 10.0, "samples": 21,
         "outputs": ["lab_momentum", "casimir"]},
        {"count": 2 * BLOCK + 3, "seed": 2, "reductions": ["max_casimir_error"],
         "M": {"distribution": "sphere", "norm": 2.0}, "R": {"distribution": "uniform"},
         "inertia": {"distribution": "loguniform", "low": [1.0, 1.0, 1.0], "high": [5.0, 5.0, 5.0]}},
    )
    result = compute_chunk(scene, 0, scene.count)
    lab = result["lab_momentum"]
    assert np.abs(lab - lab[:, :1]).max() < 1e-13
    assert np.abs(result["casimir"] - 4.0).max() < 1e-13
    assert result["max_casimir_error"].max() < 1e-13


def test_chunks_of_any_size_give_the_same_bits():
    """A member's loop depends on nothing but its own data (no chunk-wide choice here: every
    angle is far below the libm limit), so cutting the members differently changes no bit."""
    scene = _scene(
        {"method": "lie-poisson-4", "dt": 0.05, "t_end": 5.0, "samples": 11, "outputs": ["energy"]},
        {"count": 600, "seed": 5, "reductions": ["flip_time", "max_energy_error", "final_state"],
         "M": {"distribution": "sphere", "norm": 1.0}, "R": {"distribution": "uniform"}},
    )
    whole = compute_chunk(scene, 0, 600)
    parts = [compute_chunk(scene, lo, hi) for lo, hi in ((0, 7), (7, 300), (300, 600))]
    for name, array in whole.items():
        assert np.array_equal(array, np.concatenate([part[name] for part in parts]), equal_nan=True), name
