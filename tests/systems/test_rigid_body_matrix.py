"""The rigid body through Lagrangian (78): factory, inertia check, and the engine's
Dirac–Bergmann chain (217), multipliers (221) and equations of motion (225)–(226).

Every expected formula is written out here by hand from the paper (Sect. X); the
engine's output is only evaluated, never used as a reference.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import sympy
from rigid_body_analyses import cached_analysis, eps, hat

import dirac
from dirac.errors import InputError
from dirac_systems import rigid_body_matrix

I1, I2, I3 = (sympy.Symbol(f"I_{k}", positive=True) for k in (1, 2, 3))
R = sympy.Matrix(3, 3, lambda i, j: sympy.Symbol(f"R_{i + 1}{j + 1}", real=True))
R_DOT = sympy.Matrix(3, 3, lambda i, j: sympy.Symbol(f"R_{i + 1}{j + 1}_dot", real=True))
PAIRS = ((1, 1), (1, 2), (1, 3), (2, 2), (2, 3), (3, 3))


@pytest.fixture(scope="module")
def analysis(request):
    return cached_analysis(request.config, "rigid_body_matrix")


# ------------------------------------------------------------------ hand formulas
def random_rotation(rng: np.random.Generator) -> np.ndarray:
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q @ np.diag(np.sign(np.diag(r)))
    return q if np.linalg.det(q) > 0 else -q


def random_admissible_inertia(rng: np.random.Generator) -> np.ndarray:
    """I_1 = g_2 + g_3 etc. (72) with random positive g: the triangle inequality holds."""
    g = rng.uniform(0.3, 2.0, size=3)
    return np.array([g[1] + g[2], g[0] + g[2], g[0] + g[1]])


def hand_point(R_: np.ndarray, omega: np.ndarray, inertia: np.ndarray) -> dict[str, float]:
    """Surface point of (217): p = R_dot g (205), R_dot = R hat(Omega) (225), lambda (221)."""
    i1, i2, i3 = inertia
    g = np.array([(i2 + i3 - i1) / 2, (i1 + i3 - i2) / 2, (i1 + i2 - i3) / 2])  # (72)
    p = R_ @ hat(omega) @ np.diag(g)
    lam = np.empty((3, 3))
    for i in range(3):
        for j in range(3):  # (221)
            lam[i, j] = 2 * g[i] * g[j] / (g[i] + g[j]) * ((omega @ omega) * (i == j) - omega[i] * omega[j])
    point = {f"R_{i + 1}{j + 1}": R_[i, j] for i in range(3) for j in range(3)}
    point |= {f"p_R_{i + 1}{j + 1}": p[i, j] for i in range(3) for j in range(3)}
    for k, (i, j) in enumerate(PAIRS, start=1):
        point[f"lambda_{k}"] = lam[i - 1, j - 1]
        point[f"p_lambda_{k}"] = 0.0
    point |= {"I_1": i1, "I_2": i2, "I_3": i3}
    return point


def hand_points(count: int, seed: int) -> list[tuple[dict[str, float], np.ndarray, np.ndarray, np.ndarray]]:
    rng = np.random.default_rng(seed)
    result = []
    for _ in range(count):
        R_, omega, inertia = random_rotation(rng), rng.normal(size=3), random_admissible_inertia(rng)
        result.append((hand_point(R_, omega, inertia), R_, omega, inertia))
    return result


def evaluator(analysis, expressions):
    """Numeric function point -> values of expressions (phase space + I_1..I_3)."""
    args = [*analysis.phase_space, I1, I2, I3]
    fn = sympy.lambdify(args, list(expressions), "numpy")

    def evaluate(point):
        return np.array(fn(*[point[s.name] for s in args]), dtype=float)

    return evaluate


def gradient_evaluator(analysis, expressions):
    args = [*analysis.phase_space, I1, I2, I3]
    jac = sympy.Matrix(list(expressions)).jacobian(list(analysis.phase_space))
    fn = sympy.lambdify(args, jac, "numpy")
    return lambda point: np.array(fn(*[point[s.name] for s in args]), dtype=float)


def hand_chain(analysis) -> list[list[sympy.Expr]]:
    """The chain (217), written out by hand, with g from (72)."""
    s = analysis.symbols
    p = sympy.Matrix(3, 3, lambda i, j: s[f"p_R_{i + 1}{j + 1}"])
    g = [(I2 + I3 - I1) / 2, (I1 + I3 - I2) / 2, (I1 + I2 - I3) / 2]
    g_inv = sympy.diag(*[1 / x for x in g])
    lam = sympy.zeros(3, 3)
    for k, (i, j) in enumerate(PAIRS, start=1):
        lam[i - 1, j - 1] = lam[j - 1, i - 1] = s[f"lambda_{k}"]
    stage1 = [s[f"p_lambda_{k}"] for k in range(1, 7)]  # pi_ij = 0 (206)
    T = R.T * R - sympy.eye(3)  # (217) second
    S = R.T * p * g_inv
    S = S + S.T  # (210)
    F = g_inv * lam + lam * g_inv - 2 * g_inv * p.T * p * g_inv  # (215)

    def pick(A):
        return [A[i - 1, j - 1] for i, j in PAIRS]

    return [stage1, pick(T), pick(S), pick(F)]


# ------------------------------------------------------------------ the factory
def test_lagrangian_is_78_with_g_from_72():
    L = rigid_body_matrix.system()
    assert [q.name for q in L.coordinates] == [f"R_{i}{j}" for i in (1, 2, 3) for j in (1, 2, 3)]
    assert [v.name for v in L.velocities] == [f"R_{i}{j}_dot" for i in (1, 2, 3) for j in (1, 2, 3)]
    assert {p.name: v for p, v in L.parameters.items()} == {"I_1": 2.0, "I_2": 3.0, "I_3": 4.0}
    g = [(I2 + I3 - I1) / 2, (I1 + I3 - I2) / 2, (I1 + I2 - I3) / 2]
    expected = sum(g[i] * R_DOT[k, i] ** 2 for i in range(3) for k in range(3)) / 2
    assert sympy.expand(L.expression - expected) == 0
    # -lambda_a chi_a = -1/2 lambda_ij (R^T R - 1)_ij with symmetric lambda (78)
    lam = sympy.symbols("l11 l12 l13 l22 l23 l33")
    Lam = sympy.Matrix([[lam[0], lam[1], lam[2]], [lam[1], lam[3], lam[4]], [lam[2], lam[4], lam[5]]])
    engine_form = -sum(l * c for l, c in zip(lam, L.constraints))
    paper_form = -sum(Lam[i, j] * (R.T * R - sympy.eye(3))[i, j] for i in range(3) for j in range(3)) / 2
    assert sympy.expand(engine_form - paper_form) == 0


def test_check_inertia_accepts_a_body_and_returns_g():
    assert rigid_body_matrix.check_inertia(2.0, 3.0, 4.0) == pytest.approx((2.5, 1.5, 0.5))


@pytest.mark.parametrize(
    "inertia, bad",
    [((2.0, 1.0, 2.0 / 3.0), "g_1"), ((1.0, 5.0, 1.0), "g_2"), ((1.0, 2.0, 3.0), "g_3"), ((1.0, -1.0, 1.0), "I_2")],
)
def test_check_inertia_refuses_a_mass_matrix_that_is_not_positive(inertia, bad):
    with pytest.raises(InputError, match=bad):
        rigid_body_matrix.check_inertia(*inertia)


def test_fixing_impossible_inertia_through_load_system_is_refused():
    with pytest.raises(InputError, match="triangle inequality"):
        dirac.load_system("rigid_body_matrix", I_1=2.0, I_2=1.0, I_3=2.0 / 3.0)
    partly = dirac.load_system("rigid_body_matrix", I_1=1.0, I_2=2.0)  # I_3 still symbolic: fine
    with pytest.raises(InputError, match="g_3"):
        partly.fix(I_3=3.0)  # planar limit g_3 = 0
    with pytest.raises(InputError, match="I_2"):
        dirac.load_system("rigid_body_matrix", I_2=-1.0)
    fixed = partly.fix(I_3=2.5)
    assert not fixed.parameters and fixed.expression.free_symbols <= set(R_DOT)


def test_defaults_are_an_admissible_body():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        L = rigid_body_matrix.system().with_defaults()
    assert not L.parameters


# ------------------------------------------------------------------ the engine: (217)
def test_chain_217_counts(analysis):
    assert [len(stage) for stage in analysis.stages] == [6, 6, 6, 6]
    assert len(analysis.phase_space) == 30
    assert len(analysis.second_class) == 24 and analysis.first_class == []
    assert analysis.physical_degrees_of_freedom == 3


def test_chain_217_stage_by_stage(analysis):
    """Stage k of the engine spans the same constraints as (217) stage k, modulo the
    earlier stages (gradients on the surface, at hand-built points)."""
    hand = hand_chain(analysis)
    assert [sympy.sympify(c) for c in analysis.stages[0]] == hand[0]
    engine_all = [c for stage in analysis.stages for c in stage]
    values = evaluator(analysis, engine_all)
    engine_grads = [gradient_evaluator(analysis, [c for st in analysis.stages[:k] for c in st]) for k in range(1, 5)]
    hand_grads = [gradient_evaluator(analysis, [c for st in hand[:k] for c in st]) for k in range(1, 5)]
    for point, *_ in hand_points(5, seed=1):
        assert np.max(np.abs(values(point))) < 1e-10
        for k in range(1, 5):
            engine_grad, hand_grad = engine_grads[k - 1](point), hand_grads[k - 1](point)
            assert np.linalg.matrix_rank(hand_grad, tol=1e-9) == 6 * k
            assert np.linalg.matrix_rank(np.vstack([engine_grad, hand_grad]), tol=1e-9) == 6 * k


def test_multipliers_221_are_the_unique_solution_of_stage_4(analysis):
    stage4 = list(analysis.stages[3])
    lambdas = [analysis.symbols[f"lambda_{k}"] for k in range(1, 7)]
    residual = evaluator(analysis, stage4)
    jac = sympy.lambdify(
        [*analysis.phase_space, I1, I2, I3], sympy.Matrix(stage4).jacobian(lambdas), "numpy"
    )
    for point, *_ in hand_points(20, seed=2):
        assert np.max(np.abs(residual(point))) < 1e-10
        J = np.array(jac(*[point[s.name] for s in [*analysis.phase_space, I1, I2, I3]]), dtype=float)
        assert np.linalg.matrix_rank(J) == 6  # stage 4 fixes lambda uniquely


def test_surface_point_completes_lambda_as_in_221(analysis):
    """With the default inertia (2, 3, 4), the engine's surface point with given R, p has
    the multipliers (221)."""
    rng = np.random.default_rng(3)
    for _ in range(3):
        hand = hand_point(random_rotation(rng), rng.normal(size=3), np.array([2.0, 3.0, 4.0]))
        given = {k: v for k, v in hand.items() if k.startswith(("R_", "p_R_"))}
        point = analysis.surface_point(values=given, seed=5)
        for k in range(1, 7):
            assert point[f"lambda_{k}"] == pytest.approx(hand[f"lambda_{k}"], abs=1e-9)
            assert point[f"p_lambda_{k}"] == pytest.approx(0.0, abs=1e-9)


def test_all_primary_multipliers_are_determined(analysis):
    assert set(analysis.multipliers) == {f"u_{k}" for k in range(1, 7)}
    assert not analysis.undetermined_multipliers


# ------------------------------------------------------------------ equations of motion
def test_equations_of_motion_are_225_226(analysis):
    """The engine's reduced vector field z_dot = {z, H}_D on (R, M) is (225)-(226).

    All primary multipliers are determined here, so H = H_c (second-class terms of H_T
    drop out of Dirac brackets). Components are taken one by one with
    ``analysis.dirac_bracket(z, H_c)``, exactly what ``equations_of_motion()`` does for
    each phase-space variable; its p- and lambda-components are not needed for (225)-(226).
    """
    s = analysis.symbols
    H = analysis.canonical_hamiltonian
    p = sympy.Matrix(3, 3, lambda i, j: s[f"p_R_{i + 1}{j + 1}"])
    Q = R.T * p
    M = [-sum(eps(k, i, j) * Q[i, j] for i in range(3) for j in range(3)) for k in range(3)]  # (233)
    R_dot_exprs = [analysis.dirac_bracket(s[f"R_{i}{j}"], H) for i in (1, 2, 3) for j in (1, 2, 3)]
    M_dot_exprs = [analysis.dirac_bracket(M[k], H) for k in range(3)]
    values = evaluator(analysis, R_dot_exprs + M_dot_exprs)
    for point, R_, omega, inertia in hand_points(10, seed=4):
        got = values(point)
        R_dot = np.array(
            [[-sum(eps(j, k, m) * omega[k] * R_[i, m] for k in range(3) for m in range(3)) for j in range(3)] for i in range(3)]
        )  # (225)
        M_ = inertia * omega
        M_dot = np.cross(M_, omega)  # (226): I Omega_dot = [I Omega, Omega]
        np.testing.assert_allclose(got[:9], R_dot.ravel(), atol=1e-10)
        np.testing.assert_allclose(got[9:], M_dot, atol=1e-10)
