"""Regression tests of weaknesses the stress tests found (robustness findings F1-F15).

Kernels: F5 an ``M`` whose ``|M|^2`` overflows crashed ``exact`` (now an input error); F6 tiny
moments of inertia printed raw numpy overflow warnings; F7 a slowly turning body (``|M|``
below ~1e-154) crashed ``exact``; F14 booleans were taken as numbers; F15 components whose
squares underflow gave NaN or ZeroDivisionError. Flows and ``dirac run``: F1 an absurd number
of samples and F2 a step count beyond 2^62 gave MemoryError/OverflowError tracebacks; F4
``--out`` naming a directory crashed after the whole run; F10 ``auto`` crashed on a long
constrained run; F3 a singular Newton matrix in RATTLE divided by zero; F12 the guard-rail options of ``integrate`` were not validated. Bad input
gives an ``InputError`` (one ``error:`` line, exit status 2); legal input gives the correct
result, checked by the homogeneity of the Euler-Poisson equations (250)-(251).
"""

from __future__ import annotations

import numpy as np
import pytest
from cli_output import one_error_line

RIGID = """
[system]
name = "rigid_body"
inertia = {inertia}
[initial]
M = {M}
[run]
t_end = {t_end}
{extra}
"""


def _scene(tmp_path, **fields) -> str:
    values = {"inertia": "[1.0, 2.0, 3.0]", "M": "[1.0, 0.2, 0.1]", "t_end": "1.0", "extra": ""} | fields
    path = tmp_path / "scene.toml"
    path.write_text(RIGID.format(**values))
    return str(path)


def test_f5_momentum_whose_square_overflows_is_an_input_error():
    from dirac.errors import InputError
    from dirac.flows.problems import RigidBodyProblem

    with pytest.raises(InputError):
        RigidBodyProblem([1.0, 2.0, 3.0], [1e308, 1e308, 0.0])


def test_f6_tiny_inertia_gives_only_dirac_lines_on_stderr(tmp_path, run_cli):
    scene = _scene(tmp_path, inertia="[1e-300, 1.0, 1.0]", M="[1.0, 1.0, 1.0]", extra='method = "exact"')
    status, _, err = run_cli("run", scene, "--out", str(tmp_path / "o.npz"), "--no-progress")
    lines = [line for line in err.splitlines() if line.strip()]
    assert status in (0, 2) and all(line.startswith(("error:", "warning:")) for line in lines), err


def test_f6_tiny_moments_give_the_time_scaled_flow():
    """``I -> c I`` slows the motion by ``c``: ``M(t; c I) = M(t / c; I)``, same for ``R``."""
    from dirac.rigidbody.exact import ExactRigidBodyFlow

    M0 = [0.6, 0.48, 0.64]
    tiny = ExactRigidBodyFlow([1e-300, 2e-300, 3e-300], M0)
    unit = ExactRigidBodyFlow([1.0, 2.0, 3.0], M0)
    times = np.array([0.0, 0.7, 5.0])
    M_tiny, R_tiny = tiny.state(times * 1e-300)
    M_unit, R_unit = unit.state(times)
    assert np.allclose(M_tiny, M_unit, rtol=0, atol=1e-14)
    assert np.allclose(R_tiny, R_unit, rtol=0, atol=1e-14)


def test_f6_moments_whose_reciprocal_overflows_are_an_input_error():
    from dirac.errors import InputError
    from dirac.flows.problems import RigidBodyProblem

    with pytest.raises(InputError, match="overflows"):
        RigidBodyProblem([1e-310, 1.0, 1.0], [1.0, 0.0, 0.0])


