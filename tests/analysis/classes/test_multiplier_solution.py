"""Multipliers in general form ``u = U + v_a V_a`` (Dirac; Henneaux–Teitelboim Sect. 1.2.2).

The pendulum constraint given twice, ``chi_1 = chi_2 = x^2 + y^2 - l^2`` with
``L = m/2 (x_dot^2 + y_dot^2) - m g y`` (by hand):
  ``H_c = p^2/(2m) + m g y + (lambda_1 + lambda_2) chi``; the primary constraints
  ``p_lambda_1``, ``p_lambda_2`` give the same chain as the pendulum with
  ``lambda = lambda_1 + lambda_2``: ``chi``, ``psi_3 = 2 (x p_x + y p_y)/m`` and
  ``psi_4 = 2 g y + 4 lambda r^2/m - 2 p^2/m^2`` (``r^2 = x^2 + y^2``). The last consistency
  condition is ``{psi_4, H_c} + (u_1 + u_2) 4 r^2/m = 0`` with
  ``{psi_4, H_c} = 6 g p_y/m + 16 lambda (x p_x + y p_y)/m^2``, so only the sum is fixed:
  ``u_1 + u_2 = (-3 g p_y - 8 lambda (x p_x + y p_y)/m) / (2 r^2)``,
  and the null space of ``A = (4 r^2/m, 4 r^2/m)`` is spanned by ``V = (1, -1)`` (up to a
  factor): neither multiplier is fixed alone, one is free, and ``p_lambda_1 - p_lambda_2`` is
  the first-class primary combination. Classes: 1 first class, 4 second class,
  ``(8 - 2 - 4)/2 = 1`` degree of freedom, as for the pendulum.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import sympy

import dirac

PENDULUM = "m/2*(x_dot**2 + y_dot**2) - m*g*y"
TWICE = ["x**2 + y**2 - l**2", "x**2 + y**2 - l**2"]


@pytest.fixture(scope="module")
def doubled():
    lagrangian = dirac.Lagrangian.from_strings(
        "doubled_pendulum", ["x", "y"], PENDULUM, parameters={"m": 1.3, "g": 9.81, "l": 0.8}, constraints=TWICE
    )
    return dirac.analyze(lagrangian)


def _sum_by_hand(s: dict) -> sympy.Expr:
    m, g = sympy.symbols("m g", real=True)
    lam = s["lambda_1"] + s["lambda_2"]
    radial = s["x"] * s["p_x"] + s["y"] * s["p_y"]
    return (-3 * g * s["p_y"] - 8 * lam * radial / m) / (2 * (s["x"] ** 2 + s["y"] ** 2))


def test_doubled_constraint_fixes_only_the_sum(doubled):
    s = doubled.symbols
    solution = doubled.multiplier_solution
    assert [len(stage) for stage in doubled.stages] == [2, 1, 1, 1]
    assert doubled.multipliers == {}
    assert [u.name for u in doubled.undetermined_multipliers] == ["u_1", "u_2"]
    assert len(solution.null_vectors) == 1 and len(solution.free) == 1
    V = solution.null_vectors[0]
    assert V["u_1"] != 0 and sympy.simplify(V["u_1"] + V["u_2"]) == 0
    general = solution.general
    total = sympy.simplify(general["u_1"] + general["u_2"] - _sum_by_hand(s))
    assert total == 0  # the sum is fixed, whatever v_1 is
    combination = solution.first_class_primary[0]
    assert sympy.simplify(combination / (s["p_lambda_1"] - s["p_lambda_2"])).is_number
    assert len(doubled.first_class) == 1 and len(doubled.second_class) == 4
    assert doubled.physical_degrees_of_freedom == 1


def test_total_hamiltonian_keeps_every_constraint_for_any_free_multiplier(doubled):
    """``{Phi, H' + v phi_1st} ≈ 0`` for every constraint and several values of ``v``."""
    solution = doubled.multiplier_solution
    H = solution.total_hamiltonian
    (v,) = solution.free
    rates = [doubled.poisson_bracket(c, H) for c in doubled.constraints]
    variables = list(doubled.phase_space)
    params = sympy.symbols("m g l", real=True)
    values = dict(zip(params, (1.3, 9.81, 0.8)))
    rates_fn = sympy.lambdify([*variables, v], [r.subs(values) for r in rates])
    for seed, v_value in [(1, 0.0), (2, 3.7), (3, -11.0)]:
        point = doubled.surface_point(seed=seed)
        got = np.array(rates_fn(*[point[x.name] for x in variables], v_value), dtype=float)
        assert np.max(np.abs(got)) < 1e-8
    # while the printed form of old, H_c + u_1 p_lambda_1 + u_2 p_lambda_2 with both "free",
    # leaves the surface: u_1 = 1, u_2 = 0 moves psi_4 (it is not a solution)
    naive = doubled.canonical_hamiltonian + doubled.primary_constraints[0]
    last = doubled.stages[-1][0]
    rate = sympy.lambdify(variables, doubled.poisson_bracket(last, naive).subs(values))
    point = doubled.surface_point(seed=4)
    assert abs(rate(*[point[x.name] for x in variables])) > 1e-3


def test_reports_show_the_general_solution(doubled):
    text = doubled.to_text()
    assert "u_1: not fixed alone (see the general solution)" in text
    assert "general solution u = U + v_1*V_1 (v_1 free):" in text
    assert "null vector V_1 = (-1, 1) of (u_1, u_2)" in text
    hamiltonian_line = next(line for line in text.splitlines() if line.startswith("total Hamiltonian"))
    assert "v_1*(-p_lambda_1 + p_lambda_2)" in hamiltonian_line
    assert "u_1*" not in hamiltonian_line and "u_2*" not in hamiltonian_line
    latex = doubled.to_latex()
    assert r"H_T &= H_c +" in latex and r"v_{1}" in latex and r"\text{undetermined" not in latex


def test_json_of_the_doubled_constraint(run_cli, tmp_path):
    path = tmp_path / "doubled.toml"
    path.write_text(
        '[system]\nname = "doubled"\ncoordinates = ["x", "y"]\nparameters = { m = 1.0, g = 9.81, l = 1.0 }\n'
        f'lagrangian = "{PENDULUM}"\nconstraints = {json.dumps(TWICE)}\n',
        encoding="utf-8",
    )
    status, out, err = run_cli("analyze", str(path), "--json")
    assert status == 0, err
    data = json.loads(out)
    assert data["multipliers"] == {"u_1": "undetermined", "u_2": "undetermined"}
    solution = data["multiplier_solution"]
    assert set(solution) >= {"particular", "null_vectors"}
    assert len(solution["null_vectors"]) == 1
    names = {name: sympy.Symbol(name, real=True) for name in data["phase_space"] + data["parameters"]}
    V = {k: sympy.sympify(e, locals=names) for k, e in solution["null_vectors"][0].items()}
    assert set(V) == {"u_1", "u_2"} and V["u_1"] != 0 and V["u_1"] + V["u_2"] == 0
    U = {k: sympy.sympify(e, locals=names) for k, e in solution["particular"].items()}
    assert sympy.simplify(U["u_1"] + U["u_2"] - _sum_by_hand(names)) == 0


def test_fixed_multipliers_are_the_particular_solution():
    """Pendulum: ``u_1`` is fixed alone, so ``U = u`` and there is no null vector."""
    analysis = dirac.analyze(dirac.load_system("pendulum"))
    solution = analysis.multiplier_solution
    assert solution.null_vectors == [] and solution.free == ()
    assert solution.particular == analysis.multipliers
    assert analysis.to_json()["multiplier_solution"]["null_vectors"] == []


def test_a_free_multiplier_is_a_unit_null_vector():
    """gauge_system: ``{p_z, phi} = 0`` for every constraint, so ``U = 0`` and ``V_1 = e_1``."""
    analysis = dirac.analyze(dirac.load_system("gauge_system"))
    solution = analysis.multiplier_solution
    assert solution.particular == {"u_1": 0}
    assert solution.null_vectors == [{"u_1": 1}]
    assert analysis.to_json()["multipliers"] == {"u_1": "undetermined"}
    assert "u_1: undetermined (gauge freedom)" in analysis.to_text()
