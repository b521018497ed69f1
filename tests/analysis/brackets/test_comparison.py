"""Comparing brackets: built-in structures, Jacobi identity, Casimirs, agreement and
disagreement reports on the rigid body (78)."""

from __future__ import annotations

import numpy as np
import pytest
import sympy
from rigid_body_analyses import cached_analysis

from dirac.analysis.brackets.casimirs import casimirs, jacobi_residual
from dirac.analysis.brackets.comparison import compare_brackets
from dirac.analysis.brackets.named_brackets import CanonicalBracket, StructureBracket, analysis_variables
from dirac.analysis.brackets.noncanonical import NoncanonicalVariables
from dirac.analysis.brackets.structures import chetaev_structure, lie_poisson_so3_structure, named_bracket
from dirac.errors import InputError

M = sympy.symbols("M_1:4", real=True)
R = sympy.Matrix(3, 3, lambda i, j: sympy.Symbol(f"R_{i + 1}{j + 1}", real=True))
P_R = sympy.Matrix(3, 3, lambda i, j: sympy.Symbol(f"p_R_{i + 1}{j + 1}", real=True))
NAMES = [*(f"M_{k}" for k in (1, 2, 3)), *(f"R_{i}{j}" for i in (1, 2, 3) for j in (1, 2, 3))]


@pytest.fixture(scope="module")
def analysis(request):
    return cached_analysis(request.config, "rigid_body_matrix")


@pytest.fixture(scope="module")
def plain_variables():
    """M and R as variables on the 18-dim phase space (R, p): enough for structures."""
    Q = R.T * P_R
    functions = {f"M_{k + 1}": -sum(sympy.LeviCivita(k, i, j) * Q[i, j] for i in range(3) for j in range(3)) for k in range(3)}
    functions |= {R[i, j].name: R[i, j] for i in range(3) for j in range(3)}
    return NoncanonicalVariables(functions, list(zip(R, P_R)), inverse={})


def random_values(rng, names):
    return {name: float(v) for name, v in zip(names, rng.normal(size=len(names)))}


# ------------------------------------------------------------------ structures
def test_chetaev_structure_entries_by_hand():
    J = chetaev_structure(M, R)
    assert J[0, 1] == -M[2] and J[1, 2] == -M[0] and J[2, 0] == -M[1]  # (248)
    # (249) {M_1, R_jk} = -eps_1km R_jm: {M_1, R_22} = -eps_123 R_23 = -R_23, {M_1, R_23} = R_22
    assert J[0, 3 + 3 * 1 + 1] == -R[1, 2] and J[0, 3 + 3 * 1 + 2] == R[1, 1]
    assert J[0, 3] == 0  # {M_1, R_11} = 0
    assert J[3:, 3:] == sympy.zeros(9, 9)  # {R, R} = 0
    assert J + J.T == sympy.zeros(12, 12)
    assert lie_poisson_so3_structure(M) == J[:3, :3]


def test_jacobi_holds_for_chetaev_and_fails_for_a_wrong_sign(plain_variables):
    rng = np.random.default_rng(0)
    points = [random_values(rng, NAMES) for _ in range(5)]
    chetaev = StructureBracket("chetaev", "", plain_variables, NAMES, chetaev_structure(M, R))
    assert jacobi_residual(chetaev, points) < 1e-12
    wrong = chetaev_structure(M, R)
    wrong[:3, 3:] = -wrong[:3, 3:]  # M acting on the rows with the opposite sign
    wrong[3:, :3] = -wrong[3:, :3]
    broken = StructureBracket("broken", "", plain_variables, NAMES, wrong)
    assert jacobi_residual(broken, points) > 1e-2


def test_casimir_of_so3_is_the_length_of_M(plain_variables):
    so3 = StructureBracket("so3", "", plain_variables, NAMES[:3], lie_poisson_so3_structure(M))
    found = casimirs(so3)
    assert len(found) == 1
    ratio = sympy.cancel(found[0] / (M[0] ** 2 + M[1] ** 2 + M[2] ** 2))
    assert ratio.is_number and ratio != 0


