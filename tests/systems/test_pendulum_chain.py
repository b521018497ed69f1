"""Planar pendulum in Cartesian coordinates: the four-stage chain of Sect. X, (205)-(217) (docs/conventions.md).

Hand derivation (L_ext = m/2 |q_dot|^2 - m g y - lambda chi, chi = x^2 + y^2 - l^2):
p = m q_dot, H_c = |p|^2/(2m) + m g y + lambda chi, H_T = H_c + u p_lambda.
  stage 1: p_lambda = 0;  {p_lambda, H_T} = -chi
  stage 2: chi = x^2 + y^2 - l^2
  stage 3: {chi, H_c} = 2 (x p_x + y p_y)/m
  stage 4: {stage 3, H_c} = 2|p|^2/m^2 - 2 g y - 4 lambda (x^2 + y^2)/m
           => lambda = (|p|^2/m - m g y) / (2 (x^2 + y^2)) = (|p|^2/m - m g y)/(2 l^2)
  consistency of stage 4 fixes u = lambda_dot ≈ -3 g p_y / (2 l^2).
All four are second class; (6 - 4)/2 = 1 degree of freedom. With C_ab on the surface the
Dirac bracket is that of a particle on the circle: {x, p_x}_D = 1 - x^2/l^2,
{x, p_y}_D = -x y / l^2, {x, y}_D = 0.
"""

from __future__ import annotations

import pytest
import sympy

import dirac


@pytest.fixture(scope="module")
def analysis():
    return dirac.analyze(dirac.load_system("pendulum"))


def _sym(analysis, *names):
    s = {**analysis.symbols, **{p.name: p for p in analysis.parameters}}
    return [s[n] for n in names]


def test_four_stages_of_one_constraint(analysis):
    assert [len(stage) for stage in analysis.stages] == [1, 1, 1, 1]
    x, y, px, py, lam, plam, m, g, l = _sym(analysis, "x", "y", "p_x", "p_y", "lambda_1", "p_lambda_1", "m", "g", "l")
    expected = [
        plam,
        x**2 + y**2 - l**2,
        2 * (x * px + y * py) / m,
        2 * (px**2 + py**2) / m**2 - 2 * g * y - 4 * lam * (x**2 + y**2) / m,
    ]
    for (found,), hand in zip(analysis.stages, expected):
        ratio = sympy.cancel(found / hand)
        assert ratio.is_number and ratio != 0, (found, hand)


def test_fourth_stage_fixes_lambda(analysis):
    x, y, px, py, lam, m, g, l = _sym(analysis, "x", "y", "p_x", "p_y", "lambda_1", "m", "g", "l")
    (solution,) = sympy.solve(analysis.stages[3][0], lam)
    hand = ((px**2 + py**2) / m - m * g * y) / (2 * (x**2 + y**2))
    assert sympy.simplify(solution - hand) == 0
    # on the surface x^2 + y^2 = l^2 this is the textbook tension multiplier
    assert sympy.simplify(hand.subs(y**2, l**2 - x**2) - ((px**2 + py**2) / m - m * g * y) / (2 * l**2)) == 0


def test_classes_dof_and_multiplier(analysis):
    assert analysis.first_class == []
    assert len(analysis.second_class) == 4
    assert analysis.physical_degrees_of_freedom == 1
    assert [u.name for u in analysis.primary_multipliers] == ["u_1"]
    assert set(analysis.multipliers) == {"u_1"}
    point = analysis.surface_point(seed=3)
    x, y, px, py = point["x"], point["y"], point["p_x"], point["p_y"]
    g, l, m = 9.81, 1.0, 1.0
    # the point is on the hand-derived surface
    assert x**2 + y**2 == pytest.approx(l**2, abs=1e-10)
    assert x * px + y * py == pytest.approx(0.0, abs=1e-10)
    assert point["lambda_1"] == pytest.approx(((px**2 + py**2) / m - m * g * y) / (2 * l**2), rel=1e-9)
    u = analysis.multipliers["u_1"]
    values = {analysis.symbols[k]: v for k, v in point.items()}
    values.update({p: analysis.lagrangian.parameters[p] for p in analysis.parameters})
    assert float(u.subs(values)) == pytest.approx(-3 * g * py / (2 * l**2), rel=1e-9)


