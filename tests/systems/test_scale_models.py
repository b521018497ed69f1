"""The scale models against their hand counts (systems/scale_models.py).

Hand derivations (docstrings of the factories):

chain(n), L = m/2 sum |r_k_dot|^2 - m g sum y_k, rods chi_k (n of them):
  6n-dimensional phase space (x_k, y_k, lambda_k and momenta). Stage 1: p_lambda_k = 0;
  {p_lambda_k, H_c} = chi_k: stage 2 is the rods; stage 3 their time derivatives
  2 (r_k - r_{k-1}) . (p_k - p_{k-1}) / m; stage 4 (second derivatives) contains the
  lambda_k through the tridiagonal matrix of the rods' gradients, which is invertible:
  it fixes every lambda_k, and {stage 4, p_lambda} fixes every u_k. 4n constraints, all
  second class (C is invertible: the chain's pairs (p_lambda, stage 4), (stage 2, stage 3)),
  no reducible one, (6n - 4n)/2 = n degrees of freedom.
maxwell_ring(n), L = sum_i (A1_i_dot - (A0_{i+1} - A0_i))^2/2:
  p_A1_i = E_i = A1_i_dot - (A0_{i+1} - A0_i), p_A0_i = 0 (primary, n);
  H_c = sum_i p_A1_i^2/2 + sum_i p_A1_i (A0_{i+1} - A0_i);
  {p_A0_i, H_c} = -(p_A1_{i-1} - p_A1_i): the Gauss laws G_i = p_A1_i - p_A1_{i-1}
  (stage 2); sum_i G_i = 0, so n - 1 are independent and one is reducible;
  {G_i, H_c} = 0 (H_c has no A1), so the chain stops; everything is first class,
  the n multipliers stay free, (4n - 2(2n - 1))/2 = 1 degree of freedom.
maxwell_torus(L): the same with two link directions; Gauss laws
  p_Ax_{a,b} - p_Ax_{a-1,b} + p_Ay_{a,b} - p_Ay_{a,b-1}; {G, H_c} = 0 because the magnetic
  energy depends on the links through lattice curls, whose divergence vanishes;
  L^2 primary, L^2 - 1 independent Gauss laws, 1 reducible, all first class,
  (6L^2 - 2(2L^2 - 1))/2 = L^2 + 1 degrees of freedom.
"""

from __future__ import annotations

from collections import Counter

import pytest
import sympy
from stress_scaling import stress_scale

import dirac
from dirac.analysis.constraint_analysis import ConstraintAnalysis
from dirac.errors import InputError
from dirac_systems.scale_models import chain, maxwell_ring, maxwell_torus


def _full() -> bool:
    return stress_scale() == 1.0


def _ring_gauss_laws(n: int) -> list[sympy.Expr]:
    p = [sympy.Symbol(f"p_A1_{i}", real=True) for i in range(1, n + 1)]
    return [p[i] - p[i - 1] for i in range(n)]  # p[-1] is site n: periodic


def _torus_gauss_laws(size: int) -> list[sympy.Expr]:
    def p(field: str, a: int, b: int) -> sympy.Symbol:
        return sympy.Symbol(f"p_{field}_{a % size}_{b % size}", real=True)

    return [
        p("Ax", a, b) - p("Ax", a - 1, b) + p("Ay", a, b) - p("Ay", a, b - 1)
        for a in range(size)
        for b in range(size)
    ]


def _same_up_to_sign(found: list[sympy.Expr], expected: list[sympy.Expr]) -> bool:
    """Each found constraint is one expected constraint or its negative, and each expected one is found once."""
    def key(e: sympy.Expr) -> sympy.Expr:  # the expanded form or its negative, whichever sorts first
        e = sympy.expand(e)
        return min(e, -e, key=sympy.default_sort_key)

    return Counter(key(c) for c in found) == Counter(key(e) for e in expected)


def check_chain(n: int, analysis: ConstraintAnalysis | None = None) -> None:
    analysis = analysis or dirac.analyze(chain(n))
    assert [len(stage) for stage in analysis.stages] == [n, n, n, n]
    assert len(analysis.second_class) == 4 * n and analysis.first_class == []
    assert analysis.reducible_constraints == []
    assert analysis.physical_degrees_of_freedom == n
    assert analysis.undetermined_multipliers == []
    assert len(analysis.multipliers) == n
    s = analysis.symbols
    x = [s[f"x{k}"] for k in range(1, n + 1)]
    y = [s[f"y{k}"] for k in range(1, n + 1)]
    lsym = sympy.Symbol("l", real=True)
    rods = [x[0] ** 2 + y[0] ** 2 - lsym**2] + [
        (x[k] - x[k - 1]) ** 2 + (y[k] - y[k - 1]) ** 2 - lsym**2 for k in range(1, n)
    ]
    assert _same_up_to_sign(analysis.stages[1], rods)
    primary = [s[f"p_lambda_{k}"] for k in range(1, n + 1)]
    assert _same_up_to_sign(analysis.stages[0], primary)


