"""Per-member reductions against closed forms (the standard test case, docs/conventions.md) and independent code paths."""

from __future__ import annotations

import math

import numpy as np
import pytest

from dirac.ensemble.chunk import compute_chunk
from dirac.ensemble.scene import parse_ensemble_scene

#: The standard test case (docs/conventions.md): the body, its period of M and M(10) (40-digit references).
INERTIA = [2.0, 1.0, 2.0 / 3.0]
M0 = [math.cos(1.1), 0.0, math.sin(1.1)]
PERIOD = 10.73146523488280383381
M_AT_10 = np.array([0.40706613658804081, 0.28300742681284408, 0.86844916766156164])


def _scene(run: dict, ensemble: dict, initial: dict | None = None, inertia=INERTIA):
    import warnings

    with warnings.catch_warnings():  # the standard body violates the triangle inequality
        warnings.simplefilter("ignore")
        return parse_ensemble_scene(
            {
                "system": {"name": "rigid_body", "inertia": inertia},
                "initial": initial or {"M": M0},
                "run": run,
                "ensemble": ensemble,
            }
        )


def test_flip_time_is_the_quarter_period_of_the_standard_body():
    # 2 H_0 / |M|^2 = 1.294 > 1/I_2: M circles body axis 3 and M_1 = A cn(tau) with
    # M_2(0) = 0, so M_1 first vanishes at a quarter of the period of M.
    # Linear interpolation between samples t_a, t_b errs by about
    # (t_a - t*)(t_b - t*) M_1''' / (6 M_1') <= spacing^2 / 4 * O(1) = 2.5e-7 for spacing 1e-3.
    scene = _scene(
        {"method": "lie-poisson-8", "dt": 0.001, "t_end": 3.0, "samples": 3001},
        {"count": 2, "reductions": ["flip_time"], "flip_axis": 1},
    )
    flip = compute_chunk(scene, 0, 2)["flip_time"]
    assert flip == pytest.approx([PERIOD / 4] * 2, abs=2.5e-7)


def test_flip_time_with_coarse_samples_is_bracketed_by_the_samples():
    scene = _scene(
        {"method": "lie-poisson-8", "dt": 0.01, "t_end": 3.0, "samples": 31},
        {"count": 1, "reductions": ["flip_time"], "flip_axis": 1},
    )
    flip = compute_chunk(scene, 0, 1)["flip_time"][0]
    assert 2.6 < flip < 2.7 and flip != pytest.approx(2.6) and flip != pytest.approx(2.7)


def test_flip_time_is_nan_without_a_flip():
    # M_3 never changes sign (M circles axis 3); M_2(0) = 0 has no sign to flip from
    scene = _scene(
        {"method": "lie-poisson-4", "dt": 0.01, "t_end": 20.0, "samples": 201},
        {"count": 1, "reductions": ["flip_time"], "flip_axis": 3},
    )
    assert np.isnan(compute_chunk(scene, 0, 1)["flip_time"][0])
    scene = _scene(
        {"method": "lie-poisson-4", "dt": 0.01, "t_end": 20.0, "samples": 201},
        {"count": 1, "reductions": ["flip_time"], "flip_axis": 2},
    )
    assert np.isnan(compute_chunk(scene, 0, 1)["flip_time"][0])


def test_final_state_matches_the_reference_value():
    scene = _scene(
        {"method": "lie-poisson-8", "dt": 0.01, "t_end": 10.0, "samples": 11},
        {"count": 3, "reductions": ["final_state", "max_casimir_error"]},
    )
    result = compute_chunk(scene, 0, 3)
    assert np.abs(result["final_M"] - M_AT_10).max() < 1e-12
    R = result["final_R"]
    assert np.abs(np.einsum("nki,nkj->nij", R, R) - np.eye(3)).max() < 1e-13
    # m = R M is conserved (R(0) = 1, so m = M(0))
    assert np.abs(np.einsum("nij,nj->ni", R, result["final_M"]) - M0).max() < 1e-13
    assert result["max_casimir_error"].max() < 1e-13


def test_energy_error_is_second_order_for_lie_poisson_2():
    errors = []
    for dt in (0.02, 0.01):
        scene = _scene(
            {"method": "lie-poisson-2", "dt": dt, "t_end": 10.0, "samples": 501},
            {"count": 1, "reductions": ["max_energy_error"]},
        )
        errors.append(compute_chunk(scene, 0, 1)["max_energy_error"][0])
    assert errors[0] / errors[1] == pytest.approx(4.0, rel=0.1)


def test_max_energy_error_equals_the_maximum_over_the_stored_energy():
    scene = _scene(
        {"method": "lie-poisson-2", "dt": 0.05, "t_end": 5.0, "samples": 51, "outputs": ["energy"]},
        {"count": 1, "reductions": ["max_energy_error"]},
    )
    result = compute_chunk(scene, 0, 1)
    energy = result["energy"][0]
    assert energy[0] == pytest.approx(0.64712527931383642713, rel=1e-15)
    expected = np.max(np.abs(energy - energy[0]) / energy[0])
    assert result["max_energy_error"][0] == pytest.approx(expected, rel=1e-12)


def test_members_follow_the_single_body_kernel():
    from dirac.rigidbody.splitting import SCHEMES, advance

    scene = _scene(
        {"method": "lie-poisson-4", "dt": 0.01, "t_end": 1.0, "samples": 2, "outputs": ["M", "R"]},
        {
            "count": 5,
            "seed": 3,
            "reductions": ["initial_state"],
            "M": {"distribution": "sphere", "norm": 2.0},
            "R": {"distribution": "uniform"},
            "inertia": {"distribution": "uniform", "low": [1.0, 1.0, 1.0], "high": [2.0, 2.0, 2.0]},
        },
    )
    result = compute_chunk(scene, 0, 5)
    for i in range(5):
        M = result["initial_M"][i].copy()
        R = result["initial_R"][i].copy()
        advance(M, R, 1.0 / result["inertia"][i], 0.01, 100, SCHEMES["lie-poisson-4"].coefficients, True)
        assert np.abs(result["M"][i, -1] - M).max() < 1e-13
        assert np.abs(result["R"][i, -1] - R).max() < 1e-13
        assert np.array_equal(result["M"][i, 0], result["initial_M"][i])
