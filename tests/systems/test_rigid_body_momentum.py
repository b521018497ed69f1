"""The rigid body through its body angular momentum, Lagrangian (228) with (227):
factory, the degenerate Hessian, and the engine's chain of Sect. XI (primary constraints
P_ij (230)). Expected formulas are written out by hand from the paper."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import sympy

import dirac
from dirac.errors import DiracWarning, InputError
from dirac_systems import rigid_body_momentum

I = [sympy.Symbol(f"I_{k}", positive=True) for k in (1, 2, 3)]  # noqa: E741
R = sympy.Matrix(3, 3, lambda i, j: sympy.Symbol(f"R_{i + 1}{j + 1}", real=True))
R_DOT = sympy.Matrix(3, 3, lambda i, j: sympy.Symbol(f"R_{i + 1}{j + 1}_dot", real=True))
PAIRS = ((1, 1), (1, 2), (1, 3), (2, 2), (2, 3), (3, 3))


def eps(i: int, j: int, k: int) -> int:
    return int((i - j) * (j - k) * (k - i) / 2)


def hat(w: np.ndarray) -> np.ndarray:
    return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]], dtype=float)


def cached_analysis(config: pytest.Config, name: str):
    """One engine analysis per built-in system for the whole test session."""
    store = config.__dict__.setdefault("_dirac_rigid_body_analyses", {})
    if name not in store:
        store[name] = dirac.analyze(dirac.load_system(name))
    return store[name]


def test_lagrangian_is_228_with_M_of_227():
    L = rigid_body_momentum.system()
    A = R.T * R_DOT
    M = [-sum(I[k] * eps(k, n, m) * A[n, m] for n in range(3) for m in range(3)) / 2 for k in range(3)]  # (227)
    expected = sum(M[k] ** 2 / I[k] for k in range(3)) / 2  # (228), I = diag(I_1, I_2, I_3)
    assert sympy.expand(L.expression - expected) == 0
    assert [v.name for v in L.velocities] == [f"R_{i}{j}_dot" for i in (1, 2, 3) for j in (1, 2, 3)]
    lam = sympy.symbols("l11 l12 l13 l22 l23 l33")
    Lam = sympy.Matrix([[lam[0], lam[1], lam[2]], [lam[1], lam[3], lam[4]], [lam[2], lam[4], lam[5]]])
    engine_form = -sum(l * c for l, c in zip(lam, L.constraints))
    paper_form = -sum(Lam[i, j] * (R.T * R - sympy.eye(3))[i, j] for i in range(3) for j in range(3)) / 2
    assert sympy.expand(engine_form - paper_form) == 0


def test_hessian_has_rank_3_so_six_more_primary_constraints():
    """L depends on the nine velocities through the three Omega_k only (227)."""
    L = rigid_body_momentum.system().with_defaults()
    H = sympy.hessian(L.expression, list(R_DOT))
    rng = np.random.default_rng(0)
    for _ in range(3):
        values = dict(zip(R, rng.normal(size=9)))
        assert np.linalg.matrix_rank(np.array(H.subs(values), dtype=float), tol=1e-10) == 3


def test_momenta_229_satisfy_P_230():
    """p = dL/dR_dot obeys sym(R^{-1} p) = 0 identically (230) and M = -eps (R^{-1} p) (231)."""
    L = rigid_body_momentum.system()
    p = sympy.Matrix(3, 3, lambda i, j: sympy.diff(L.expression, R_DOT[i, j]))
    rng = np.random.default_rng(1)
    values = dict(zip([*R, *R_DOT, *I], [*rng.normal(size=18), 2.0, 3.0, 4.0]))
    R_, p_ = (np.array(X.subs(values), dtype=float) for X in (R, p))
    Q = np.linalg.inv(R_) @ p_
    np.testing.assert_allclose(Q + Q.T, 0.0, atol=1e-12)
    A = R_.T @ np.array(R_DOT.subs(values), dtype=float)
    M_lagrangian = [-0.5 * [2.0, 3.0, 4.0][k] * sum(eps(k, n, m) * A[n, m] for n in range(3) for m in range(3)) for k in range(3)]
    M_hamiltonian = [-sum(eps(k, i, j) * Q[i, j] for i in range(3) for j in range(3)) for k in range(3)]
    np.testing.assert_allclose(M_hamiltonian, M_lagrangian, atol=1e-12)


def test_inertia_validation():
    with pytest.raises(InputError, match="I_1"):
        dirac.load_system("rigid_body_momentum", I_1=0.0)
    with pytest.warns(DiracWarning, match="triangle inequality"):
        dirac.load_system("rigid_body_momentum", I_1=2.0, I_2=1.0, I_3=2.0 / 3.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert not dirac.load_system("rigid_body_momentum", I_1=2.0, I_2=3.0, I_3=4.0).parameters


def hand_point(R_: np.ndarray, M_: np.ndarray, inertia: np.ndarray) -> dict[str, float]:
    """Surface point of Sect. XI: p = -1/2 R eps.M (229) (so P = 0), pi = 0 and the
    multipliers from P_dot = 0 with v = 0: lambda_ab = (M.Omega) delta_ab -
    (Omega_a M_b + Omega_b M_a)/2 (derivation in dirac_systems.rigid_body_momentum)."""
    omega = M_ / inertia
    p = 0.5 * R_ @ hat(M_)
    lam = (M_ @ omega) * np.eye(3) - (np.outer(omega, M_) + np.outer(M_, omega)) / 2
    point = {f"R_{i + 1}{j + 1}": R_[i, j] for i in range(3) for j in range(3)}
    point |= {f"p_R_{i + 1}{j + 1}": p[i, j] for i in range(3) for j in range(3)}
    for k, (i, j) in enumerate(PAIRS, start=1):
        point[f"lambda_{k}"] = lam[i - 1, j - 1]
        point[f"p_lambda_{k}"] = 0.0
    return point | {f"I_{k + 1}": inertia[k] for k in range(3)}


@pytest.mark.slow
def test_engine_chain_of_section_XI(request):
    analysis = cached_analysis(request.config, "rigid_body_momentum")
    s = analysis.symbols
    assert len(analysis.phase_space) == 30
    assert len(analysis.constraints) == 24 and len(analysis.second_class) == 24 and not analysis.first_class
    assert analysis.physical_degrees_of_freedom == 3
    primary = [sympy.sympify(c) for c in analysis.stages[0]]
    assert len(primary) == 12
    assert {s[f"p_lambda_{k}"] for k in range(1, 7)} <= set(primary)
    # the six others span P_ij = [R^T p + (R^T p)^T]_ij (230) on the surface; T = R^T R - 1 at stage 2
    p = sympy.Matrix(3, 3, lambda i, j: s[f"p_R_{i + 1}{j + 1}"])
    P = R.T * p + p.T * R
    T = R.T * R - sympy.eye(3)
    hand_P = [P[i - 1, j - 1] for i, j in PAIRS]
    hand_T = [T[i - 1, j - 1] for i, j in PAIRS]
    args = [*analysis.phase_space, *I]
    grad = lambda exprs: sympy.lambdify(args, sympy.Matrix(exprs).jacobian(list(analysis.phase_space)), "numpy")  # noqa: E731
    g_primary, g_P = grad(primary), grad(hand_P)
    g_upto2, g_T = grad([c for st in analysis.stages[:2] for c in st]), grad(hand_T)
    values = sympy.lambdify(args, list(analysis.constraints), "numpy")
    rng = np.random.default_rng(2)
    for _ in range(5):
        q, r = np.linalg.qr(rng.normal(size=(3, 3)))
        R_ = q * np.linalg.det(q)
        point = hand_point(R_, rng.normal(size=3), np.array([2.0, 3.0, 4.0]) * rng.uniform(0.5, 1.5))
        x = [point[a.name] for a in args]
        assert np.max(np.abs(values(*x))) < 1e-10  # the hand-built point is on the surface
        A, B = np.array(g_primary(*x), dtype=float), np.array(g_P(*x), dtype=float)
        assert np.linalg.matrix_rank(np.vstack([A, B]), tol=1e-9) == 12
        C, D = np.array(g_upto2(*x), dtype=float), np.array(g_T(*x), dtype=float)
        assert np.linalg.matrix_rank(np.vstack([C, D]), tol=1e-9) == np.linalg.matrix_rank(C, tol=1e-9)
