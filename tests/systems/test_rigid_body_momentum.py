"""The rigid body through its body angular momentum, Lagrangian (228) with (227):
factory, the degenerate Hessian, the primary constraints P_ij (230), the canonical
Hamiltonian (232) and the engine's chain of Sect. XI. Expected formulas are written out
by hand from the paper."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import sympy
from rigid_body_analyses import cached_analysis, eps, hat

import dirac
from dirac.analysis.legendre.transform import legendre_transform
from dirac.codegen.scalar_backend import scalar_function
from dirac.errors import DiracWarning, InputError
from dirac_systems import rigid_body_momentum

I = [sympy.Symbol(f"I_{k}", positive=True) for k in (1, 2, 3)]
R = sympy.Matrix(3, 3, lambda i, j: sympy.Symbol(f"R_{i + 1}{j + 1}", real=True))
R_DOT = sympy.Matrix(3, 3, lambda i, j: sympy.Symbol(f"R_{i + 1}{j + 1}_dot", real=True))


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


PAIRS = ((1, 1), (1, 2), (1, 3), (2, 2), (2, 3), (3, 3))
INERTIA = np.array([2.0, 3.0, 4.0])


def hand_point(R_: np.ndarray, M_: np.ndarray, inertia: np.ndarray) -> dict[str, float]:
    """Surface point of Sect. XI written by hand: p = -1/2 R eps.M (229) (so P = 0),
    pi = 0, and the multipliers from P_dot = 0 with v = 0 (fixed by d(R^T R)/dt = 0):
    lambda_ab = (M.Omega) delta_ab - (Omega_a M_b + Omega_b M_a)/2, Omega = I^{-1} M."""
    omega = M_ / inertia
    p = 0.5 * R_ @ hat(M_)
    lam = (M_ @ omega) * np.eye(3) - (np.outer(omega, M_) + np.outer(M_, omega)) / 2
    point = {f"R_{i + 1}{j + 1}": R_[i, j] for i in range(3) for j in range(3)}
    point |= {f"p_R_{i + 1}{j + 1}": p[i, j] for i in range(3) for j in range(3)}
    for k, (i, j) in enumerate(PAIRS, start=1):
        point[f"lambda_{k}"] = lam[i - 1, j - 1]
        point[f"p_lambda_{k}"] = 0.0
    return point | {f"I_{k + 1}": inertia[k] for k in range(3)}


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return q * np.linalg.det(q)


def test_canonical_hamiltonian_is_232_off_the_orthogonality_surface():
    """On the primary surface (any invertible R, p = R X with X antisymmetric, so that
    sym(R^{-1} p) = 0) the engine's H_c equals (232): 1/2 I^{-1} M M with M = -eps (R^{-1} p)
    (233), and it stays finite at R = 1 (no minor of R in a denominator)."""
    L = dirac.load_system("rigid_body_momentum")
    legendre = legendre_transform(L, np.random.default_rng(0), {s: v for s, v in zip(I, INERTIA)})
    H = sympy.lambdify([*legendre.phase_space.variables, *I], legendre.canonical_hamiltonian, "numpy")
    primary = sympy.lambdify([*legendre.phase_space.variables, *I], legendre.primary, "numpy")
    rng = np.random.default_rng(4)
    for k in range(6):
        R_ = np.eye(3) if k == 0 else rng.normal(size=(3, 3))
        X = rng.normal(size=(3, 3))
        p_ = R_ @ (X - X.T)
        Q = np.linalg.inv(R_) @ p_
        M_ = np.array([-sum(eps(a, i, j) * Q[i - 1, j - 1] for i in (1, 2, 3) for j in (1, 2, 3)) for a in (1, 2, 3)])
        lam = rng.normal(size=6)
        z = [*R_.ravel(), *lam, *p_.ravel(), *np.zeros(6)]
        T = R_.T @ R_ - np.eye(3)
        constraint_term = sum(l * T[i - 1, j - 1] * (0.5 if i == j else 1.0) for l, (i, j) in zip(lam, PAIRS))
        assert H(*z, *INERTIA) == pytest.approx(0.5 * np.sum(M_**2 / INERTIA) + constraint_term, rel=1e-10)
        assert np.max(np.abs(primary(*z, *INERTIA))) < 1e-10


@pytest.mark.slow
def test_engine_chain_of_section_XI(request):
    """12 primary (6 pi + 6 spanning P (230)), R^T R - 1 at stage 2, then the six
    conditions P_dot = 0 that fix lambda: 24 second class, 30-dim, 3 degrees of freedom."""
    analysis = cached_analysis(request.config, "rigid_body_momentum")
    s = analysis.symbols
    assert len(analysis.phase_space) == 30
    assert [len(stage) for stage in analysis.stages] == [12, 6, 6]
    assert len(analysis.second_class) == 24 and not analysis.first_class
    assert analysis.physical_degrees_of_freedom == 3
    primary = [sympy.sympify(c) for c in analysis.stages[0]]
    assert {s[f"p_lambda_{k}"] for k in range(1, 7)} <= set(primary)
    p = sympy.Matrix(3, 3, lambda i, j: s[f"p_R_{i + 1}{j + 1}"])
    Radj = R.adjugate()
    P = Radj * p + p.T * Radj.T  # det(R) sym(R^{-1} p): (230) without the denominator
    T = R.T * R - sympy.eye(3)
    hand_P = [P[i - 1, j - 1] for i, j in PAIRS]
    hand_T = [T[i - 1, j - 1] for i, j in PAIRS]
    args = [*analysis.phase_space, *I]
    variables = list(analysis.phase_space)

    def gradients(exprs):
        return sympy.lambdify(args, sympy.Matrix(exprs).jacobian(variables), "numpy")

    g_primary, g_P = gradients(primary), gradients(hand_P)
    g_stage2, g_T = gradients(list(analysis.stages[1])), gradients(hand_T)
    values = sympy.lambdify(args, list(analysis.constraints), "numpy")
    rng = np.random.default_rng(2)
    for _ in range(5):
        point = hand_point(random_rotation(rng), rng.normal(size=3), INERTIA * rng.uniform(0.5, 1.5))
        x = [point[a.name] for a in args]
        # every constraint vanishes at the hand-built point: in particular the multipliers
        # lambda written by hand satisfy the engine's stage-3 constraints
        assert np.max(np.abs(values(*x))) < 1e-10
        A, B = np.array(g_primary(*x), dtype=float), np.array(g_P(*x), dtype=float)
        assert np.linalg.matrix_rank(np.vstack([A, B]), tol=1e-9) == 12  # same span as pi, P
        C, D = np.array(g_stage2(*x), dtype=float), np.array(g_T(*x), dtype=float)
        assert np.linalg.matrix_rank(np.vstack([C, D]), tol=1e-9) == 6  # stage 2 spans R^T R - 1
    # the hand lambda is the only solution: perturbing one multiplier breaks a constraint
    point = hand_point(random_rotation(rng), rng.normal(size=3), INERTIA)
    for k in range(1, 7):
        moved = dict(point, **{f"lambda_{k}": point[f"lambda_{k}"] + 1e-3})
        assert np.max(np.abs(values(*[moved[a.name] for a in args]))) > 1e-6


@pytest.mark.slow
def test_dirac_vector_field_is_euler_poisson_on_the_surface(request):
    """{M_k, H_c}_D = (M x Omega)_k and {R_ij, H_c}_D = (R hat(Omega))_ij at hand-built
    surface points, with M_k = -eps_kij (R^T p)_ij (233): (250)-(251)."""
    analysis = cached_analysis(request.config, "rigid_body_momentum")
    s = analysis.symbols
    p = sympy.Matrix(3, 3, lambda i, j: s[f"p_R_{i + 1}{j + 1}"])
    Q = R.T * p
    M = [-sum(eps(k, i, j) * Q[i - 1, j - 1] for i in (1, 2, 3) for j in (1, 2, 3)) for k in (1, 2, 3)]
    H = analysis.canonical_hamiltonian
    rng = np.random.default_rng(11)
    for _ in range(3):
        R_, M_ = random_rotation(rng), rng.normal(size=3)
        point = hand_point(R_, M_, INERTIA)
        omega = M_ / INERTIA
        for k in range(3):
            assert analysis.dirac_bracket(M[k], H, at=point) == pytest.approx(np.cross(M_, omega)[k], abs=1e-9)
        Rdot = R_ @ hat(omega)
        for i, j in ((1, 1), (2, 3), (3, 1)):
            value = analysis.dirac_bracket(s[f"R_{i}{j}"], H, at=point)
            assert value == pytest.approx(Rdot[i - 1, j - 1], abs=1e-9)


@pytest.mark.slow
def test_multipliers_are_the_rates_of_lambda_on_the_surface(request):
    """The particular multipliers U of H_T at hand-built surface points: the velocities
    v of P vanish (fixed by d(R^T R)/dt = 0), and the multiplier of pi_ab = p_lambda_ab is
    lambda_ab_dot, from lambda_ab = (M.Omega) delta_ab - (Omega_a M_b + Omega_b M_a)/2
    with Euler's M_dot = M x Omega (250) and Omega = I^{-1} M, so that (M.Omega)_dot = 0.
    Every U_k must be finite there: an exact solve whose pivot vanishes on the surface
    gives 0/0 at these points."""
    analysis = cached_analysis(request.config, "rigid_body_momentum")
    solution = analysis.multiplier_solution
    primary = [sympy.sympify(c) for c in analysis.stages[0]]
    s = analysis.symbols
    rate_of = {}  # multiplier name -> lambda index whose rate it is, for the primary p_lambda_k
    for u, phi in zip(solution.multipliers, solution.primary):
        assert phi in primary
        rate_of[u.name] = next((k for k in range(1, 7) if phi == s[f"p_lambda_{k}"]), None)
    assert sorted(k for k in rate_of.values() if k is not None) == list(range(1, 7))
    args = [*analysis.phase_space, *I]
    # the engine's compiler of analysis expressions (shared sub-trees once; lambdify prints these trees whole)
    U = scalar_function(args, [solution.particular[name] for name in rate_of])
    rng = np.random.default_rng(5)
    for _ in range(3):
        R_, M_ = random_rotation(rng), rng.normal(size=3)
        inertia = INERTIA * rng.uniform(0.5, 1.5)
        point = hand_point(R_, M_, inertia)
        omega = M_ / inertia
        M_dot = np.cross(M_, omega)
        omega_dot = M_dot / inertia
        lam_dot = -(np.outer(omega_dot, M_) + np.outer(omega, M_dot) + np.outer(M_, omega_dot) + np.outer(M_dot, omega)) / 2
        values = np.array(U(*[point[a.name] for a in args]), dtype=float)
        assert np.all(np.isfinite(values))
        for value, k in zip(values, rate_of.values()):
            expected = 0.0 if k is None else lam_dot[PAIRS[k - 1][0] - 1, PAIRS[k - 1][1] - 1]
            assert value == pytest.approx(expected, abs=1e-8 * (1 + np.max(np.abs(lam_dot))))
