"""Gauge fixing of the Christ-Lee model (built-in gauge_system, xi called z), against hand derivations.

Constraints: p_z = 0 (primary), J = y p_x - x p_y = 0 (Gauss law), both first class;
H_c = (p_x^2 + p_y^2)/2 + k r^2/2 + z J, H_T = H_c + u p_z.

Gauge A, "y = 0 with z-fixing": chi_1 = y, chi_2 = p_y - x z (= y_dot, the preservation of
chi_1). {y, J} = x, {p_y - x z, p_z} = -x: full rank for x != 0. The preservation of chi_2
fixes u. On the surface y = 0, J = -x p_y = 0 gives p_y = 0 and then z = 0: the reduced
space is (x, p_x) with dx ^ dp_x, so {x, p_x}_D = 1 and p_y, y, z, p_z have vanishing brackets.

Gauge B, "z = 0 with its companion y - x": {z, p_z} = 1, {y - x, J} = x + y (!= 0 off the
origin); z_dot = u = 0 fixes u; d(y - x)/dt = p_y - p_x - z(x + y) vanishes on the surface
(J = x (p_x - p_y) = 0 with x = y). Surface: x = y = s, p_x = p_y = pi, z = p_z = 0, with
dx ^ dp_x + dy ^ dp_y = 2 ds ^ dpi: {x, p_x}_D = {x, p_y}_D = 1/2, {x, y}_D = 0.

Gauge-invariant functions have the same bracket in both gauges, equal to the Poisson
bracket: {r^2, x.p} = 2 r^2 (A: {x^2, x p_x} = 2 x^2; B: {2 s^2, 2 s pi}_D = 4 s^2).
"""

from __future__ import annotations

import json

import pytest
import sympy

import dirac


@pytest.fixture(scope="module")
def christ_lee():
    return dirac.analyze(dirac.load_system("gauge_system"))


@pytest.fixture(scope="module")
def gauge_a(christ_lee):
    return christ_lee.fix_gauge(["y", "p_y - x*z"])


@pytest.fixture(scope="module")
def gauge_b(christ_lee):
    return christ_lee.fix_gauge(["z", "y - x"])


def _weakly(analysis, expr, value, count=3):
    """``expr`` equals ``value`` at points of the gauge-fixed surface (parameters at defaults)."""
    expr = sympy.sympify(expr).subs({p: v for p, v in analysis.lagrangian.parameters.items() if v is not None})
    for seed in range(count):
        point = analysis.surface_point(seed=seed)
        got = float(expr.subs({analysis.symbols[n]: v for n, v in point.items()}))
        target = float(sympy.sympify(value).subs({analysis.symbols[n]: v for n, v in point.items()}))
        assert got == pytest.approx(target, rel=1e-9, abs=1e-9), (expr, point)


@pytest.mark.parametrize("which", ["a", "b"])
def test_the_gauge_is_fixed_completely(which, christ_lee, gauge_a, gauge_b):
    fixed = {"a": gauge_a, "b": gauge_b}[which]
    assert fixed.first_class == []
    assert len(fixed.second_class) == 4
    assert fixed.physical_degrees_of_freedom == christ_lee.physical_degrees_of_freedom == 1
    assert fixed.undetermined_multipliers == []
    assert fixed.gauge_generators == []
    assert christ_lee.first_class and christ_lee.gauge_conditions == ()  # the original is unchanged


def test_dirac_brackets_in_gauge_a(gauge_a):
    s = gauge_a.symbols
    _weakly(gauge_a, gauge_a.dirac_bracket("x", "p_x"), 1)
    for other in ("y", "z", "p_y", "p_z"):
        _weakly(gauge_a, gauge_a.dirac_bracket("x", other), 0)
        _weakly(gauge_a, gauge_a.dirac_bracket("p_x", other), 0)
    r2, xp = s["x"] ** 2 + s["y"] ** 2, s["x"] * s["p_x"] + s["y"] * s["p_y"]
    _weakly(gauge_a, gauge_a.dirac_bracket(r2, xp), 2 * r2)
    point = gauge_a.surface_point({"x": 0.7, "p_x": -0.4})
    assert point["y"] == pytest.approx(0, abs=1e-12) and point["z"] == pytest.approx(0, abs=1e-12)
    assert gauge_a.dirac_bracket("x", "p_x", at=point) == pytest.approx(1.0, rel=1e-12)
    # the multiplier of p_z, from the preservation of p_y - x z: weakly zero here (z = 0 stays)
    _weakly(gauge_a, gauge_a.multipliers["u_1"], 0)


def test_dirac_brackets_in_gauge_b(gauge_b):
    s = gauge_b.symbols
    for a, b in (("x", "p_x"), ("x", "p_y"), ("y", "p_x"), ("y", "p_y")):
        _weakly(gauge_b, gauge_b.dirac_bracket(a, b), sympy.Rational(1, 2))
    _weakly(gauge_b, gauge_b.dirac_bracket("x", "y"), 0)
    _weakly(gauge_b, gauge_b.dirac_bracket("p_x", "p_y"), 0)
    r2, xp = s["x"] ** 2 + s["y"] ** 2, s["x"] * s["p_x"] + s["y"] * s["p_y"]
    _weakly(gauge_b, gauge_b.dirac_bracket(r2, xp), 2 * r2)
    point = gauge_b.surface_point({"x": 0.5, "p_x": 0.3})
    assert point["y"] == pytest.approx(0.5) and point["p_y"] == pytest.approx(0.3)
    assert gauge_b.dirac_bracket("x", "p_x", at=point) == pytest.approx(0.5, rel=1e-12)
    assert gauge_b.multipliers["u_1"] == 0  # z_dot = u and z = 0


