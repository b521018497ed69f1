"""Batched Lie–Poisson kernels (dirac.rigidbody.batch): equal to the single-body kernel,
conserve the invariants, and the polynomial sin/cos is accurate to round-off.

No timing assertions here: speed is measured by ``dirac bench``.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest

from dirac.errors import InputError
from dirac.rigidbody.batch import (
    BLOCK,
    MAX_POLY_ANGLE,
    advance_batch,
    advance_batch_numpy,
    sincos_poly_array,
)
from dirac.rigidbody.splitting import SCHEMES, advance


def _random_bodies(n: int, seed: int, spread: float = 1.0):
    """``n`` bodies: random M, random rotations R, random physical inertias."""
    rng = np.random.default_rng(seed)
    M = spread * rng.normal(size=(n, 3))
    # random rotations from QR of Gaussian matrices, made proper
    q, r = np.linalg.qr(rng.normal(size=(n, 3, 3)))
    q = q * np.sign(np.diagonal(r, axis1=1, axis2=2))[:, None, :]
    q[np.linalg.det(q) < 0, :, 0] *= -1.0
    inertia = rng.uniform(0.5, 2.0, size=(n, 3))
    return np.ascontiguousarray(M), np.ascontiguousarray(q), 1.0 / inertia


def _single_body_reference(M, R, inv, dt, n_steps, coefficients, with_R=True):
    M = M.copy()
    R = R.copy()
    for b in range(M.shape[0]):
        m_b = np.ascontiguousarray(M[b])
        r_b = np.ascontiguousarray(R[b])
        advance(m_b, r_b, inv[b], dt, n_steps, coefficients, with_R)
        M[b] = m_b
        R[b] = r_b
    return M, R


# dt = 0.05: every angle below pi/4 (polynomial without reduction); dt = 0.3 and 0.6:
# angles up to a few radians (reduction by pi/2 and quadrant selects). The two kernels
# differ only by sin/cos rounding (< 1 ulp); large steps of a splitting map amplify such
# differences quickly (d theta / d M = h / I per sub-step), so the big-step cases are
# compared after few steps.
@pytest.mark.parametrize(
    "dt,spread,n_steps", [(0.05, 1.0, 40), (0.3, 1.0, 10), (0.6, 1.0, 1), (-0.1, 1.0, 20)]
)
@pytest.mark.parametrize("name", ["lie-poisson-2", "lie-poisson-4", "lie-poisson-8"])
def test_batch_equals_single_body_kernel(name, dt, spread, n_steps):
    n = BLOCK + 45  # two blocks, the second partly filled
    M0, R0, inv = _random_bodies(n, seed=7, spread=spread)
    coefficients = SCHEMES[name].coefficients
    M_ref, R_ref = _single_body_reference(M0, R0, inv, dt, n_steps, coefficients)
    M, R = M0.copy(), R0.copy()
    advance_batch(M, R, inv, dt, n_steps, coefficients)
    scale = np.linalg.norm(M0, axis=1)
    assert np.max(np.abs(M - M_ref).max(axis=1) / scale) <= 1e-14
    assert np.max(np.abs(R - R_ref)) <= 1e-14


def test_batch_large_angles_use_libm_and_still_match():
    # one sub-step angle beyond MAX_POLY_ANGLE: the kernel falls back to libm sin/cos
    M0, R0, inv = _random_bodies(5, seed=3)
    dt = 2.0 * MAX_POLY_ANGLE
    M_ref, R_ref = _single_body_reference(M0, R0, inv, dt, 3, (1.0,))
    M, R = M0.copy(), R0.copy()
    advance_batch(M, R, inv, dt, 3, (1.0,))
    np.testing.assert_allclose(M, M_ref, rtol=0, atol=1e-9)  # angles ~1e5: conditioning
    np.testing.assert_allclose(np.einsum("bij,bj->bi", R, M), np.einsum("bij,bj->bi", R0, M0), atol=1e-12)


def test_shared_inverse_inertia_broadcasts():
    M0, R0, _ = _random_bodies(30, seed=11)
    inv = 1.0 / np.array([2.0, 1.0, 2.0 / 3.0])
    M1, R1 = M0.copy(), R0.copy()
    advance_batch(M1, R1, inv, 0.1, 25, (1.0,))
    M2, R2 = M0.copy(), R0.copy()
    advance_batch(M2, R2, np.tile(inv, (30, 1)), 0.1, 25, (1.0,))
    np.testing.assert_array_equal(M1, M2)
    np.testing.assert_array_equal(R1, R2)


def test_without_R_gives_the_same_M_and_leaves_R_alone():
    M0, R0, inv = _random_bodies(70, seed=5)
    coefficients = SCHEMES["lie-poisson-4"].coefficients
    M1, R1 = M0.copy(), R0.copy()
    advance_batch(M1, R1, inv, 0.2, 30, coefficients, with_R=True)
    M2, R2 = M0.copy(), R0.copy()
    advance_batch(M2, R2, inv, 0.2, 30, coefficients, with_R=False)
    np.testing.assert_array_equal(M1, M2)
    np.testing.assert_array_equal(R2, R0)
    M3 = M0.copy()
    advance_batch(M3, None, inv, 0.2, 30, coefficients, with_R=False)
    np.testing.assert_array_equal(M3, M1)


def test_invariants_are_kept_to_round_off():
    # |M|^2 (Casimir of (248)), R^T R = 1 and the lab momentum m = R M are exact
    # invariants of every sub-flow, so 2000 steps keep them to round-off.
    M0, R0, inv = _random_bodies(40, seed=2)
    M, R = M0.copy(), R0.copy()
    advance_batch(M, R, inv, 0.05, 2000, SCHEMES["lie-poisson-2"].coefficients)
    np.testing.assert_allclose(np.sum(M * M, axis=1), np.sum(M0 * M0, axis=1), rtol=1e-12)
    orth = np.einsum("bki,bkj->bij", R, R) - np.eye(3)
    assert np.max(np.abs(orth)) < 1e-12
    np.testing.assert_allclose(
        np.einsum("bij,bj->bi", R, M), np.einsum("bij,bj->bi", R0, M0), rtol=0, atol=1e-12
    )


def test_strang_step_is_second_order_against_the_closed_form():
    # Body rotating about its principal axis 3, m = (0, 0, m3): M stays put and R is the
    # rotation about z by w t, w = m3 / I3 (paper (133)-(165)). Every sub-flow is then exact.
    inertia = np.array([[2.0, 1.0, 2.0 / 3.0]])
    m3 = 1.3
    M = np.array([[0.0, 0.0, m3]])
    R = np.eye(3)[None].copy()
    advance_batch(M, R, 1.0 / inertia, 0.01, 1000, (1.0,))
    angle = m3 / inertia[0, 2] * 10.0
    c, s = math.cos(angle), math.sin(angle)
    expected = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    np.testing.assert_allclose(R[0], expected, atol=1e-12)
    np.testing.assert_allclose(M[0], [0.0, 0.0, m3], atol=1e-15)


def test_numpy_baseline_computes_the_same_step():
    M0, R0, inv = _random_bodies(50, seed=9)
    coefficients = SCHEMES["lie-poisson-4"].coefficients
    M1, R1 = M0.copy(), R0.copy()
    advance_batch(M1, R1, inv, 0.1, 20, coefficients)
    M2, R2 = M0.copy(), R0.copy()
    advance_batch_numpy(M2, R2, inv, 0.1, 20, coefficients)
    np.testing.assert_allclose(M2, M1, rtol=0, atol=1e-14 * np.abs(M0).max())
    np.testing.assert_allclose(R2, R1, rtol=0, atol=1e-14)


def _exact_sin_cos(x: np.ndarray) -> tuple[list, list]:
    with mpmath.workdps(40):
        return [mpmath.sin(mpmath.mpf(float(v))) for v in x], [mpmath.cos(mpmath.mpf(float(v))) for v in x]


def _errors(approx: np.ndarray, exact: list) -> tuple[float, float]:
    """Largest absolute error and largest error in units of the last place."""
    with mpmath.workdps(40):
        abs_err = np.array([float(abs(mpmath.mpf(float(a)) - e)) for a, e in zip(approx, exact)])
    ulp = np.spacing(np.abs(np.array([float(e) for e in exact])))
    return float(abs_err.max()), float((abs_err / ulp).max())


def test_polynomial_sin_cos_against_40_digit_values():
    # The range used: sub-step angles |theta| <= pi/4 (reduction-free path) and, for big
    # steps, anything up to MAX_POLY_ANGLE, including angles next to multiples of pi/2.
    rng = np.random.default_rng(12)
    x = np.concatenate(
        [
            rng.uniform(-math.pi / 4, math.pi / 4, 1500),
            rng.uniform(-1e-6, 1e-6, 200),
            rng.uniform(-50.0, 50.0, 1000),
            rng.uniform(-MAX_POLY_ANGLE, MAX_POLY_ANGLE, 500),
            np.arange(-300, 301) * (math.pi / 2) + rng.uniform(-1e-3, 1e-3, 601),
        ]
    )
    s, c = sincos_poly_array(x)
    exact_s, exact_c = _exact_sin_cos(x)
    abs_s, ulp_s = _errors(s, exact_s)
    abs_c, ulp_c = _errors(c, exact_c)
    # absolute error below 1e-16 (|sin|, |cos| <= 1) and below one ulp everywhere
    # (faithful rounding, the accuracy class of libm's sin and cos)
    assert abs_s <= 1e-16 and abs_c <= 1e-16
    assert ulp_s < 1.0 and ulp_c < 1.0


def test_polynomial_sin_cos_against_numpy_on_a_dense_grid():
    x = np.linspace(-20.0, 20.0, 400_001)
    s, c = sincos_poly_array(x)
    assert np.max(np.abs(s - np.sin(x))) <= 1.2e-16
    assert np.max(np.abs(c - np.cos(x))) <= 1.2e-16
    # and to the last place: at most one ulp apart from libm (both are faithful)
    assert np.max(np.abs(s - np.sin(x)) / np.spacing(np.abs(np.sin(x)))) <= 1.0
    assert np.max(np.abs(c - np.cos(x)) / np.spacing(np.abs(np.cos(x)))) <= 1.0


@pytest.mark.parametrize(
    "M,R,inv,message",
    [
        (np.zeros((4, 2)), np.zeros((4, 3, 3)), np.ones(3), "shape"),
        (np.zeros((4, 3)), np.zeros((3, 3, 3)), np.ones(3), "R must"),
        (np.zeros((4, 3)), np.zeros((4, 3, 3)), np.ones((5, 3)), "inv_inertia"),
        (np.zeros((4, 3)), np.zeros((4, 3, 3)), -np.ones(3), "positive"),
        (np.zeros((4, 3), dtype=np.float32), np.zeros((4, 3, 3)), np.ones(3), "float64"),
    ],
)
def test_bad_input_is_rejected(M, R, inv, message):
    with pytest.raises(InputError, match=message):
        advance_batch(M, R, inv, 0.1, 3, (1.0,))