def test_dirac_bracket_is_the_circle_bracket(analysis):
    x, y, px, py = _sym(analysis, "x", "y", "p_x", "p_y")
    exact_xpx = analysis.dirac_bracket(x, px)
    exact_xpy = analysis.dirac_bracket(x, py)
    assert analysis.dirac_bracket(x, y) == 0
    assert analysis.poisson_bracket(x, px) == 1
    for seed in range(3):
        point = analysis.surface_point(seed=seed)
        X, Y, l = point["x"], point["y"], 1.0
        values = {analysis.symbols[k]: v for k, v in point.items()}
        values.update({p: analysis.lagrangian.parameters[p] for p in analysis.parameters})
        assert float(exact_xpx.subs(values)) == pytest.approx(1 - X**2 / l**2, abs=1e-10)
        assert float(exact_xpy.subs(values)) == pytest.approx(-X * Y / l**2, abs=1e-10)
        assert analysis.dirac_bracket("x", "p_x", at=point) == pytest.approx(1 - X**2 / l**2, abs=1e-10)
        assert analysis.dirac_bracket(x, py, at=point) == pytest.approx(-X * Y / l**2, abs=1e-10)
    # constraints are Casimirs of the Dirac bracket
    point = analysis.surface_point(seed=7)
    for c in analysis.second_class:
        assert analysis.dirac_bracket(c, px**2 + x * py, at=point) == pytest.approx(0.0, abs=1e-9)


def test_numeric_bracket_is_fast_in_loops(analysis):
    import time

    points = [analysis.surface_point(seed=s) for s in range(5)]
    analysis.dirac_bracket("x", "p_x", at=points[0])  # compile once
    start = time.process_time()  # CPU time: another test worker on the same cores does not count
    for _ in range(40):
        for point in points:
            analysis.dirac_bracket("x", "p_x", at=point)
    assert (time.process_time() - start) / 200 < 0.05


def test_fixed_parameters_stay_exact():
    analysis = dirac.analyze(dirac.load_system("pendulum", l=2.0, m=0.5))
    assert [p.name for p in analysis.parameters] == ["g"]
    x, y = analysis.symbols["x"], analysis.symbols["y"]
    assert sympy.cancel(analysis.stages[1][0] / (x**2 + y**2 - 4)).is_number


def test_equations_of_motion_on_the_surface(analysis):
    eom = analysis.equations_of_motion()
    point = analysis.surface_point(seed=11)
    values = {analysis.symbols[k]: v for k, v in point.items()}
    values.update({p: analysis.lagrangian.parameters[p] for p in analysis.parameters})
    X, Y, PX, PY = point["x"], point["y"], point["p_x"], point["p_y"]
    g, m, l = 9.81, 1.0, 1.0
    tension = ((PX**2 + PY**2) / m - m * g * Y) / (2 * l**2)
    assert float(eom[analysis.symbols["x"]].subs(values)) == pytest.approx(PX / m, abs=1e-9)
    assert float(eom[analysis.symbols["p_x"]].subs(values)) == pytest.approx(-2 * tension * X, abs=1e-9)
    assert float(eom[analysis.symbols["p_y"]].subs(values)) == pytest.approx(-m * g - 2 * tension * Y, abs=1e-9)


def test_hamiltonians(analysis):
    x, y, px, py, lam, plam, m, g, l = _sym(analysis, "x", "y", "p_x", "p_y", "lambda_1", "p_lambda_1", "m", "g", "l")
    hand = (px**2 + py**2) / (2 * m) + m * g * y + lam * (x**2 + y**2 - l**2)
    assert sympy.simplify(analysis.canonical_hamiltonian - hand) == 0
    (u,) = analysis.primary_multipliers
    assert sympy.simplify(analysis.total_hamiltonian - hand - u * plam) == 0


def test_reports_render(analysis):
    latex = analysis._repr_latex_()
    assert latex.startswith("$$") and r"\begin{aligned}" in latex and "p_{\\lambda_{1}} = 0" in latex
    text = analysis.to_text()
    assert "stage 4: 1 constraint(s)" in text and "physical degrees of freedom" in text
    data = analysis.to_json()
    assert data["physical_degrees_of_freedom"] == 1 and data["hessian_rank"] == 2