def test_partial_fixing_says_which_first_class_constraints_remain(christ_lee):
    """z = 0 alone fixes p_z (and u = 0); the Gauss law stays first class."""
    fixed = christ_lee.fix_gauge(["z"])
    s = fixed.symbols
    [left] = fixed.first_class
    assert sympy.cancel(left / (s["y"] * s["p_x"] - s["x"] * s["p_y"])).is_number
    assert fixed.physical_degrees_of_freedom == 1
    assert fixed.multipliers["u_1"] == 0
    assert any("partial gauge fixing" in n and str(left) in n for n in fixed.notes)
    assert "remains after the gauge conditions" in fixed.to_text()


def test_a_condition_that_fixes_nothing_is_refused(christ_lee):
    """x^2 + y^2 commutes with p_z and with the rotation generator J."""
    with pytest.raises(dirac.InputError, match=r"'x\*\*2 \+ y\*\*2' fixes nothing.*p_z.*p_x\*y - p_y\*x"):
        christ_lee.fix_gauge(["x**2 + y**2"])


def test_a_condition_not_preserved_in_time_names_its_derivative(christ_lee):
    """y alone: y_dot = p_y - x z, into which no multiplier enters."""
    with pytest.raises(dirac.InputError, match=r"'y' is not preserved in time.*p_y - x\*z"):
        christ_lee.fix_gauge(["y"])


def test_unknown_names_and_time_dependence(christ_lee):
    with pytest.raises(dirac.InputError, match=r"unknown name 'yy' \(did you mean 'y'"):
        christ_lee.fix_gauge(["yy"])
    with pytest.raises(dirac.InputError, match="time-dependent gauge"):
        christ_lee.fix_gauge(["x - t"])


def test_no_gauge_freedom_is_refused():
    pendulum = dirac.analyze(dirac.load_system("pendulum"))
    with pytest.raises(dirac.InputError, match="no first-class constraints"):
        pendulum.fix_gauge(["x"])


def test_einbein_gauge_fixes_the_einbein_only():
    """relativistic_particle with e = 1: {e - 1, p_e} = 1 fixes p_e, e_dot = u = 0; the mass
    shell stays first class (its gauge, x^0 = tau, needs explicit time)."""
    particle = dirac.analyze(dirac.load_system("relativistic_particle"))
    fixed = particle.fix_gauge(["e - 1"])
    assert len(fixed.first_class) == 1 and fixed.multipliers == {"u_1": 0}
    assert fixed.physical_degrees_of_freedom == 3


def test_cli_gauge_json_and_refusal(run_cli):
    status, out, err = run_cli("analyze", "gauge_system", "--gauge", "z", "--gauge", "y - x", "--json")
    assert status == 0, err
    data = json.loads(out)
    assert data["gauge_conditions"] == ["z", "y - x"]
    assert data["first_class"] == [] and data["gauge_generators"] == []
    assert data["physical_degrees_of_freedom"] == 1
    status, out, err = run_cli("analyze", "gauge_system", "--gauge", "x**2 + y**2")
    assert status == 2 and out == ""
    assert err.startswith("error: gauge condition 'x**2 + y**2' fixes nothing")
    status, out, err = run_cli("analyze", "gauge_system", "--json")
    assert status == 0
    [entry] = json.loads(out)["gauge_generators"]
    assert entry == {"terms": ["p_x*y - p_y*x", "p_z"]}


def test_fixing_in_two_steps_equals_fixing_at_once(christ_lee):
    """z = 0, then y - x = 0 on that analysis: the Gauss law, left first class by the first
    step, is fixed by the second; the brackets are those of gauge B ({x, p_x}_D = 1/2)."""
    fixed = christ_lee.fix_gauge(["z"]).fix_gauge(["y - x"])
    assert fixed.gauge_conditions == ("z", "y - x")
    assert fixed.first_class == [] and fixed.physical_degrees_of_freedom == 1
    point = fixed.surface_point({"x": 0.8, "p_x": 0.3})
    assert fixed.dirac_bracket("x", "p_x", at=point) == pytest.approx(0.5, rel=1e-12)


def test_singular_points_of_the_gauge_are_left_out_and_said(gauge_b):
    """Rotations do not move the origin: there {y - x, J} = x + y = 0 and the gauge is singular.
    Such sampled points are counted in a note; surface points avoid them."""
    assert any("singular for the gauge" in note for note in gauge_b.notes)
    for seed in range(4):
        point = gauge_b.surface_point(seed=seed)
        assert abs(point["x"] + point["y"]) > 1e-6
    with pytest.raises(dirac.InputError, match="singular for the gauge"):
        gauge_b.surface_point({"x": 0.0})


def test_sympy_conditions_are_matched_by_name(christ_lee):
    """Plain sympy symbols (without the analysis' assumptions) name the same variables."""
    x, y, z = sympy.symbols("x y z")
    fixed = christ_lee.fix_gauge([z, y - x])
    assert fixed.first_class == [] and fixed.gauge_conditions == ("z", "-x + y")
    with pytest.raises(dirac.InputError, match="unknown symbol"):
        christ_lee.fix_gauge([sympy.Symbol("w")])
