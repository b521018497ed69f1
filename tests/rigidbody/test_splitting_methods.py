"""Lie–Poisson splitting methods (dirac.rigidbody.splitting): observed order, invariants,
the paper's closed forms (165), (183), and the reference value of the standard test case (docs/conventions.md)."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from dirac.errors import DiracWarning, InputError
from dirac.rigidbody.closed_forms import principal_axis_rotation, symmetric_top
from dirac.rigidbody.euler_poisson import energy
from dirac.rigidbody.exact import ExactRigidBodyFlow
from dirac.rigidbody.splitting import SCHEMES, advance, advance_scheme, build_sequence

STANDARD_I = np.array([2.0, 1.0, 2.0 / 3.0])
STANDARD_M0 = np.array([np.cos(1.1), 0.0, np.sin(1.1)])
REF_M10 = np.array([0.40706613658804081, 0.28300742681284408, 0.86844916766156164])


@pytest.fixture(scope="module")
def standard_exact_at_10():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DiracWarning)
        M, R = ExactRigidBodyFlow(STANDARD_I, STANDARD_M0).state([10.0])
    return M[0], R[0]


def _run(name, inertia, M0, R0, dt, n, with_R=True):
    M = np.array(M0, dtype=float)
    R = np.array(R0, dtype=float)
    advance_scheme(name, M, R, inertia, dt, n, with_R)
    return M, R


def test_scheme_table():
    for order in (2, 4, 6, 8):
        assert SCHEMES[f"lie-poisson-{order}"].order == order
        assert SCHEMES[f"lie-poisson-{order}"].splitting == "axes"
        assert SCHEMES[f"lie-poisson-sym-{order}"].splitting == "symmetric"
    for scheme in SCHEMES.values():
        gammas = np.array(scheme.coefficients)
        assert math.isclose(math.fsum(gammas), 1.0, abs_tol=1e-15)
        np.testing.assert_array_equal(gammas, gammas[::-1])  # symmetric composition


def test_merged_sequence_of_strang():
    inv = np.array([0.5, 1.0, 1.5])
    axes, rates, fractions, casimir_rate = build_sequence(inv, (1.0,), "axes")
    np.testing.assert_array_equal(axes, [0, 1, 2, 1, 0])
    np.testing.assert_allclose(fractions, [0.5, 0.5, 1.0, 0.5, 0.5])
    np.testing.assert_allclose(rates, inv[axes])
    assert casimir_rate == 0.0
    # Yoshida: the halves of axis 0 between the three stages merge
    axes, _, fractions, _ = build_sequence(inv, SCHEMES["lie-poisson-4"].coefficients, "axes")
    assert len(axes) == 13 and np.sum(fractions[axes == 2]) == pytest.approx(1.0)
    # symmetric split about the middle axis a = 1: rates 1/I_k - 1/I_a, Casimir rate 1/I_a
    axes, rates, fractions, casimir_rate = build_sequence(inv, (1.0,), "symmetric")
    np.testing.assert_array_equal(axes, [0, 2, 0])
    np.testing.assert_allclose(rates, [-0.5, 0.5, -0.5])
    assert casimir_rate == 1.0


# step counts over t = 10 keeping the error between ~1e-13 and ~1e-2 (asymptotic regime)
_STEPS = {2: [50, 100, 200, 400], 4: [20, 40, 80, 160], 6: [10, 20, 40, 80], 8: [8, 12, 18, 27]}


@pytest.mark.parametrize("name", sorted(SCHEMES))
def test_observed_convergence_order(name, standard_exact_at_10):
    scheme = SCHEMES[name]
    steps = _STEPS[scheme.order]
    if scheme.splitting == "symmetric" and scheme.order == 8:
        steps = [20, 27, 36, 48]  # ten times smaller error constant: smaller steps reach it
    M_ref, R_ref = standard_exact_at_10
    errors = []
    for n in steps:
        M, R = _run(name, STANDARD_I, STANDARD_M0, np.eye(3), 10.0 / n, n)
        errors.append(max(np.max(np.abs(M - M_ref)), np.max(np.abs(R - R_ref))))
    slope = np.polyfit(np.log(10.0 / np.array(steps)), np.log(errors), 1)[0]
    assert abs(slope - scheme.order) <= 0.3, (name, errors, slope)


@pytest.mark.parametrize("name", ["lie-poisson-8", "lie-poisson-sym-8"])
def test_reference_M10_at_small_step(name):
    M, _ = _run(name, STANDARD_I, STANDARD_M0, np.eye(3), 0.05, 200)
    np.testing.assert_allclose(M, REF_M10, rtol=0, atol=1e-12)


@pytest.mark.parametrize("name", ["lie-poisson-2", "lie-poisson-sym-2", "lie-poisson-8"])
def test_conservation_over_1e5_steps(name):
    inertia = STANDARD_I
    M = STANDARD_M0.copy()
    R = np.eye(3)
    m0 = R @ M
    casimir0 = float(M @ M)
    chunks, per_chunk = 100, 1000
    energy_error = np.empty(chunks)
    h0 = energy(M, inertia)
    for k in range(chunks):
        advance_scheme(name, M, R, inertia, 0.01, per_chunk)
        energy_error[k] = abs(energy(M, inertia) - h0)
    assert abs(float(M @ M) - casimir0) <= 1e-12
    assert np.max(np.abs(R.T @ R - np.eye(3))) <= 1e-12
    assert np.max(np.abs(R @ M - m0)) <= 1e-12
    first, last = energy_error[:10].max(), energy_error[-10:].max()
    assert last <= 2.0 * first + 1e-14  # bounded, no secular drift


@pytest.mark.parametrize("name", sorted(SCHEMES))
def test_principal_axis_rotation_165_exact_for_every_method(name):
    inertia = np.array([1.7, 1.1, 0.6])
    M_cf, R_cf = principal_axis_rotation(inertia, -0.8, [7.0])
    M, R = _run(name, inertia, [0.0, 0.0, -0.8], np.eye(3), 0.7, 10)
    np.testing.assert_allclose(M, M_cf[0], atol=1e-15)
    np.testing.assert_allclose(R, R_cf[0], atol=1e-13)


# 3-term split: the symmetric top is not solved exactly; steps to reach 1e-9 at t = 5
_TOP_STEPS = {2: 100000, 4: 1000, 6: 200, 8: 100}


@pytest.mark.parametrize("name", sorted(SCHEMES))
def test_symmetric_top_183_for_every_method(name):
    inertia = np.array([1.3, 1.3, 0.7])
    m2, m3 = 0.6, -0.9
    M_cf, R_cf = symmetric_top(inertia, m2, m3, [5.0])
    scheme = SCHEMES[name]
    if scheme.splitting == "symmetric":
        # I1 = I2: the Casimir split about axis 2 leaves only the (exact) axis-3 term, so
        # even a coarse step reproduces (183) to round-off.
        n, tol = 4, 1e-13
    else:
        n, tol = _TOP_STEPS[scheme.order], 1e-9
    M, R = _run(name, inertia, [0.0, m2, m3], np.eye(3), 5.0 / n, n)
    np.testing.assert_allclose(M, M_cf[0], atol=tol)
    np.testing.assert_allclose(R, R_cf[0], atol=tol)


@pytest.mark.parametrize("name", ["lie-poisson-2", "lie-poisson-sym-4", "lie-poisson-6"])
def test_merged_steps_equal_single_steps_and_time_reversal(name):
    inertia = np.array([0.9, 1.4, 2.3])
    M0 = np.array([0.3, -0.8, 0.5])
    c, s = np.cos(0.4), np.sin(0.4)
    R0 = np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    M_all, R_all = _run(name, inertia, M0, R0, 0.1, 25)
    M, R = M0.copy(), R0.copy()
    for _ in range(25):
        advance_scheme(name, M, R, inertia, 0.1, 1)
    np.testing.assert_allclose(M, M_all, atol=1e-14)
    np.testing.assert_allclose(R, R_all, atol=1e-14)
    advance_scheme(name, M, R, inertia, -0.1, 25)  # symmetric methods: exact reversal
    np.testing.assert_allclose(M, M0, atol=1e-14)
    np.testing.assert_allclose(R, R0, atol=1e-14)


@pytest.mark.parametrize("name", ["lie-poisson-4", "lie-poisson-sym-4"])
def test_without_R_the_attitude_is_never_touched(name):
    R_nan = np.full((3, 3), np.nan)
    M_only, R_after = _run(name, STANDARD_I, STANDARD_M0, R_nan, 0.05, 100, with_R=False)
    M_full, _ = _run(name, STANDARD_I, STANDARD_M0, np.eye(3), 0.05, 100, with_R=True)
    assert np.all(np.isnan(R_after))
    np.testing.assert_array_equal(M_only, M_full)


def test_bad_names_raise_input_error():
    M, R = STANDARD_M0.copy(), np.eye(3)
    with pytest.raises(InputError, match="lie-poisson-3.*choose one of"):
        advance_scheme("lie-poisson-3", M, R, STANDARD_I, 0.1, 1)
    with pytest.raises(InputError, match="splitting = 'diagonal'"):
        advance(M, R, 1.0 / STANDARD_I, 0.1, 1, (1.0,), True, "diagonal")
