"""Sect. XI: the Chetaev bracket is the Dirac bracket.

The engine's Dirac bracket of ``M_k = -eps_kij (R^T p)_ij`` (233) and ``R_ij``, on the
constraint surface of the rotation-matrix Lagrangian (78), is compared with (248)–(249)
written out by hand, at 100 random points of the surface (random rotation, angular
velocity and admissible inertia), and ``H_0 = 1/2 I^{-1}_ij M_i M_j`` (247) is shown to
generate the Euler–Poisson equations (250)–(251).
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy
from rigid_body_analyses import cached_analysis, eps, hat

PAIRS = ((1, 1), (1, 2), (1, 3), (2, 2), (2, 3), (3, 3))
POINTS = 100


@pytest.fixture(scope="module")
def analysis(request):
    return cached_analysis(request.config, "rigid_body_matrix")


def surface_points(count: int, seed: int):
    """Hand-built points of the surface (217): random R in SO(3), random Omega, random
    g > 0 (so I_1 = g_2 + g_3 etc. (72) is admissible), p = R hat(Omega) g (205),
    lambda from (221), pi = 0."""
    rng = np.random.default_rng(seed)
    result = []
    for _ in range(count):
        q, r = np.linalg.qr(rng.normal(size=(3, 3)))
        R = q @ np.diag(np.sign(np.diag(r)))
        R *= np.linalg.det(R)
        omega = rng.normal(size=3)
        g = rng.uniform(0.3, 2.0, size=3)
        inertia = np.array([g[1] + g[2], g[0] + g[2], g[0] + g[1]])
        p = R @ hat(omega) @ np.diag(g)
        point = {f"R_{i + 1}{j + 1}": R[i, j] for i in range(3) for j in range(3)}
        point |= {f"p_R_{i + 1}{j + 1}": p[i, j] for i in range(3) for j in range(3)}
        for k, (i, j) in enumerate(PAIRS, start=1):
            i0, j0 = i - 1, j - 1
            point[f"lambda_{k}"] = 2 * g[i0] * g[j0] / (g[i0] + g[j0]) * ((omega @ omega) * (i == j) - omega[i0] * omega[j0])
            point[f"p_lambda_{k}"] = 0.0
        point |= {f"I_{k + 1}": inertia[k] for k in range(3)}
        result.append((point, R, inertia * omega, inertia))
    return result


def body_momentum(analysis) -> list[sympy.Expr]:
    s = analysis.symbols
    R = sympy.Matrix(3, 3, lambda i, j: s[f"R_{i + 1}{j + 1}"])
    p = sympy.Matrix(3, 3, lambda i, j: s[f"p_R_{i + 1}{j + 1}"])
    Q = R.T * p
    return [-sum(eps(k, i, j) * Q[i, j] for i in range(3) for j in range(3)) for k in range(3)]  # (233)


def test_points_are_on_the_engines_constraint_surface(analysis):
    constraints = sympy.lambdify(
        [*analysis.phase_space, *analysis.parameters], list(analysis.constraints), "numpy"
    )
    names = [s.name for s in [*analysis.phase_space, *analysis.parameters]]
    for point, *_ in surface_points(10, seed=11):
        assert np.max(np.abs(constraints(*[point[n] for n in names]))) < 1e-10


def test_dirac_bracket_of_M_and_R_is_chetaev_248_249_at_100_points(analysis):
    s = analysis.symbols
    M = body_momentum(analysis)
    R = [[s[f"R_{i + 1}{j + 1}"] for j in range(3)] for i in range(3)]
    M_at = sympy.lambdify(list(analysis.phase_space), M, "numpy")
    worst = 0.0
    for point, R_, M_, _ in surface_points(POINTS, seed=12):
        # on the surface of (78), (233) is the body angular momentum I Omega (227)
        np.testing.assert_allclose(M_at(*[point[z.name] for z in analysis.phase_space]), M_, atol=1e-12)
        for i in range(3):
            for j in range(i + 1, 3):  # (248) {M_i, M_j}_D = -eps_ijk M_k
                expected = -sum(eps(i, j, k) * M_[k] for k in range(3))
                worst = max(worst, abs(analysis.dirac_bracket(M[i], M[j], at=point) - expected))
            for j in range(3):
                for k in range(3):  # (249) {M_i, R_jk}_D = -eps_ikm R_jm
                    expected = -sum(eps(i, k, m) * R_[j, m] for m in range(3))
                    worst = max(worst, abs(analysis.dirac_bracket(M[i], R[j][k], at=point) - expected))
        flat = [x for row in R for x in row]
        for a in range(9):
            for b in range(a + 1, 9):  # (248) {R_ij, R_ab}_D = 0
                worst = max(worst, abs(analysis.dirac_bracket(flat[a], flat[b], at=point)))
    assert worst < 1e-10


def test_dirac_bracket_of_M_is_chetaev_symbolically(analysis):
    """The engine's exact (weakly simplified) brackets of M_i with M_j and with R_jk,
    minus (248)-(249), vanish on the surface (checked at hand-built points)."""
    s = analysis.symbols
    M = body_momentum(analysis)
    differences = []
    for i in range(3):
        j = (i + 1) % 3
        k = (i + 2) % 3
        differences.append(analysis.dirac_bracket(M[i], M[j]) - (-eps(i, j, k) * M[k]))
        expected = -sum(eps(i, 2, m) * s[f"R_1{m + 1}"] for m in range(3))
        differences.append(analysis.dirac_bracket(M[i], s["R_13"]) - expected)
    args = [*analysis.phase_space, *analysis.parameters]
    f = sympy.lambdify(args, differences, "numpy")
    for point, *_ in surface_points(10, seed=13):
        assert np.max(np.abs(f(*[point[a.name] for a in args]))) < 1e-10


def test_H0_247_generates_the_euler_poisson_equations_250_251(analysis):
    M = body_momentum(analysis)
    I = analysis.parameters
    assert [p.name for p in I] == ["I_1", "I_2", "I_3"]
    H0 = sum(M[k] ** 2 / I[k] for k in range(3)) / 2  # (247), principal axes
    s = analysis.symbols
    R = [[s[f"R_{i + 1}{j + 1}"] for j in range(3)] for i in range(3)]
    for point, R_, M_, inertia in surface_points(20, seed=14):
        omega = M_ / inertia
        M_dot = [analysis.dirac_bracket(M[i], H0, at=point) for i in range(3)]
        np.testing.assert_allclose(M_dot, np.cross(M_, omega), atol=1e-10)  # (251)
        R_dot = [[analysis.dirac_bracket(R[i][j], H0, at=point) for j in range(3)] for i in range(3)]
        expected = [
            [-sum(eps(j, k, m) * omega[k] * R_[i, m] for k in range(3) for m in range(3)) for j in range(3)]
            for i in range(3)
        ]  # (250)
        np.testing.assert_allclose(R_dot, expected, atol=1e-10)
        np.testing.assert_allclose(R_dot, R_ @ hat(omega), atol=1e-10)  # R_dot = R hat(Omega), docs/conventions.md
