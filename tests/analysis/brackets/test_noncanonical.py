"""Brackets in noncanonical variables: the change (235) ``(R, p) -> (R, M, P)`` and the
brackets (236)–(238), written out by hand here; Dirac brackets of the new variables on
the constraint surface of (228) from the engine. (Those on the surface of (78) are
exercised in test_comparison.py and test_chetaev.py.)"""

from __future__ import annotations

import numpy as np
import pytest
import sympy
from rigid_body_analyses import cached_analysis, eps, hat

from dirac.analysis.brackets.noncanonical import (
    NoncanonicalVariables,
    canonical_bracket,
    rigid_body_variables,
)
from dirac.errors import AnalysisError, InputError

R = sympy.Matrix(3, 3, lambda i, j: sympy.Symbol(f"R_{i + 1}{j + 1}", real=True))
M = sympy.symbols("M_1:4", real=True)
SYM = ((1, 1), (1, 2), (1, 3), (2, 2), (2, 3), (3, 3))


def delta(i: int, j: int) -> int:
    return int(i == j)


def hand_brackets(Rt: np.ndarray, M_: np.ndarray) -> dict[tuple[str, str], float]:
    """(236)-(238) with R~ = R^{-1}, K = R~ R~^T, for all pairs of (R, M, P).

    (238) is used in its corrected form: the paper prints
    -K_ia eps_jbn M_n - K_jb eps_jan M_n + (a <-> b); the second index pattern must be
    eps_ian (derived by hand from {Q_ij, Q_ab} = -K_ia eps_jbn M_n, Q = R~ p), without
    which the right side is not antisymmetric under (ij) <-> (ab).
    """
    K = Rt @ Rt.T
    KM = K @ M_
    out: dict[tuple[str, str], float] = {}
    for i in range(3):
        for j in range(3):  # (236) {M_i, M_j} = -eps_ijk (K M)_k
            out[(f"M_{i + 1}", f"M_{j + 1}")] = -sum(eps(i, j, k) * KM[k] for k in range(3))
        for j in range(3):
            for k in range(3):  # (236) {M_i, R_jk} = -eps_ikm R~^T_jm
                out[(f"M_{i + 1}", f"R_{j + 1}{k + 1}")] = -sum(eps(i, k, m) * Rt.T[j, m] for m in range(3))
    for i in range(3):
        for j in range(3):
            for a, b in SYM:  # (237) {R_ij, P_ab} = R~^T_ia delta_jb + R~^T_ib delta_ja
                a0, b0 = a - 1, b - 1
                out[(f"R_{i + 1}{j + 1}", f"P_{a}{b}")] = Rt.T[i, a0] * delta(j, b0) + Rt.T[i, b0] * delta(j, a0)
    for k in range(3):
        for a, b in SYM:  # (237) {M_k, P_ab}
            a0, b0 = a - 1, b - 1
            out[(f"M_{k + 1}", f"P_{a}{b}")] = -2 * M_[k] * K[a0, b0] + delta(k, a0) * KM[b0] + delta(k, b0) * KM[a0]
    for i, j in SYM:
        for a, b in SYM:  # (238), corrected
            i0, j0, a0, b0 = i - 1, j - 1, a - 1, b - 1
            total = 0.0
            for n in range(3):
                total -= K[i0, a0] * eps(j0, b0, n) * M_[n] + K[j0, b0] * eps(i0, a0, n) * M_[n]
                total -= K[i0, b0] * eps(j0, a0, n) * M_[n] + K[j0, a0] * eps(i0, b0, n) * M_[n]
            out[(f"P_{i}{j}", f"P_{a}{b}")] = total
    return out


@pytest.fixture(scope="module")
def change_235():
    """The change (235) with R~ = R^{-1}, built (and compiled) once for the module."""
    return rigid_body_variables()


