"""Counter-based draws: member i depends on (seed, i) only; the named distributions."""

from __future__ import annotations

import numpy as np
import pytest

from dirac.ensemble.distributions import Gaussian, HaarRotation, LogUniform, Sphere, Uniform, parse_distribution
from dirac.ensemble.sampling import SAMPLING_BLOCK, STREAMS, MemberSource, draw_range
from dirac.errors import InputError


def _members(source: MemberSource, chunk: int) -> tuple[np.ndarray, ...]:
    parts = [source.members(a, min(a + chunk, source.count)) for a in range(0, source.count, chunk)]
    return tuple(np.concatenate(arrays) for arrays in zip(*parts))


def test_draws_are_bit_identical_whatever_the_chunking():
    count = 2 * SAMPLING_BLOCK + 123  # spans three sampling blocks
    source = MemberSource(
        count,
        seed=2026,
        distributions={
            "M": Gaussian(np.array([0.0, 1.0, 0.0]), np.full(3, 1e-3), 1.0),
            "R": HaarRotation(),
            "inertia": LogUniform(np.array([1.0, 1.0, 1.0]), np.array([5.0, 5.0, 5.0])),
        },
    )
    whole = source.members(0, count)
    for chunk in (1000, 1025, 37):
        pieces = _members(source, chunk)
        for a, b in zip(whole, pieces):
            assert a.tobytes() == b.tobytes()


def test_seed_and_streams_are_independent():
    sphere = Sphere(1.0)
    a = draw_range(sphere, 1, STREAMS["M"], 0, 50)
    assert not np.array_equal(a, draw_range(sphere, 2, STREAMS["M"], 0, 50))
    # changing the R distribution does not change the M draws (own stream per quantity)
    base = {"M": sphere, "inertia": Uniform(np.ones(3), 2 * np.ones(3))}
    with_haar = MemberSource(50, 3, {**base, "R": HaarRotation()}).members(0, 50)
    with_fixed = MemberSource(50, 3, {**base, "R": parse_distribution("R", {}, "[R]", np.eye(3))}).members(0, 50)
    assert np.array_equal(with_haar[0], with_fixed[0])
    assert np.array_equal(with_haar[2], with_fixed[2])
    assert np.array_equal(with_fixed[1], np.broadcast_to(np.eye(3), (50, 3, 3)))


def test_sphere_is_uniform_on_the_sphere():
    M = draw_range(Sphere(2.5), 5, 0, 0, 40000)
    assert np.allclose(np.linalg.norm(M, axis=1), 2.5, rtol=1e-15, atol=0)
    # uniform on the sphere: each component of M/|M| is uniform on [-1, 1] (Archimedes),
    # mean 0 and variance 1/3; 5 standard errors
    unit = M / 2.5
    n = unit.shape[0]
    assert np.all(np.abs(unit.mean(axis=0)) < 5 * np.sqrt(1 / 3 / n))
    assert np.all(np.abs((unit**2).mean(axis=0) - 1 / 3) < 5 * np.sqrt(4 / 45 / n))


def test_haar_rotations_are_proper_and_uniform():
    R = draw_range(HaarRotation(), 9, 1, 0, 40000)
    assert np.abs(np.einsum("nki,nkj->nij", R, R) - np.eye(3)).max() < 1e-14
    assert np.allclose(np.linalg.det(R), 1.0, atol=1e-14)
    # Haar measure: E[R] = 0 and E[R_ij^2] = 1/3 (each column is uniform on the sphere)
    n = R.shape[0]
    assert np.abs(R.mean(axis=0)).max() < 5 * np.sqrt(1 / 3 / n)
    assert np.abs((R**2).mean(axis=0) - 1 / 3).max() < 5 * np.sqrt(4 / 45 / n)


def test_gaussian_cloud_mean_and_spread():
    g = Gaussian(np.array([0.1, 1.0, -0.2]), np.array([0.01, 0.02, 0.03]))
    M = draw_range(g, 4, 0, 0, 40000)
    n = M.shape[0]
    assert np.all(np.abs(M.mean(axis=0) - g.mean) < 5 * g.std / np.sqrt(n))
    assert np.allclose(M.std(axis=0), g.std, rtol=5 * np.sqrt(2 / n))


def test_uniform_inertia_bounds():
    low, high = np.array([1.0, 2.0, 3.0]), np.array([1.5, 2.5, 4.0])
    inertia = draw_range(Uniform(low, high), 4, 2, 0, 10000)
    assert np.all(inertia >= low) and np.all(inertia <= high)
    assert np.allclose(inertia.mean(axis=0), (low + high) / 2, atol=5 * (high - low).max() / np.sqrt(12 * 10000))


@pytest.mark.parametrize(
    ("quantity", "table", "fragment"),
    [
        ("M", {"distribution": "cube"}, "distribution: unknown distribution 'cube'; known distributions: fixed, gaussian, sphere"),
        ("M", {"distribution": "sphre"}, "unknown distribution 'sphre' (did you mean 'sphere'?)"),
        ("M", {"distribution": "sphere", "nrom": 1.0}, "has an unknown key 'nrom' (did you mean 'norm'?)"),
        ("M", {"distribution": "sphere"}, "needs 'norm'"),
        ("M", {"distribution": "sphere", "norm": -1.0}, "norm = -1.0 must be"),
        ("M", {"distribution": "gaussian", "mean": [0, 1, 0]}, "needs 'std'"),
        ("inertia", {"distribution": "uniform", "low": [1, 1, 1], "high": [0.5, 2, 2]}, "0 < low <= high"),
        ("R", {"distribution": "fixed", "value": [1, 0, 0]}, "shape (3, 3)"),
    ],
)
def test_bad_distribution_tables_name_the_key(quantity, table, fragment):
    with pytest.raises(InputError, match=None) as info:
        parse_distribution(quantity, table, f"[ensemble.{quantity}]")
    assert fragment in str(info.value)
    assert f"[ensemble.{quantity}]" in str(info.value)
