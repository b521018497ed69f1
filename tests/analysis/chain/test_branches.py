"""Constraints that are unions of branches: crossings refused, disjoint branches followed one by one.

Each test states the hand derivation it checks (canonical bracket ``{q, p} = 1``).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import sympy

import dirac
import dirac.analysis.chain.constraint_chain as constraint_chain
from dirac.errors import AnalysisError, DiracWarning

GRAVITY = "(x_dot**2 + y_dot**2)/2 - y"


def test_two_crossing_lines_are_analysed_as_two_components(run_cli, tmp_path):
    """``x^2 - y^2 = 0`` is the union of the lines ``x - y = 0`` and ``x + y = 0``, which cross at
    the origin, where the gradient ``(2x, -2y)`` vanishes. On either line alone the motion is
    a bead on a straight wire under gravity (``p_lambda``, the line, the velocity along its
    normal, the equation fixing ``lambda``: 4 second class, ``(6 - 4)/2 = 1`` degree of
    freedom), but at the crossing the multiplier is free; the union has no single regular
    surface, so each line is analysed as a component of its own (found by factorisation of
    the expanded constraint), with a warning naming both."""
    L = dirac.Lagrangian.from_strings("cross", ["x", "y"], GRAVITY, ["x**2 - y**2"])
    with pytest.warns(DiracWarning, match=r"2 crossing branches.*x \+ y = 0.*x - y = 0"):
        analysis = dirac.analyze(L)
    assert sorted(c.condition for c in analysis.components) == ["x + y = 0", "x - y = 0"]
    for part in analysis.components:
        a = part.analysis
        assert [len(s) for s in a.stages] == [1, 1, 1, 1]
        assert len(a.second_class) == 4 and a.first_class == [] and a.physical_degrees_of_freedom == 1
    path = tmp_path / "cross.toml"
    path.write_text('[system]\nname = "cross"\ncoordinates = ["x", "y"]\n'
                    f'lagrangian = "{GRAVITY}"\nconstraints = ["x**2 - y**2"]\n')
    status, out, err = run_cli("analyze", str(path), "--json")
    listed = json.loads(out)["components"]
    assert status == 0 and err.startswith("warning:")
    assert sorted((c["condition"], len(c["second_class"]), c["physical_degrees_of_freedom"]) for c in listed) == [
        ("x + y = 0", 4, 1), ("x - y = 0", 4, 1)]
    status, out, _ = run_cli("analyze", str(path))
    assert status == 0 and "components of the constraint surface:" in out and "  - x - y = 0: stages 1+1+1+1" in out


def test_either_line_alone_is_a_bead_on_a_wire():
    """The branch ``x - y = 0`` by itself: the hand count of the test above (4 second class, 1)."""
    a = dirac.analyze(dirac.Lagrangian.from_strings("line", ["x", "y"], GRAVITY, ["x - y"]))
    assert [len(s) for s in a.stages] == [1, 1, 1, 1]
    assert len(a.second_class) == 4 and a.first_class == [] and a.physical_degrees_of_freedom == 1


def test_sample_points_stay_off_the_crossing_when_the_product_is_not_factored(monkeypatch):
    """With factorisation switched off the chain meets ``x^2 - y^2`` as one constraint. Its
    surface (with ``x p_x - y p_y`` and the ``lambda`` equation) contains the whole crossing
    ``x = y = 0, p_x = +-p_y`` where the gradient of ``x^2 - y^2`` vanishes; Gauss-Newton
    converges next to it (gradient ~1e-6, row-normalised it looks regular). Such points are
    singular and dropped: every sample point has ``|x| = |y|`` well away from 0, and on the
    lines the structure is the bead's (4 second class, 1 degree of freedom)."""
    monkeypatch.setattr(constraint_chain, "FACTOR_TERMS", 0)
    monkeypatch.setattr(constraint_chain, "MAX_FACTOR_TERMS", 0)
    a = dirac.analyze(dirac.Lagrangian.from_strings("cross", ["x", "y"], GRAVITY, ["x**2 - y**2"]))
    x, y = (a.phase_space.index(a.symbols[n]) for n in ("x", "y"))
    for z in a._points:
        assert abs(abs(z[x]) - abs(z[y])) < 1e-8 and abs(z[x]) > 1e-3
    assert len(a.second_class) == 4 and a.physical_degrees_of_freedom == 1