def test_casimirs_of_chetaev_are_the_scalar_products_of_the_rows(plain_variables):
    chetaev = StructureBracket("chetaev", "", plain_variables, NAMES, chetaev_structure(M, R))
    found = casimirs(chetaev)
    assert len(found) == 6
    RRt = R * R.T  # rows a, b, c: |a|^2, a.b, ... are invariant under M (rotation of each row)
    c = sympy.symbols("c0:6")
    for i in range(3):
        for j in range(i, 3):
            combination = sympy.expand(sum(ci * f for ci, f in zip(c, found)) - RRt[i, j])
            equations = sympy.Poly(combination, *M, *R).coeffs()
            assert sympy.solve(equations, c, dict=True), (i, j)


def test_casimirs_need_a_linear_structure(plain_variables):
    quadratic = sympy.Matrix([[0, M[2] ** 2, 0], [-M[2] ** 2, 0, 0], [0, 0, 0]])
    bracket = StructureBracket("quadratic", "", plain_variables, NAMES[:3], quadratic)
    assert not bracket.is_linear
    with pytest.raises(InputError, match="not a linear"):
        casimirs(bracket)


def test_structure_must_be_antisymmetric(plain_variables):
    with pytest.raises(InputError, match="antisymmetric"):
        StructureBracket("bad", "", plain_variables, NAMES[:3], sympy.eye(3))


# ------------------------------------------------------------------ on the engine's analysis
def test_dirac_and_chetaev_agree_on_the_surface_of_78(analysis):
    variables = analysis_variables(analysis)
    assert list(variables.names) == NAMES
    points = [analysis.surface_point(seed=k) for k in range(5)]
    result = compare_brackets(named_bracket("dirac", analysis, variables), named_bracket("chetaev", analysis, variables), points)
    assert result.agree and result.points == 5 and len(result.entries) == 66
    assert result.max_difference < 1e-10
    so3 = compare_brackets(named_bracket("dirac", analysis, variables), named_bracket("lie_poisson_so3", analysis, variables), points)
    assert so3.variables == ("M_1", "M_2", "M_3") and so3.agree


def test_dirac_and_canonical_differ_exactly_where_the_hand_calculation_says(analysis):
    """Variables M, R and the stage-3 constraints S = R^T p G + G p^T R, G = g^{-1} for
    the default inertia (2, 3, 4), g = (5/2, 3/2, 1/2). The Dirac bracket of a
    second-class constraint vanishes; canonically {R_ij, S_ab} = R_ia delta_jb G_b +
    G_a delta_ja R_ib, non-zero iff j is a or b. M and R keep their brackets ((246) with
    (239))."""
    s = analysis.symbols
    R_, p_ = (sympy.Matrix(3, 3, lambda i, j, x=x: s[f"{x}_{i + 1}{j + 1}"]) for x in ("R", "p_R"))
    G = sympy.diag(sympy.Rational(2, 5), sympy.Rational(2, 3), 2)
    S = R_.T * p_ * G + G * p_.T * R_
    base = analysis_variables(analysis)
    functions = dict(base.functions)
    pairs_S = [(a, b) for a in (1, 2, 3) for b in (1, 2, 3) if a <= b]
    functions |= {f"S_{a}{b}": sympy.expand(S[a - 1, b - 1]) for a, b in pairs_S}
    variables = NoncanonicalVariables(functions, base.pairs, inverse={})
    points = [analysis.surface_point(seed=k) for k in range(2)]
    result = compare_brackets(named_bracket("dirac", analysis, variables), CanonicalBracket(variables), points)
    expected_differ = set()
    for i in (1, 2, 3):
        for j in (1, 2, 3):
            for a, b in pairs_S:
                if j in (a, b):
                    expected_differ.add((f"R_{i}{j}", f"S_{a}{b}"))
    differ = set(result.differing)
    assert not result.agree
    assert {pair for pair in differ if pair[0].startswith("R_")} == expected_differ
    assert not {pair for pair in differ if not pair[1].startswith("S_")}  # M, R pairs agree
    J_D = variables.dirac_bracket_matrix(analysis, points[0])
    index = [variables.names.index(f"S_{a}{b}") for a, b in pairs_S]
    assert np.max(np.abs(J_D[index, :])) < 1e-9


def test_jacobi_identity_of_the_dirac_bracket(analysis):
    dirac_bracket = named_bracket("dirac", analysis)
    assert jacobi_residual(dirac_bracket, [analysis.surface_point(seed=1)]) < 1e-6