@pytest.mark.parametrize("M", [[1e-170, 1e-170, 0.0], [8.8e-290, 1.9e-171, -2.4e-295], [3e-200, 4e-200, 5e-200]])
def test_f7_exact_flow_of_a_slowly_turning_body_is_the_scaled_flow(M):
    """Homogeneity of (250)-(251): M(t; s M0) = s M(s t; M0) and R(t; s M0) = R(s t; M0)."""
    from dirac.rigidbody.exact import ExactRigidBodyFlow

    M = np.array(M)
    largest = float(np.max(np.abs(M)))
    scale = largest * float(np.linalg.norm(M / largest))  # |M| without underflow
    unit = ExactRigidBodyFlow([1.0, 2.0, 3.0], M / scale)
    tiny = ExactRigidBodyFlow([1.0, 2.0, 3.0], M)
    times = np.array([0.0, 1.0, 2.0]) / scale
    M_tiny, R_tiny = tiny.state(times)
    M_unit, R_unit = unit.state(times * scale)
    assert np.allclose(M_tiny / scale, M_unit, rtol=0, atol=1e-14)
    assert np.allclose(R_tiny, R_unit, rtol=0, atol=1e-14)



@pytest.mark.parametrize(("inertia", "M"), [([True, 2.0, 3.0], [1.0, 0.0, 0.0]), ([1.0, 2.0, 3.0], [False, 0.2, 0.1]),
                                            (np.array([1.0, 2.0, 3.0]), np.array([True, False, True]))])
def test_f14_booleans_are_not_numbers_for_the_rigid_body_kernels(inertia, M):
    """``True`` would silently become 1.0 (hypothesis ran a scene with ``M = [false, 0.2, 0.1]``)."""
    from dirac.errors import InputError
    from dirac.rigidbody.exact import ExactRigidBodyFlow

    with pytest.raises(InputError, match="true/false"):
        ExactRigidBodyFlow(inertia, M)



@pytest.mark.parametrize("M", [[0.0, 1.0, 2.225073858507e-311], [1.0, 0.0, 1e-200], [0.0, 1.0, -1e-170]])
def test_f15_symmetric_body_with_an_underflowing_component_is_a_slow_precession(M):
    """``I = (1, 1, 2)``: ``M_3`` is constant and ``(M_1, M_2)`` turns about axis 3 at the rate
    ``(1/I_3 - 1/I_1) M_3`` (Euler's equations (250) with ``I_1 = I_2``); for ``M_3 ~ 1e-311``
    that is no visible motion. Hypothesis found ``exact`` dividing by ``a_2 - a_3 = 0`` here."""
    from dirac.rigidbody.exact import ExactRigidBodyFlow

    flow = ExactRigidBodyFlow([1.0, 1.0, 2.0], M)
    times = np.array([0.0, 1.0, 10.0])
    M_t, R_t = flow.state(times)
    rate = (0.5 - 1.0) * M[2]
    angle = rate * times
    expected = np.stack([M[0] * np.cos(angle) + M[1] * np.sin(angle),
                         -M[0] * np.sin(angle) + M[1] * np.cos(angle), np.full(3, M[2])], axis=1)
    assert np.allclose(M_t, expected, rtol=0, atol=1e-15)
    assert np.all(np.isfinite(R_t))
    for R in R_t:
        assert np.allclose(R.T @ R, np.eye(3), atol=1e-14)
    assert np.allclose(np.einsum("tij,tj->ti", R_t, M_t), np.asarray(M, dtype=float)[None], atol=1e-14)



@pytest.mark.parametrize(("inertia", "M"), [((2.0, 1.0, 3.0), (0.0, 1.0, 1.5e-170)), ((1.0, 2.0, 1.0), (0.0, 1.0, 1.5e-170)),
                                            ((3.0, 2.0, 1.0), (1e-200, 1e-190, 1.0))])
def test_f15_momentum_within_1e_170_of_an_axis_is_finite_and_keeps_the_invariants(inertia, M):
    """Found by hypothesis: amplitudes sqrt(M_i^2 ...) and the frame norm underflowed (NaN,
    ZeroDivisionError). The motion stays within ~1e-170 of the axis: M(t) = M(0) and R(t) is
    the rotation about that axis, |M| and m = R M conserved."""
    from dirac.rigidbody.exact import ExactRigidBodyFlow

    times = np.array([0.0, 0.3, 7.0])
    M_t, R_t = ExactRigidBodyFlow(inertia, M).state(times)
    assert np.all(np.isfinite(M_t)) and np.all(np.isfinite(R_t))
    assert np.allclose(M_t, np.asarray(M)[None], rtol=0, atol=1e-15)
    for R in R_t:
        assert np.allclose(R.T @ R, np.eye(3), atol=1e-14)
    assert np.allclose(np.einsum("tij,tj->ti", R_t, M_t), np.asarray(M)[None], atol=1e-14)