def test_expanded_product_of_two_crossing_planes_is_analysed_plane_by_plane():
    """``(w + x - 2z + 2)(2w + x + 2y + z - 4)`` written expanded (13 terms): two hyperplanes of
    ``(w, x, y, z)`` with independent normals, which meet in a plane where the gradient of the
    product vanishes. Each plane is a component: a particle on a hyperplane of R^4 under
    gravity (``p_lambda``, the plane, the normal velocity, the ``lambda`` equation: 4 second
    class, ``(10 - 4)/2 = 3`` degrees of freedom)."""
    w, x, y, z = sympy.symbols("w x y z")
    chi = str(sympy.expand((w + x - 2 * z + 2) * (2 * w + x + 2 * y + z - 4)))
    L = dirac.Lagrangian.from_strings(
        "planes", ["w", "x", "y", "z"], "(w_dot**2 + x_dot**2 + y_dot**2 + z_dot**2)/2 - y", [chi]
    )
    with pytest.warns(DiracWarning, match=r"crossing branches"):
        analysis = dirac.analyze(L)
    assert sorted(c.condition for c in analysis.components) == ["2*w + x + 2*y + z - 4 = 0", "w + x - 2*z + 2 = 0"]
    for part in analysis.components:
        assert (len(part.analysis.second_class), part.analysis.physical_degrees_of_freedom) == (4, 3)


FIRST_ORDER = "-3*x**2*x_dot - x*z**2/2 + x_dot*z - y**2*y_dot - 2*y*y_dot - y*z**2 + y*z*z_dot"


def test_spurious_branch_without_motion_is_dropped():
    """``L = a(q).q_dot - V`` with ``a = (z - 3x^2, -y^2 - 2y, y z)``, ``V = x z^2/2 + y z^2``.

    Primary ``phi = p - a``; ``{phi_i, phi_j} = F_ij = d_i a_j - d_j a_i``: ``F_xy = 0``,
    ``F_xz = -1``, ``F_yz = z``; ``{phi_i, H_c} = -d_i V = (-z^2/2, -z^2, -(x + 2y) z)``.
    Consistency: the x row gives ``u_3 = -z^2/2``, the z row ``u_1 = z u_2 + (x + 2y) z``,
    the y row ``-z^2 + z u_3 = -z^2 (1 + z/2) = 0``: ``z = 0`` or ``z = -2``. On ``z = -2``
    the constraint's own consistency ``z_dot = u_3 = 0`` contradicts ``u_3 = -z^2/2 = -2``
    (the Euler-Lagrange equation ``z_dot = -z^2/2``): no motion, the branch is dropped.
    On ``z = 0``: ``u_3 = 0``, ``u_1 = 0``, ``u_2`` free, and the chain ends. Brackets of
    ``(phi_1, phi_2, phi_3, z)`` on ``z = 0``: ``{phi_1, phi_3} = -1``, ``{phi_3, z} = -1``,
    the rest 0: rank 2, so 2 second class, 2 first class (``phi_2`` and
    ``phi_1 + z = p_x + 3x^2``), ``(6 - 2*2 - 2)/2 = 0`` degrees of freedom.
    """
    L = dirac.Lagrangian.from_strings("spur", ["x", "y", "z"], FIRST_ORDER)
    a = dirac.analyze(L)
    s = a.symbols
    x, y, z, px, py, pz = (s[n] for n in ("x", "y", "z", "p_x", "p_y", "p_z"))
    assert [len(stage) for stage in a.stages] == [3, 1]
    assert a.stages[1] == [z]
    expected = [px + 3 * x**2 - z, py + y**2 + 2 * y, pz - y * z]
    assert all(any(sympy.expand(c - e) == 0 for c in a.stages[0]) for e in expected)
    assert len(a.first_class) == 2 and len(a.second_class) == 2
    assert a.bracket_matrix_rank == 2
    assert a.physical_degrees_of_freedom == 0
    assert [u.name for u in a.undetermined_multipliers] == ["u_2"]
    assert sympy.expand(a.multipliers["u_1"].subs(z, 0)) == 0 and sympy.expand(a.multipliers["u_3"].subs(z, 0)) == 0
    assert any("z + 2 = 0" in n and "dropped" in n for n in a.notes)
    for seed in range(6):
        assert abs(a.surface_point(seed=seed)["z"]) < 1e-8
    iz = a.phase_space.index(z)
    assert all(abs(p[iz]) < 1e-8 for p in a._points)


