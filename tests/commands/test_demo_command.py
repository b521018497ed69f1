"""``dirac demo``: the flagship scene (a real box that tumbles, docs/cli.md) with a summary."""

from __future__ import annotations

import json
import re

import numpy as np


def _value(stdout: str, label: str) -> float:
    match = re.search(rf"{re.escape(label)}\s+([0-9.e+-]+)", stdout)
    assert match, (label, stdout)
    return float(match.group(1))


def _period_landau(inertia: tuple[float, float, float], M0: tuple[float, float, float]) -> float:
    """Period of M(t) of the free asymmetric body, by hand (Landau & Lifshitz, Mechanics, section 37).

    With A < B < C the moments, M^2 = |M|^2 and 2E = sum M_i^2 / I_i: for M^2 > 2 E B,
    T = 4 K(k) sqrt(A B C / ((C - B)(M^2 - 2 E A))), k^2 = (B - A)(2 E C - M^2) / ((C - B)(M^2 - 2 E A));
    for M^2 < 2 E B, A and C trade places.
    """
    from scipy.special import ellipk

    A, B, C = sorted(inertia)
    square = sum(m * m for m in M0)
    two_e = sum(m * m / i for m, i in zip(M0, inertia))
    if square < two_e * B:
        A, C = C, A
    k2 = (B - A) * (two_e * C - square) / ((C - B) * (square - two_e * A))
    return float(4.0 * ellipk(k2) * np.sqrt(A * B * C / ((C - B) * (square - two_e * A))))


def test_demo_runs_a_real_tumbling_box_without_warnings(run_cli):
    status, stdout, stderr = run_cli("demo", "--no-progress")
    assert status == 0
    assert "warning" not in stderr, stderr  # a real body: the flagship does not warn about itself
    assert "a homogeneous box, edges 1 x 2 x 3, mass 12" in stdout
    # box of mass m = 12 with edges (a, b, c) = (1, 2, 3): I_1 = m (b^2 + c^2) / 12 etc.
    assert "I = (13, 10, 5)" in stdout
    inertia = (13.0, 10.0, 5.0)
    for k in range(3):  # the triangle inequality I_i + I_j >= I_k of a physical body
        assert sum(inertia) - inertia[k] >= inertia[k]
    assert "M(0) = (0.1, 1, 0.1)" in stdout
    # H_0 = 0.1^2 / 26 + 1 / 20 + 0.1^2 / 10 = 167 / 3250 by hand
    assert f"H_0 = {167 / 3250:.15g})" in stdout
    period = _period_landau(inertia, (0.1, 1.0, 0.1))
    assert abs(period - 245.748) < 1e-3
    assert f"M(t) has period {period:.6g}" in stdout
    assert "method         exact flow (Jacobi elliptic functions; no time steps)" in stdout
    assert "order 0" not in stdout
    assert "t = 0 .. 1000" in stdout
    for label in ("energy H_0", "Casimir |M|^2", "lab momentum m = R M", "|R^T R - 1|"):
        assert _value(stdout, label) < 1e-12
    assert re.search(r"CPU time\s+[0-9.e+-]+ s", stdout)


def test_demo_body_flips_twice_per_period(run_cli, tmp_path):
    out = tmp_path / "demo.npz"
    status, _, _ = run_cli("demo", "--no-progress", "--out", str(out))
    assert status == 0
    with np.load(out) as data:
        M = data["M"]
    # M_2 starts at +1 and changes sign twice per period: 1000 / 245.748 = 4.07 periods, 8 flips
    assert abs(M[0, 1] - 1.0) < 1e-14
    assert int(np.sum(np.diff(np.sign(M[:, 1])) != 0)) == 8
    assert M[:, 1].min() < -0.95 and M[:, 1].max() > 0.95  # it turns right over


def test_demo_bad_method_gives_the_error_alone(run_cli):
    status, stdout, stderr = run_cli("demo", "--method", "lie-poison-4")
    assert status == 2 and stdout == ""
    assert stderr.startswith("error: --method: unknown method 'lie-poison-4'"), stderr
    assert "warning" not in stderr


def test_demo_with_a_splitting_method_and_output_file(run_cli, tmp_path):
    out = tmp_path / "demo.npz"
    status, stdout, _ = run_cli("demo", "--method", "lie-poisson-6", "--t-end", "50", "--dt", "0.05",
                                "--out", str(out), "--no-progress")
    assert status == 0
    assert "lie-poisson-6 (order 6), dt = 0.05" in stdout
    assert "steps          1000" in stdout
    assert _value(stdout, "Casimir |M|^2") < 1e-12
    assert _value(stdout, "energy H_0") < 1e-6
    with np.load(out) as data:
        meta = json.loads(str(data["meta"]))
        M = data["M"]
        t = data["t"]
    assert meta["method"] == "lie-poisson-6" and meta["complete"] is True
    # M(50) against Euler's equations dM/dt = M x Omega, Omega_i = M_i / I_i, written out
    # here and solved by scipy at a tight tolerance
    from scipy.integrate import solve_ivp

    inertia = np.array([13.0, 10.0, 5.0])
    reference = solve_ivp(lambda _, m: np.cross(m, m / inertia), (0.0, 50.0), [0.1, 1.0, 0.1],
                          method="DOP853", rtol=1e-13, atol=1e-15).y[:, -1]
    assert t[-1] == 50.0
    assert np.abs(M[-1] - reference).max() < 1e-7