def test_canonical_bracket_is_the_one_of_the_paper():
    q, p, x, y = sympy.symbols("q p x y", real=True)
    pairs = [(q, p), (x, y)]
    assert canonical_bracket(q, p, pairs) == 1 and canonical_bracket(p, q, pairs) == -1
    assert canonical_bracket(q * x, p * y, pairs) == x * y + q * p
    assert canonical_bracket(q, x, pairs) == 0


def test_inverse_change_235_is_the_inverse(change_235):
    w = change_235
    for name in ["M_1", "M_2", "M_3", "P_11", "P_12", "P_23", "P_33"]:
        back = sympy.cancel(sympy.together(w.functions[name].xreplace(w.inverse)))
        assert back == w.symbols[name]


def test_brackets_236_237_symbolically_for_any_invertible_R(change_235):
    """{M_i, R_jk} = -eps_ikm R~^T_jm (236) and {R_ij, P_ab} = R~^T_ia delta_jb +
    R~^T_ib delta_ja (237), exactly, with R~ = R^{-1} of a general matrix."""
    w = change_235
    Rt = R.inv(method="ADJ")
    for i in range(3):
        for j, k in [(0, 0), (1, 2), (2, 1)]:
            expected = -sum(eps(i, k, m) * Rt.T[j, m] for m in range(3))
            got = w.bracket(f"M_{i + 1}", f"R_{j + 1}{k + 1}", express=True)
            assert sympy.cancel(got - expected) == 0
    for a, b in [(1, 1), (1, 2), (2, 3)]:
        for i, j in [(0, 0), (1, 1), (2, 2), (0, 2)]:
            expected = Rt.T[i, a - 1] * delta(j, b - 1) + Rt.T[i, b - 1] * delta(j, a - 1)
            got = w.bracket(f"R_{i + 1}{j + 1}", f"P_{a}{b}", express=True)
            assert sympy.cancel(got - expected) == 0


def test_with_R_transpose_the_canonical_brackets_of_M_R_are_chetaev_exactly():
    """With M_k = -eps_kij (R^T p)_ij (233) the canonical brackets of (M, R) are, as
    polynomials, {M_i, M_j} = -eps_ijk M_k and {M_i, R_jk} = -eps_ikm R_jm: (236) with
    R~ = R^T, i.e. (248)-(249) without any use of the constraints."""
    w = rigid_body_variables(inverse="transpose")
    for i in range(3):
        for j in range(3):
            expected = -sum(eps(i, j, k) * w.functions[f"M_{k + 1}"] for k in range(3))
            assert sympy.expand(w.bracket(f"M_{i + 1}", f"M_{j + 1}") - expected) == 0
            for k in range(3):
                expected = -sum(eps(i, k, m) * R[j, m] for m in range(3))
                assert sympy.expand(w.bracket(f"M_{i + 1}", f"R_{j + 1}{k + 1}") - expected) == 0


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_brackets_236_to_238_numerically_all_entries(seed, change_235):
    """Arbitrary invertible R (off the surface) and arbitrary p: every bracket of
    (R, M, P) from the canonical ones equals (236)-(238)."""
    w = change_235
    rng = np.random.default_rng(seed)
    R_ = rng.normal(size=(3, 3)) + 2 * np.eye(3)
    p_ = rng.normal(size=(3, 3))
    point = {f"R_{i + 1}{j + 1}": R_[i, j] for i in range(3) for j in range(3)}
    point |= {f"p_R_{i + 1}{j + 1}": p_[i, j] for i in range(3) for j in range(3)}
    Rt = np.linalg.inv(R_)
    Q = Rt @ p_
    M_ = np.array([-sum(eps(k, i, j) * Q[i, j] for i in range(3) for j in range(3)) for k in range(3)])  # (233)
    values = w.values(point)
    np.testing.assert_allclose([values[f"M_{k}"] for k in (1, 2, 3)], M_, atol=1e-12)
    np.testing.assert_allclose([values[f"P_{i}{j}"] for i, j in SYM], [Q[i - 1, j - 1] + Q[j - 1, i - 1] for i, j in SYM])
    J = w.numeric_bracket_matrix(point)
    index = {name: k for k, name in enumerate(w.names)}
    expected = hand_brackets(Rt, M_)
    for (a, b), value in expected.items():
        assert J[index[a], index[b]] == pytest.approx(value, abs=1e-10), (a, b)
    for a in w.names:  # {R, R} = 0 (236)
        for b in w.names:
            if a.startswith("R_") and b.startswith("R_"):
                assert J[index[a], index[b]] == 0.0