def test_disjoint_branches_of_different_structure_are_refused():
    """``L = x_dot z_dot + y z (z - 1) + x^2 z/2``: ``p_y = 0`` primary,
    ``H_c = p_x p_z - y z (z - 1) - x^2 z/2``; ``{p_y, H_c} = z (z - 1)``, branches ``z = 0``
    and ``z = 1``. Both have ``{z, H_T} = p_x``: ``p_x = 0``; then ``{p_x, H_T} = x z``: on
    ``z = 0`` the chain ends (``p_y, z, p_x``, all first class, ``u`` free); on ``z = 1`` it
    goes on with ``x``, ``p_z`` (``{x, H_T} = p_z``), ``y`` (``{p_z, H_T} = y (2z - 1) + x^2/2``),
    ``y`` fixing ``u``: six second class. Two different systems: refused, naming both."""
    L = dirac.Lagrangian.from_strings("two", ["x", "y", "z"], "x_dot*z_dot + y*z*(z - 1) + x**2*z/2")
    with pytest.raises(AnalysisError, match=r"branches .*z - 1 = 0.*z = 0.*different structure") as caught:
        dirac.analyze(L)
    message = str(caught.value)
    assert "stages of sizes 1, 1, 1, 1, 1, 1" in message and "stages of sizes 1, 1, 1," in message


def test_disjoint_branches_of_the_same_structure_keep_the_union():
    """``x^2 - 1 = 0`` written expanded: the walls ``x = 1`` and ``x = -1`` never meet, and on
    each the motion is the bead's (4 second class, 1 degree of freedom): the union is one
    regular surface, analysed as such, and sample points lie on it."""
    a = dirac.analyze(dirac.Lagrangian.from_strings("walls", ["x", "y"], GRAVITY, ["x**2 - 1"]))
    assert [len(st) for st in a.stages] == [1, 1, 1, 1]
    assert len(a.second_class) == 4 and a.physical_degrees_of_freedom == 1
    ix = a.phase_space.index(a.symbols["x"])
    assert np.allclose(np.abs([p[ix] for p in a._points]), 1.0)
    assert any("same structure" in n for n in a.notes)