def test_f1_absurd_number_of_samples_is_an_input_error(tmp_path, run_cli):
    scene = _scene(tmp_path, extra="samples = 100000000000000")
    status, _, err = run_cli("run", scene, "--out", str(tmp_path / "o.npz"), "--no-progress")
    assert "samples" in one_error_line(status, err)


def test_f2_step_count_overflow_is_an_input_error(tmp_path, run_cli):
    scene = _scene(tmp_path, t_end="1e300", extra='method = "lie-poisson-2"\ndt = 1e-300\nsamples = 2')
    status, _, err = run_cli("run", scene, "--out", str(tmp_path / "o.npz"), "--no-progress")
    one_error_line(status, err)


def test_f4_out_naming_a_directory_is_an_input_error(tmp_path, run_cli):
    (tmp_path / "d.npz").mkdir()
    status, _, err = run_cli("run", _scene(tmp_path), "--out", str(tmp_path / "d.npz"), "--no-progress")
    assert "d.npz" in one_error_line(status, err)


def test_f10_auto_on_a_long_constrained_run_chooses_a_working_step(tmp_path, run_cli):
    path = tmp_path / "scene.toml"
    path.write_text('[system]\nname = "pendulum"\n[initial]\nq = { x = 1.0, y = 0.0 }\n'
                    '[run]\nt_end = 1000.0\nmethod = "auto"\ntolerance = 1e-2\nsamples = 11\n')
    status, _, err = run_cli("run", str(path), "--out", str(tmp_path / "o.npz"), "--no-progress")
    assert status == 0, err


@pytest.mark.parametrize("options", [{"drift_limit": float("nan")}, {"drift_limit": -1.0},
                                     {"newton_tolerance": -1.0}, {"newton_tolerance": float("nan")},
                                     {"max_newton_iterations": 0}, {"max_newton_iterations": 10**30}])
def test_f12_integrate_validates_its_guard_rail_options(options):
    from dirac.errors import InputError
    from dirac.flows.integration import integrate
    from dirac.flows.problems import RigidBodyProblem

    problem = RigidBodyProblem([1.0, 2.0, 3.0], [1.0, 0.2, 0.1])
    with pytest.raises(InputError):
        integrate(problem, "midpoint", t_end=1.0, dt=0.1, samples=3, **options)


@pytest.mark.parametrize("M", [[False, 0.2, 0.1], np.array([True, False, True])])
def test_f14_booleans_are_not_numbers_in_rigid_body_problem(M):
    from dirac.errors import InputError
    from dirac.flows.problems import RigidBodyProblem

    with pytest.raises(InputError):
        RigidBodyProblem([1.0, 2.0, 3.0], M)


def test_f14_booleans_are_not_numbers_in_scenes(tmp_path, run_cli):
    path = _scene(tmp_path, M="[false, 0.2, 0.1]", extra='method = "exact"')
    status, _, err = run_cli("run", path, "--out", str(tmp_path / "o.npz"), "--no-progress")
    one_error_line(status, err)


def test_f3_singular_constraint_jacobian_is_reported_not_a_traceback(tmp_path, run_cli):
    path = tmp_path / "scene.toml"
    path.write_text('[system]\nname = "pendulum"\nparameters = { l = 0.0 }\n[initial]\nq = { x = 0.0, y = 0.0 }\n'
                    '[run]\nt_end = 1.0\nmethod = "rattle-2"\ndt = 0.01\n')
    status, _, err = run_cli("run", str(path), "--out", str(tmp_path / "o.npz"), "--no-progress")
    one_error_line(status, err)