def test_the_printed_238_is_not_antisymmetric_so_it_has_a_typo():
    rng = np.random.default_rng(5)
    Rt = np.linalg.inv(rng.normal(size=(3, 3)) + 2 * np.eye(3))
    M_ = rng.normal(size=3)
    K = Rt @ Rt.T

    def printed(i, j, a, b):  # -K_ia eps_jbn M_n - K_jb eps_jan M_n + (a <-> b), as printed
        def term(a_, b_):
            return -sum(K[i, a_] * eps(j, b_, n) * M_[n] + K[j, b_] * eps(j, a_, n) * M_[n] for n in range(3))

        return term(a, b) + term(b, a)

    assert abs(printed(0, 1, 1, 2) + printed(1, 2, 0, 1)) > 1e-3
    corrected = hand_brackets(Rt, M_)
    assert corrected[("P_12", "P_23")] == pytest.approx(-corrected[("P_23", "P_12")])


def test_change_that_cannot_be_inverted_is_reported():
    q, p = sympy.symbols("q p", real=True)
    w = NoncanonicalVariables({"q": q, "E": p**2 / 2 + q**2 / 2}, [(q, p)])
    assert w.bracket("q", "E") == p
    with pytest.raises(AnalysisError, match="inverted"):
        w.bracket("q", "E", express=True)


def test_bad_new_variables_are_refused():
    q, p = sympy.symbols("q p", real=True)
    with pytest.raises(InputError, match="does not depend"):
        NoncanonicalVariables({"c": sympy.Integer(3)}, [(q, p)])
    with pytest.raises(InputError, match="name of a canonical variable"):
        NoncanonicalVariables({"q": p}, [(q, p)])
    w = NoncanonicalVariables({"q": q, "s": p + q}, [(q, p)])
    assert w.bracket("q", "s", express=True) == 1
    with pytest.raises(InputError, match="not one of the new variables"):
        w.bracket("q", "x")


@pytest.mark.slow
def test_dirac_brackets_of_R_M_P_on_the_surface_of_228(request):
    """On the surface, the Dirac brackets of the new variables are (236) with R~ = R^T
    = R^{-1}, i.e. Chetaev (248)-(249), and the constraints P are Casimirs (Sect. XI)."""
    analysis = cached_analysis(request.config, "rigid_body_momentum")
    w = rigid_body_variables(analysis.symbols, inverse="transpose")
    rng = np.random.default_rng(7)
    for _ in range(3):
        q, r = np.linalg.qr(rng.normal(size=(3, 3)))
        R_ = q * np.sign(np.linalg.det(q))
        M_ = rng.normal(size=3)
        p_ = 0.5 * R_ @ hat(M_)  # (229)
        given = {f"R_{i + 1}{j + 1}": R_[i, j] for i in range(3) for j in range(3)}
        given |= {f"p_R_{i + 1}{j + 1}": p_[i, j] for i in range(3) for j in range(3)}
        point = analysis.surface_point(values=given, seed=3)
        J = w.dirac_bracket_matrix(analysis, point)
        index = {name: k for k, name in enumerate(w.names)}
        expected = hand_brackets(R_.T, M_)
        for (a, b), value in expected.items():
            if a.startswith("P") or b.startswith("P"):
                value = 0.0  # P_ij are second-class constraints: Casimirs of { , }_D
            assert J[index[a], index[b]] == pytest.approx(value, abs=1e-9), (a, b)
