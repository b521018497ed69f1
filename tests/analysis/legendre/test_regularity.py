"""Irregular and reducible constraints: regularised visibly, refused clearly, never a traceback.

Each test states the hand derivation it checks (canonical bracket ``{q, p} = 1``).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import sympy

import dirac
from dirac.errors import AnalysisError, DiracWarning


def test_cawley_example_is_regularised_to_z_and_finds_p_x():
    """Cawley's ``L = x_dot z_dot + y z^2/2``.

    ``p_x = z_dot``, ``p_z = x_dot``, ``p_y = 0`` (primary); ``H_c = p_x p_z - y z^2/2``.
    ``{p_y, H_c} = z^2/2``: the secondary ``z^2 = 0`` is irregular (gradient ``z dz``
    vanishes on it) and is regular as ``z = 0``. ``{z, H_T} = dH_c/dp_z = p_x``:
    tertiary ``p_x = 0``; ``{p_x, H_T} = -dH/dx = 0`` ends the chain.
    All brackets among ``p_y, z, p_x`` vanish: three first class, ``u_1`` free,
    ``(6 - 2*3)/2 = 0`` degrees of freedom in the regular form.
    """
    L = dirac.Lagrangian.from_strings("cawley", ["x", "y", "z"], "x_dot*z_dot + y*z**2/2")
    a = dirac.analyze(L)
    s = a.symbols
    assert a.stages == [[s["p_y"]], [s["z"]], [s["p_x"]]]
    assert len(a.first_class) == 3 and a.second_class == []
    assert a.physical_degrees_of_freedom == 0
    assert a.undetermined_multipliers == list(a.primary_multipliers)
    assert any("z**2/2 = 0 is irregular" in n and "square-free part z = 0" in n for n in a.notes)


def _pendulum(constraint: str) -> dirac.Lagrangian:
    return dirac.Lagrangian.from_strings(
        "p", ["x", "y"], "m/2*(x_dot**2 + y_dot**2) - m*g*y", [constraint], {"m": 1.0, "g": 9.81, "l": 1.0}
    )


def test_squared_constraint_is_the_pendulum():
    """``chi = (x^2 + y^2 - l^2)^2``: the force ``lambda dchi = 2 lambda chi dchi_0`` vanishes on
    the surface, so the multiplier cannot hold the bob; the square-free part
    ``x^2 + y^2 - l^2`` is the pendulum, whose chain is ``p_lambda``, ``chi_0``,
    ``x p_x + y p_y`` (times ``2/m``), the equation fixing ``lambda``: four stages of one
    constraint, all second class, ``(6 - 4)/2 = 1`` degree of freedom."""
    a = dirac.analyze(_pendulum("(x**2 + y**2 - l**2)**2"))
    x, y, l = (a.symbols["x"], a.symbols["y"], sympy.Symbol("l", real=True))
    assert [len(stage) for stage in a.stages] == [1, 1, 1, 1]
    assert sympy.expand(a.stages[1][0] - (x**2 + y**2 - l**2)) == 0
    assert len(a.second_class) == 4 and a.first_class == []
    assert a.physical_degrees_of_freedom == 1
    assert any("square-free part" in n for n in a.notes)


def test_expanded_squared_constraint_is_refused_with_its_square_free_part():
    """The same constraint written expanded is found irregular at surface points (gradient
    ``4 chi_0 (x, y)`` vanishes where it holds); its multiplier term is irregular too, so
    it is refused, naming the square-free part to write instead."""
    expanded = "x**4 + 2*x**2*y**2 + y**4 - 2*l**2*x**2 - 2*l**2*y**2 + l**4"
    with pytest.raises(AnalysisError, match=r"constraint 1 .* is irregular.*square-free part -l\*\*2 \+ x\*\*2 \+ y\*\*2 = 0"):
        dirac.analyze(_pendulum(expanded))


def test_crossing_constraint_is_analysed_branch_by_branch(run_cli, tmp_path):
    """``x y = 0`` is the union of ``x = 0`` and ``y = 0``, which cross at ``x = y = 0`` where the
    gradient ``(y, x)`` vanishes: no single regular surface. Each branch is a bead on a straight
    wire under gravity (``p_lambda``, the line, the velocity along its normal, the equation
    fixing ``lambda``: 4 second class, ``(6 - 4)/2 = 1`` degree of freedom), listed as a
    component with a warning naming both (before, the product met again at stage 2 as
    ``-x y`` was not recognised as the holonomic constraint, and the whole was refused)."""
    L = dirac.Lagrangian.from_strings("crossing", ["x", "y"], "(x_dot**2 + y_dot**2)/2 - y", ["x*y"])
    with pytest.warns(DiracWarning, match=r"2 crossing branches"):
        analysis = dirac.analyze(L)
    assert sorted((c.condition, len(c.analysis.second_class), c.analysis.physical_degrees_of_freedom)
                  for c in analysis.components) == [("x = 0", 4, 1), ("y = 0", 4, 1)]
    path = tmp_path / "crossing.toml"
    path.write_text('[system]\nname = "crossing"\ncoordinates = ["x", "y"]\n'
                    'lagrangian = "(x_dot**2 + y_dot**2)/2 - y"\nconstraints = ["x*y"]\n')
    status, out, err = run_cli("analyze", str(path), "--json")
    assert status == 0 and err.startswith("warning:") and len(json.loads(out)["components"]) == 2


def test_disjoint_branches_are_regular():
    """``(x - 1)(x + 1) = 0``: the branches ``x = 1`` and ``x = -1`` never meet and the gradient
    ``2x`` is non-zero on both, so the constraint is regular: a chain like the pendulum's
    (constraint, velocity, multiplier-fixing equation), four second class, ``(6 - 4)/2 = 1``."""
    L = dirac.Lagrangian.from_strings("two_walls", ["x", "y"], "(x_dot**2 + y_dot**2)/2 - y", ["(x - 1)*(x + 1)"])
    a = dirac.analyze(L)
    assert [len(s) for s in a.stages] == [1, 1, 1, 1]
    assert a.physical_degrees_of_freedom == 1


def test_real_irregular_constraint_is_refused():
    """``x^2 + y^2 = 0`` holds only at ``x = y = 0``, where its gradient vanishes, and is no
    power of a polynomial: refused, naming the constraint and the remedy."""
    L = dirac.Lagrangian.from_strings("point", ["x", "y"], "(x_dot**2 + y_dot**2)/2 - y", ["x**2 + y**2"])
    with pytest.raises(AnalysisError, match=r"x\*\*2 \+ y\*\*2 = 0 is irregular.*x = 0 and y = 0"):
        dirac.analyze(L)


ROTATIONS = (
    "((x1_dot - (w2*x3 - w3*x2))**2 + (x2_dot - (w3*x1 - w1*x3))**2 + (x3_dot - (w1*x2 - w2*x1))**2)/2"
    " - (x1**2 + x2**2 + x3**2)/2"
)


def test_three_gauged_rotations_are_reducible():
    """``L = 1/2 |x_dot - w x x|^2 - |x|^2/2`` with velocity-free ``w``.

    ``p = x_dot - w x x``, ``p_w = 0`` (3 primary); ``H_c = p^2/2 + w . (x x p) + |x|^2/2``.
    ``{p_w, H_c} = -J``, ``J = x x p``: three secondary conditions with ``x . J = 0``, so
    only two are independent where ``x != 0`` (reducible). ``J`` commutes with the
    rotation-invariant ``p^2``, ``|x|^2`` and ``{J_i, w . J} = eps_ijk w_j J_k ~ 0``: the
    chain ends. ``{J_i, J_j} = eps_ijk J_k ~ 0`` and ``p_w`` commutes with ``J``: five
    independent first-class constraints, ``(12 - 2*5)/2 = 1`` degree of freedom (the
    radial motion), all three ``u`` free. The left-out ``J`` component still holds at
    every sample point.
    """
    L = dirac.Lagrangian.from_strings("rotations", ["x1", "x2", "x3", "w1", "w2", "w3"], ROTATIONS)
    a = dirac.analyze(L)
    assert [len(s) for s in a.stages] == [3, 2]
    assert len(a.first_class) == 5 and a.second_class == []
    assert a.physical_degrees_of_freedom == 1
    assert len(a.undetermined_multipliers) == 3
    assert len(a.reducible_constraints) == 1
    s = a.symbols
    x = sympy.Matrix([s["x1"], s["x2"], s["x3"]])
    p = sympy.Matrix([s["p_x1"], s["p_x2"], s["p_x3"]])
    J = x.cross(p)
    kept = a.stages[1] + a.reducible_constraints
    for j in J:  # every component of J is, up to sign, one of the three
        assert any(sympy.expand(j - c) == 0 or sympy.expand(j + c) == 0 for c in kept)
    values = a._numerics.evaluate(list(J), a._points)
    assert np.max(np.abs(values)) < 1e-8
    assert a.to_json()["reducible_constraints"] == [str(c) for c in a.reducible_constraints]
    assert any("reducible" in n for n in a.notes)


def test_sample_points_are_regular():
    """At every sample point the Jacobian of the kept constraints has full rank (here the
    pendulum's four constraints, whose gradients are independent on the whole surface)."""
    a = dirac.analyze(dirac.load_system("pendulum"))
    grads = [g for c in a.constraints for g in a._space.gradient(c)]
    n = len(a.phase_space)
    for z in a._points:
        J = a._numerics.evaluate(grads, [z]).reshape(len(a.constraints), n)
        assert np.linalg.matrix_rank(J) == len(a.constraints)


def test_squared_factor_of_a_crossing_product_is_analysed_branch_by_branch():
    """``(x - 1)^2 (y - 2) = 0``: the square-free part ``(x - 1)(y - 2)`` is the union of the lines
    ``x = 1`` and ``y = 2``, which cross at ``(1, 2)`` where its gradient ``(y - 2, x - 1)``
    vanishes: after regularisation each line is a component of its own, a particle on a line
    under gravity (``p_lambda``, the line, the normal velocity, the ``lambda`` equation: 4
    second class, ``(6 - 4)/2 = 1`` degree of freedom), with a warning naming both."""
    L = dirac.Lagrangian.from_strings("corner", ["x", "y"], "(x_dot**2 + y_dot**2)/2 - y", ["(x - 1)**2*(y - 2)"])
    with pytest.warns(dirac.DiracWarning, match=r"crossing branches"):
        analysis = dirac.analyze(L)
    assert sorted(c.condition for c in analysis.components) == ["x - 1 = 0", "y - 2 = 0"]
    for part in analysis.components:
        assert (len(part.analysis.second_class), part.analysis.physical_degrees_of_freedom) == (4, 1)


def test_expanded_product_met_in_the_chain_is_refused_with_its_branches():
    """``L = x_dot z_dot + y (x z + z)``: ``p_y = 0`` is primary, ``H_c = p_x p_z - y (x z + z)``,
    and ``{p_y, H_c} = x z + z = z (x + 1)``: the union of the branches ``z = 0`` and
    ``x = -1``, which meet at ``(x, z) = (-1, 0)``, written expanded. The chain factors its
    small new constraints, so the crossing is found whichever branch the sample points fall
    on (never a rank taken from the points of one branch only); the refusal names both."""
    L = dirac.Lagrangian.from_strings("branches", ["x", "y", "z"], "x_dot*z_dot + y*(x*z + z)")
    with pytest.raises(AnalysisError, match=r"x\*z \+ z = 0 is irregular.*branches z = 0 and x \+ 1 = 0"):
        dirac.analyze(L)


def test_quadrics_of_rank_three_or_more_are_irreducible_without_factorisation():
    """``f = z^T S z``, ``z = (v, 1)``: a product of two linear factors (even complex) has
    ``rank S <= 2``, so rank >= 3 proves ``f`` irreducible (by hand: ``x^2 + y^2 - l^2`` has
    ``S = diag(1, 1, -l^2)``, rank 3; ``(x - y)(p - q) + z w``, rank 4; ``x y + 1``, rank 3).
    Rank <= 2 is "not shown" and goes to factorisation: ``x^2 - y^2 = (x - y)(x + y)``
    (rank 2) is split, ``x^2 + y^2`` (rank 2, irreducible over the rationals) is not."""
    from dirac.analysis.legendre.regularity import _irreducible_quadric, factors

    x, y, z, w, p, q, l, m = sympy.symbols("x y z w p q l m", real=True)
    V = [x, y, z, w, p, q]
    assert _irreducible_quadric(x**2 + y**2 - l**2, V)
    assert _irreducible_quadric(sympy.expand((x - y) * (p - q) + z * w), V)
    assert _irreducible_quadric(x * y + 1, V)
    assert not _irreducible_quadric(x**2 - y**2, V)
    assert not _irreducible_quadric(x**2 + y**2, V)
    assert not _irreducible_quadric(sympy.expand(x * y * z), V)  # degree 3: not this test
    assert set(factors(x**2 - y**2, V, 60)) == {x - y, x + y}
    assert factors(x**2 + y**2, V, 60) == [x**2 + y**2]
    # with a parameter in the coefficients: (x + y - l)(x - y + 2)/m has rank 2 and is split
    split = factors(sympy.expand((x + y - l) * (x - y + 2) / m), V, 60)
    assert {sympy.expand(f) for f in split} == {x + y - l, x - y + 2}
