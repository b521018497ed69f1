"""Lagrangians linear in the velocities (Hessian rank 0): first-order systems.

Chern–Simons oscillator (Dunne, Jackiw, Trugenberger), by hand,
``L = B/2 (x y_dot - y x_dot) - k/2 (x^2 + y^2)``:
  ``a = (-B y/2, B x/2)``, ``W = 0``, so both momenta are primary constraints
  ``phi_1 = p_x + B y/2``, ``phi_2 = p_y - B x/2``; ``H_c = k/2 (x^2 + y^2)``.
  ``C_12 = {phi_1, phi_2} = {p_x, -B x/2} + {B y/2, p_y} = B/2 + B/2 = B``: second class.
  Consistency: ``{phi_1, H_c} + u_2 B = -k x + B u_2 = 0`` and ``-k y - B u_1 = 0`` fix both
  multipliers; the chain has one stage; ``(4 - 2*0 - 2)/2 = 1`` degree of freedom (the
  plane ``(x, y)`` is the phase space). Dirac bracket
  ``{x, y}_D = -{x, phi_1} (C^{-1})_12 {phi_2, y} = -(1)(-1/B)(-1) = -1/B``; then
  ``x_dot = {x, y}_D dH/dy = -k y/B``, ``y_dot = k x/B`` (rotation at frequency k/B), which is
  the Euler–Lagrange equation ``B y_dot = dV/dx``.
Massless Landau problem in the Landau gauge with an electric force ``F`` along x,
``L = B x y_dot + F x``:
  ``phi_1 = p_x``, ``phi_2 = p_y - B x``, ``H_c = -F x``, ``C_12 = {p_x, -B x} = B``; the same
  ``{x, y}_D = -1/B`` as in the symmetric gauge (the bracket is gauge invariant), and the Hall
  drift ``x_dot = {x, y}_D dH/dy = 0``, ``y_dot = {y, x}_D dH/dx = -F/B``; consistency
  ``{p_x, H_c} + u_2 B = F + B u_2 = 0`` gives the same ``u_2 = y_dot = -F/B``.
"""

from __future__ import annotations

import json

import pytest
import sympy

import dirac

CHERN_SIMONS = "B/2*(x*y_dot - y*x_dot) - k/2*(x**2 + y**2)"


def _proportional(a, b) -> bool:
    ratio = sympy.cancel(sympy.sympify(a) / sympy.sympify(b))
    return bool(ratio.is_number and ratio != 0)


@pytest.fixture(scope="module")
def chern_simons():
    lagrangian = dirac.Lagrangian.from_strings("chern_simons", ["x", "y"], CHERN_SIMONS, parameters={"B": 1.5, "k": 0.7})
    return dirac.analyze(lagrangian)


@pytest.fixture(scope="module")
def landau():
    lagrangian = dirac.Lagrangian.from_strings("landau", ["x", "y"], "B*x*y_dot + F*x", parameters={"B": 2.0, "F": 0.3})
    return dirac.analyze(lagrangian)


def test_chern_simons_constraints_and_counts(chern_simons):
    s = chern_simons.symbols
    B, k = sympy.symbols("B k", real=True)
    assert chern_simons.hessian_rank == 0
    assert [len(stage) for stage in chern_simons.stages] == [2]
    primary = chern_simons.primary_constraints
    assert _proportional(primary[0], s["p_x"] + B * s["y"] / 2)
    assert _proportional(primary[1], s["p_y"] - B * s["x"] / 2)
    assert sympy.simplify(chern_simons.canonical_hamiltonian - k / 2 * (s["x"] ** 2 + s["y"] ** 2)) == 0
    C = sympy.Matrix(2, 2, lambda i, j: chern_simons.poisson_bracket(primary[i], primary[j]))
    assert C[0, 1] != 0 and sympy.simplify(C[0, 1] ** 2 - B**2) == 0
    assert len(chern_simons.second_class) == 2 and chern_simons.first_class == []
    assert chern_simons.physical_degrees_of_freedom == 1
    assert chern_simons.undetermined_multipliers == []
    assert chern_simons.multiplier_solution.null_vectors == []