def test_crossing_branches_of_a_constraint_with_a_denominator_are_refused():
    """``L = -q1'^2 - q3 q1' q2' - q2'^2 - 2 q1' - 2 q1 q2'`` with ``q1 = 0`` (found by the
    random-Lagrangian invariants). By hand, with ``P = (p1 + 2, p2 + 2 q1)`` and
    ``W = [[-2, -q3], [-q3, -2]]``: ``H_c = (-P1^2 + q3 P1 P2 - P2^2)/(4 - q3^2) + lambda q1``, and
    ``p3_dot = 0`` demands ``psi = -(2 P1 - q3 P2)(q3 P1 - 2 P2)/(4 - q3^2)^2 = 0``: two branches
    that meet at ``P = 0``. On the first ``q1_dot = (q3 P2 - 2 P1)/(4 - q3^2)`` vanishes, on the
    second it does not (another stage): the structure differs, so no single answer is right.
    The quotient used to pass as irreducible (only polynomials were factored) and the chain
    answered for the first branch while the surface held both (H_T not tangent on the second).
    The refusal names both branches."""
    lagrangian = dirac.Lagrangian.from_strings(
        "random", ["q1", "q2", "q3"], "-q1_dot**2 - q3*q1_dot*q2_dot - q2_dot**2 - 2*q1_dot - 2*q1*q2_dot", ["q1"]
    )
    with pytest.raises(AnalysisError, match="union of the branches") as caught:
        dirac.analyze(lagrangian)
    p1, p2, q1, q3 = sympy.symbols("p_q1 p_q2 q1 q3", real=True)
    names = {"p_q1": p1, "p_q2": p2, "q1": q1, "q3": q3}
    P1, P2 = p1 + 2, p2 + 2 * q1
    listed = str(caught.value).split("union of the branches ", 1)[1].split(", which meet")[0].split(" and ")
    shown = [sympy.sympify(text.removesuffix(" = 0"), locals=names) for text in listed]
    for branch in (2 * P1 - q3 * P2, q3 * P1 - 2 * P2):
        assert any(sympy.expand(e - branch) == 0 or sympy.expand(e + branch) == 0 for e in shown)


BRANCHES = "-q3*q1_dot*q2_dot - q1*q1_dot*q3_dot - 2*q1*q1_dot - 2*q2_dot + 2*q1*q3"


def test_a_product_once_a_variable_fixed_at_the_same_stage_is_put_in_is_refused_by_its_branches():
    """``L = -q3 q1' q2' - q1 q1' q3' - 2 q1 q1' - 2 q2' + 2 q1 q3`` under ``q1 = 0`` (found by the
    random-Lagrangian invariants).

    By hand: ``p1 = -q3 q2' - q1 q3' - 2 q1``, ``p2 = -q3 q1' - 2``, ``p3 = -q1 q1'``, so
    ``phi = q1 (p2 + 2) - q3 p3`` is primary and ``H_c = -(p1 + 2 q1)(p2 + 2)/q3 - 2 q1 q3 +
    2 lambda q1``. Stage 2 is ``q1 = 0`` with ``{phi, H_c} = (p2 + 2)(p1 + 2 q1 - p2 - 2)/q3 - 2 q1
    q3``, irreducible, but ``(p2 + 2)(p1 - p2 - 2)/q3`` on ``q1 = 0``: two branches that meet.
    On ``p1 - p2 - 2 = 0`` the motion leaves ``q1 = 0`` (``q1' = -(p2 + 2)/q3 != 0``); before,
    the chain stopped there with both branches as one surface, its sample points all on that
    branch, and ``H_T`` was not tangent to it.
    """
    L = dirac.Lagrangian.from_strings("branches", ["q1", "q2", "q3"], BRANCHES, ["q1"])
    with pytest.raises(AnalysisError, match=r"branches p_q2 \+ 2 = 0 and p_q1 - p_q2 - 2 = 0, which meet.*--assume \"p_q2 \+ 2 = 0\""):
        dirac.analyze(L)


def test_the_consistent_branch_picked_by_an_assumption_against_the_hand_count():
    """On ``p2 + 2 = 0`` (the test above): ``p_lambda``, ``phi`` (``-q3 p3`` there), ``p2 + 2`` and
    ``q1`` have vanishing brackets with each other: 4 first class, ``(8 - 8)/2 = 0`` degrees of
    freedom."""
    L = dirac.Lagrangian.from_strings("branches", ["q1", "q2", "q3"], BRANCHES, ["q1"])
    a = dirac.analyze(L, assume=["p_q2 + 2 = 0"])
    assert (len(a.first_class), len(a.second_class), a.physical_degrees_of_freedom) == (4, 0, 0)