def _decided_sparsely(analysis: ConstraintAnalysis) -> bool:
    """No choice of independent rows fell back from sparse elimination to the dense pass."""
    return not any("sparse elimination met a row" in note for note in analysis.notes)


def check_ring(n: int) -> ConstraintAnalysis:
    analysis = dirac.analyze(maxwell_ring(n))
    assert [len(stage) for stage in analysis.stages] == [n, n - 1]
    assert len(analysis.reducible_constraints) == 1
    assert _same_up_to_sign(analysis.stages[1] + analysis.reducible_constraints, _ring_gauss_laws(n))
    assert len(analysis.first_class) == 2 * n - 1 and analysis.second_class == []
    assert analysis.physical_degrees_of_freedom == 1
    assert len(analysis.undetermined_multipliers) == n
    return analysis


def check_torus(size: int) -> ConstraintAnalysis:
    analysis = dirac.analyze(maxwell_torus(size))
    sites = size * size
    assert [len(stage) for stage in analysis.stages] == [sites, sites - 1]
    assert len(analysis.reducible_constraints) == 1
    assert _same_up_to_sign(analysis.stages[1] + analysis.reducible_constraints, _torus_gauss_laws(size))
    assert len(analysis.first_class) == 2 * sites - 1 and analysis.second_class == []
    assert analysis.physical_degrees_of_freedom == sites + 1
    assert len(analysis.undetermined_multipliers) == sites
    assert analysis.bracket_matrix_rank == 0
    return analysis


@pytest.fixture(scope="module")
def chain9() -> ConstraintAnalysis:
    return dirac.analyze(chain(9))


def test_chain_hand_counts(chain9):
    check_chain(9, chain9)


def test_ring_hand_counts_on_the_large_system_path():
    analysis = check_ring(32)  # 128 phase-space variables: the sparse surface points and one-pass ranks
    assert any(note.startswith("large system (128 phase-space variables)") for note in analysis.notes)
    assert _decided_sparsely(analysis)


def test_dirac_bracket_at_a_point_with_a_sparse_c(chain9):
    """36 second-class constraints (C solved by sparse LU): every constraint's Dirac bracket vanishes, (240)."""
    analysis = chain9
    point = analysis.surface_point(seed=3)
    for constraint in analysis.constraints[::5]:
        for other in ("x1", "p_y5", "p_x9"):
            assert abs(analysis.dirac_bracket(constraint, other, at=point)) < 1e-9
    # equal masses: {q_i, p_j}_D is an orthogonal projector onto the tangent space of the
    # configuration surface, so its diagonal entries lie in [0, 1] (strictly inside at a generic point)
    assert 0.0 < analysis.dirac_bracket("x9", "p_x9", at=point) < 1.0


def test_torus_hand_counts():
    check_torus(3)


def test_torus_hand_counts_on_the_large_system_path():
    analysis = check_torus(5)  # 150 phase-space variables: sparse gradients, elimination, blocks of C
    assert any(note.startswith("large system (150 phase-space variables)") for note in analysis.notes)
    assert _decided_sparsely(analysis)


@pytest.mark.slow
def test_chain_at_scale():
    """The 128-link chain (``DIRAC_FULL_STRESS=1``; 16 links in the bounded form)."""
    check_chain(128 if _full() else 16)


@pytest.mark.slow
def test_ring_at_scale():
    """The 1024-site ring (``DIRAC_FULL_STRESS=1``; 128 sites in the bounded form)."""
    assert _decided_sparsely(check_ring(1024 if _full() else 128))


@pytest.mark.slow
def test_torus_at_scale():
    """The 16 x 16 torus (``DIRAC_FULL_STRESS=1``; 8 x 8 in the bounded form)."""
    assert _decided_sparsely(check_torus(16 if _full() else 8))


@pytest.mark.parametrize(("factory", "value"), [(chain, 0), (maxwell_ring, 1), (maxwell_torus, 2.5)])
def test_bad_sizes_are_refused(factory, value):
    with pytest.raises(InputError, match="must be"):
        factory(value)