def test_chern_simons_dirac_bracket_and_flow(chern_simons):
    s = chern_simons.symbols
    B, k = sympy.symbols("B k", real=True)
    assert sympy.simplify(chern_simons.dirac_bracket(s["x"], s["y"]) + 1 / B) == 0
    # the multipliers are the velocities: {x, H'} = x_dot = -k y/B, {y, H'} = k x/B
    H = chern_simons.multiplier_solution.first_class_hamiltonian
    assert sympy.simplify(chern_simons.poisson_bracket(s["x"], H) + k * s["y"] / B) == 0
    assert sympy.simplify(chern_simons.poisson_bracket(s["y"], H) - k * s["x"] / B) == 0
    flow = chern_simons.equations_of_motion([s["x"], s["y"]])
    assert sympy.simplify(flow[s["x"]] + k * s["y"] / B) == 0
    assert sympy.simplify(flow[s["y"]] - k * s["x"] / B) == 0


def test_landau_problem_bracket_is_gauge_invariant_and_drifts(landau):
    s = landau.symbols
    B, F = sympy.symbols("B F", real=True)
    assert landau.hessian_rank == 0
    assert _proportional(landau.primary_constraints[0], s["p_x"])
    assert _proportional(landau.primary_constraints[1], s["p_y"] - B * s["x"])
    assert sympy.simplify(landau.dirac_bracket(s["x"], s["y"]) + 1 / B) == 0
    assert landau.physical_degrees_of_freedom == 1
    H = landau.multiplier_solution.first_class_hamiltonian
    assert sympy.simplify(landau.poisson_bracket(s["x"], H)) == 0
    assert sympy.simplify(landau.poisson_bracket(s["y"], H) + F / B) == 0
    point = landau.surface_point({"x": 0.4, "y": -0.2})
    assert landau.dirac_bracket("x", "y", at=point) == pytest.approx(-1 / 2.0, rel=1e-12)


def test_rank_zero_note_says_how_the_constraints_were_found(chern_simons):
    assert any("rank 0" in note and "p - a(q) = 0" in note for note in chern_simons.notes)


def test_analyze_a_rank_zero_system_file(run_cli, tmp_path):
    """``dirac analyze`` on a system file of the Chern–Simons oscillator (B = 2, k = 1)."""
    path = tmp_path / "chern_simons.toml"
    path.write_text(
        '[system]\nname = "chern_simons"\ncoordinates = ["x", "y"]\nparameters = { B = 2.0, k = 1.0 }\n'
        f'lagrangian = "{CHERN_SIMONS}"\n',
        encoding="utf-8",
    )
    status, out, err = run_cli("analyze", str(path), "--param", "B=2", "--param", "k=1")
    assert status == 0, err
    assert "Hessian d2L/dq_dot2: rank 0 of 2" in out
    assert "physical degrees of freedom: (4 - 2*0 - 2)/2 = 1" in out
    status, out, err = run_cli("analyze", str(path), "--param", "B=2", "--param", "k=1", "--json")
    assert status == 0, err
    data = json.loads(out)
    assert data["hessian_rank"] == 0
    assert [len(stage["constraints"]) for stage in data["stages"]] == [2]
    # x_dot = -k y/B = -y/2 and y_dot = x/2: the multipliers of p_x + y and p_y - x (up to sign)
    x, y, p_x, p_y = sympy.symbols("x y p_x p_y", real=True)
    stage = [sympy.sympify(c, locals={"x": x, "y": y, "p_x": p_x, "p_y": p_y}) for c in data["stages"][0]["constraints"]]
    particular = data["multiplier_solution"]["particular"]
    assert data["multiplier_solution"]["null_vectors"] == []
    for name, constraint in zip(["u_1", "u_2"], stage):
        u = sympy.sympify(particular[name], locals={"x": x, "y": y})
        # {x, u phi} = u dphi/dp_x is the velocity that constraint contributes
        contribution = (u * sympy.diff(constraint, p_x), u * sympy.diff(constraint, p_y))
        if contribution[0] != 0:
            assert sympy.simplify(contribution[0] + y / 2) == 0
        else:
            assert sympy.simplify(contribution[1] - x / 2) == 0
    assert data["multipliers"] == particular
