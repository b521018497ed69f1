"""Time-dependent gauges of the einbein particle in 1+1 dimensions, against hand derivations.

``L = (-x0_dot^2 + x1_dot^2)/(2 e) - e m^2/2``: ``p_0 = -x0_dot/e``, ``p_1 = x1_dot/e``,
``p_e = 0`` (primary); ``H_c = e T`` with the mass shell ``T = (m^2 - p_0^2 + p_1^2)/2``
(secondary, from ``p_e_dot = -T``). Both first class; ``(6 - 2*2)/2 = 1`` degree of freedom.
``x0_dot = {x0, H_T} = -e p_0``, ``x1_dot = e p_1``, ``e_dot = u_1``.

Gauge "x0 = t": ``chi_1 = x0 - t``. Its preservation ``-e p_0 - 1 = 0`` has no multiplier
in it (``{x0, p_e} = 0``), so it is the second condition ``chi_2 = e p_0 + 1`` (``e = -1/p_0``),
whose preservation ``p_0 u_1 = 0`` fixes ``u_1 = 0``. Admissible: with ``F = (p_e, T)``,
``{chi_i, F_a} = [[0, p_0], [-p_0, 0]]``, full rank (``p_0^2 = p_1^2 + m^2 >= m^2``).
All four constraints are second class; in the order ``(p_e, T, chi_1, chi_2)``

    C = [[0, 0, 0, -p_0], [0, 0, p_0, 0], [0, -p_0, 0, e], [p_0, 0, -e, 0]].

The reduced space is ``(x1, p_1)``: ``{x1, p_1}_D = 1``, ``x0`` commutes with everything,
``{x1, p_0}_D = dp_0/dp_1 = p_1/p_0``, ``{x1, e}_D = d(-1/p_0)/dp_1 = p_1/p_0^3``.
``H_c = e T`` is a product with a second-class constraint, so ``{z, H_c}_D ~ 0``: the whole
motion is the explicit-time term ``-{z, Phi_a} (C^-1)^ab d_t Phi_b`` with
``d_t Phi = (0, 0, -1, 0)``; ``C y = d_t Phi`` gives ``y = (0, 1/p_0, 0, 0)``, so
``z_dot = -{z, T}/p_0``: ``x0_dot = 1``, ``x1_dot = -p_1/p_0``, which on the branch
``e > 0`` (``p_0 = -sqrt(p_1^2 + m^2)``) is ``p_1/sqrt(p_1^2 + m^2)``, the velocity of a
particle of momentum ``p_1``; ``e_dot = p_dot = 0``.

Proper-time gauge: ``chi_1 = m e - 1`` (``e = 1/m``: ``-x_dot^2 = e^2 m^2 = 1``, the parameter is
proper time) and ``chi_2 = m x0 + p_0 t`` (``x0 = 0`` at ``t = 0``). ``m u_1 = 0`` fixes
``u_1``; ``d chi_2/dt = m (-e p_0) + p_0 = p_0 (1 - m e) ~ 0``, no new condition. With
``{p_e, chi_1} = -m``, ``{T, chi_2} = m p_0`` and ``d_t Phi = (0, 0, 0, p_0)``:
``y = (0, -1/m, 0, 0)`` and ``z_dot = {z, T}/m``: ``x1_dot = p_1/m``, ``x0_dot = -p_0/m``.
"""

from __future__ import annotations

import json

import pytest
import sympy

import dirac
from dirac.flows.analysed import AnalysedSystem
from dirac.model.lagrangian import Lagrangian

M = 1.3

SYSTEM = f"""
[system]
name = "einbein_2d"
coordinates = ["x0", "x1", "e"]
parameters = {{ m = {M} }}
lagrangian = "(-x0_dot**2 + x1_dot**2)/(2*e) - e*m**2/2"
"""


@pytest.fixture(scope="module")
def particle(tmp_path_factory):
    path = tmp_path_factory.mktemp("einbein") / "einbein_2d.toml"
    path.write_text(SYSTEM, encoding="utf-8")
    return dirac.analyze(dirac.load_system(str(path)))


@pytest.fixture(scope="module")
def lab_gauge(particle):
    return particle.fix_gauge(["x0 - t", "e*p_x0 + 1"])


@pytest.fixture(scope="module")
def proper_time(particle):
    return particle.fix_gauge(["m*e - 1", "m*x0 + p_x0*t"])


def test_the_unfixed_particle(particle):
    assert particle.time is None and len(particle.first_class) == 2
    assert particle.physical_degrees_of_freedom == 1


@pytest.mark.parametrize("which", ["lab", "proper"])
def test_the_gauge_is_fixed_completely_and_time_dependent(which, lab_gauge, proper_time):
    fixed = {"lab": lab_gauge, "proper": proper_time}[which]
    assert fixed.time is not None and fixed.time.name == "t"
    assert fixed.first_class == [] and len(fixed.second_class) == 4
    assert fixed.physical_degrees_of_freedom == 1
    assert fixed.multipliers["u_1"] == 0 and fixed.undetermined_multipliers == []
    assert any("time-dependent gauge" in note for note in fixed.notes)
    assert fixed.to_json()["time_dependent"] is True
    assert "time-dependent" in fixed.to_text()


def test_sympy_conditions_name_the_time_by_name(particle):
    """A plain ``sympy.Symbol("t")`` is the time, as ``x0`` is the coordinate."""
    x0, e, p0, t = sympy.symbols("x0 e p_x0 t")
    fixed = particle.fix_gauge([x0 - t, e * p0 + 1])
    assert fixed.time is not None and fixed.first_class == []
    assert fixed.time in fixed.second_class[2].free_symbols


def test_lab_gauge_brackets(lab_gauge):
    s = lab_gauge.symbols
    p0, p1, e = s["p_x0"], s["p_x1"], s["e"]
    assert sympy.simplify(lab_gauge.dirac_bracket("x1", "p_x1") - 1) == 0
    assert sympy.simplify(lab_gauge.dirac_bracket("x0", "p_x0")) == 0
    assert sympy.simplify(lab_gauge.dirac_bracket("x1", "p_x0") - p1 / p0) == 0
    # {x1, e}_D = p_1/p_0^3 on the surface, where e = -1/p_0
    bracket = lab_gauge.dirac_bracket("x1", "e")
    assert sympy.simplify(bracket.subs(e, -1 / p0) - p1 / p0**3) == 0


def test_lab_gauge_motion(lab_gauge):
    s = lab_gauge.symbols
    p0, p1 = s["p_x0"], s["p_x1"]
    exact = lab_gauge.equations_of_motion(["x0", "x1", "e", "p_x1"])
    assert exact[s["x0"]] == 1
    assert sympy.simplify(exact[s["x1"]] + p1 / p0) == 0
    assert exact[s["e"]] == 0 and exact[s["p_x1"]] == 0
    # at points: x0 = t, e = -1/p0, x1_dot = -p1/p0; the branch e > 0 moves at p1/sqrt(p1^2 + m^2)
    points = [lab_gauge.surface_point({"t": 2.0}, seed=k) for k in range(3)]
    points.append(lab_gauge.surface_point({"e": 0.5, "x1": 0.3, "t": -1.0}))
    for point in points:
        assert point["x0"] == pytest.approx(point["t"], abs=1e-10)
        assert point["e"] == pytest.approx(-1 / point["p_x0"], rel=1e-10)
        assert point["p_x0"] ** 2 == pytest.approx(point["p_x1"] ** 2 + M**2, rel=1e-10)
        rates = lab_gauge.equations_of_motion(at=point)
        assert rates[s["x0"]] == pytest.approx(1.0, rel=1e-10)
        assert rates[s["x1"]] == pytest.approx(-point["p_x1"] / point["p_x0"], rel=1e-10)
        assert rates[s["e"]] == pytest.approx(0.0, abs=1e-12)
    e_positive = points[-1]
    speed = e_positive["p_x1"] / (e_positive["p_x1"] ** 2 + M**2) ** 0.5
    assert e_positive["p_x0"] < 0
    assert lab_gauge.equations_of_motion(["x1"], at=e_positive)[s["x1"]] == pytest.approx(speed, rel=1e-10)


def test_proper_time_gauge_motion(proper_time):
    s = proper_time.symbols
    m = proper_time.parameters[0]
    assert sympy.simplify(proper_time.dirac_bracket("x1", "p_x1") - 1) == 0
    exact = proper_time.equations_of_motion(["x0", "x1"])
    assert sympy.simplify(exact[s["x1"]] - s["p_x1"] / m) == 0
    assert sympy.simplify(exact[s["x0"]] + s["p_x0"] / m) == 0
    for seed in range(3):
        point = proper_time.surface_point({"t": 0.7}, seed=seed)
        assert point["e"] == pytest.approx(1 / M, rel=1e-10)
        assert point["x0"] == pytest.approx(-point["p_x0"] * 0.7 / M, rel=1e-10)
        rates = proper_time.equations_of_motion(at=point)
        assert rates[s["x1"]] == pytest.approx(point["p_x1"] / M, rel=1e-10)
        assert rates[s["x0"]] == pytest.approx(-point["p_x0"] / M, rel=1e-10)


def test_a_multiplier_fixed_as_a_function_of_time(particle):
    """``x0 = t + t^3/6``: preservation gives ``-e p_0 = 1 + t^2/2``, the condition
    ``e p_0 + 1 + t^2/2``, whose preservation ``p_0 u_1 + t = 0`` fixes ``u_1 = -t/p_0``.
    Then ``x0_dot = 1 + t^2/2`` and ``e_dot = u_1 = -t/p_0`` (= d/dt of ``-(1 + t^2/2)/p_0``)."""
    fixed = particle.fix_gauge(["x0 - t - t**3/6", "e*p_x0 + 1 + t**2/2"])
    s, t = fixed.symbols, fixed.time
    assert sympy.simplify(fixed.multipliers["u_1"] + t / s["p_x0"]) == 0
    exact = fixed.equations_of_motion(["x0", "e"])
    assert sympy.simplify(exact[s["x0"]] - 1 - t**2 / 2) == 0
    assert sympy.simplify(exact[s["e"]] + t / s["p_x0"]) == 0
    point = fixed.surface_point({"t": 1.5, "x1": 0.2}, seed=1)
    rates = fixed.equations_of_motion(at=point)
    assert rates[s["x0"]] == pytest.approx(1 + 1.5**2 / 2, rel=1e-10)
    assert rates[s["e"]] == pytest.approx(-1.5 / point["p_x0"], rel=1e-10)
    assert rates[s["x1"]] == pytest.approx(point["e"] * point["p_x1"], rel=1e-10)


def test_time_dependent_gauges_that_are_not_admissible(particle):
    """``p_x1 - t`` commutes with p_e and T (neither depends on x1): it fixes nothing.
    ``x0 - t`` alone: its derivative ``-e p_0 - 1`` has no multiplier, and is named."""
    with pytest.raises(dirac.InputError, match=r"'p_x1 - t' fixes nothing"):
        particle.fix_gauge(["p_x1 - t"])
    with pytest.raises(dirac.InputError, match=r"time-dependent gauge condition 'x0 - t' is not preserved.*-e\*p_x0 - 1"):
        particle.fix_gauge(["x0 - t"])
    with pytest.raises(dirac.InputError, match="no phase-space variable"):
        particle.fix_gauge(["t - 1"])


def test_flow_in_the_time_dependent_gauge_x0_equals_t(lab_gauge):
    """The flow of the gauge-fixed particle in the gauge x0 = t, e p_0 = -1 (the midpoint rule
    on the Dirac field with its explicit-time term): by hand the momenta are constant, x0 = t
    exactly, e = -1/p0 and x1 moves at the constant speed -p1/p0 (the motion of a free
    relativistic particle in its lab time)."""
    import numpy as np

    from dirac.flows.analysed import AnalysedProblem

    system = AnalysedSystem.from_analysis(lab_gauge)
    point = lab_gauge.surface_point({"e": 0.5, "x1": 0.3, "t": 0.0})
    z0 = np.array([point[name] for name in system.variable_names])
    solution = dirac.integrate(AnalysedProblem(system, z0), "midpoint", t_end=2.0, dt=0.01, samples=5,
                               outputs=["z", "constraint_residual"])
    names = list(system.variable_names)
    z = solution["z"]
    assert z[:, names.index("x0")] == pytest.approx(solution.t, abs=1e-10)
    assert z[:, names.index("e")] == pytest.approx(-1 / point["p_x0"], rel=1e-10)
    speed = -point["p_x1"] / point["p_x0"]
    assert z[:, names.index("x1")] == pytest.approx(0.3 + speed * solution.t, abs=1e-10)
    assert np.max(solution["constraint_residual"]) <= 1e-10


def test_cli_time_dependent_gauge(run_cli, tmp_path):
    path = tmp_path / "einbein_2d.toml"
    path.write_text(SYSTEM, encoding="utf-8")
    status, out, err = run_cli("analyze", str(path), "--gauge", "x0 - t", "--gauge", "e*p_x0 + 1", "--json")
    assert status == 0, err
    data = json.loads(out)
    assert data["time_dependent"] is True and data["gauge_conditions"] == ["x0 - t", "e*p_x0 + 1"]
    assert data["first_class"] == [] and data["physical_degrees_of_freedom"] == 1
    assert "-t + x0" in data["second_class"]
    status, out, err = run_cli("analyze", str(path), "--gauge", "x0 - t", "--json")
    assert status == 2 and out == ""
    assert err.startswith("error: time-dependent gauge condition 'x0 - t' is not preserved in time")
    assert "--gauge '-e*p_x0 - 1'" in err


def test_castellani_generator_of_a_rheonomic_gauge_system():
    """``L = (x_dot - z e^t)^2/2``: ``p_z = 0``, ``H_c = p^2/2 + z e^t p``, ``-{p_z, H_c} = e^t p``
    (first class). With ``dG/dt = d_t G + {G, H_T}``: ``G_1 = p_z``, ``R = {p_z, H'} = -e^t p``,
    ``{R, H'} + d_t R = -e^t p = S_1``, so ``G_0 = e^t p + p_z`` and ``{G_0, H'} + d_t G_0 =
    e^t p - e^t p = 0``. ``delta x = eps e^t``, ``delta z = eps_dot + eps``, and indeed
    ``delta(x_dot - z e^t) = (eps e^t)_dot - (eps_dot + eps) e^t = 0``. Without the ``d_t``
    terms the chain would stop at ``G_0 = e^t p`` and ``delta z = eps_dot``, not a symmetry."""
    analysis = dirac.analyze(Lagrangian.from_strings("moving_gauge", ["x", "z"], "(x_dot - z*exp(t))**2/2"))
    assert analysis.time is not None and len(analysis.first_class) == 2
    [generator] = analysis.gauge_generators
    x, z = analysis.symbols["x"], analysis.symbols["z"]
    eps, eps_dot = generator.parameter_symbols()
    t = analysis.time
    assert sympy.simplify(generator.delta[x] - eps * sympy.exp(t)) == 0
    assert sympy.simplify(generator.delta[z] - eps - eps_dot) == 0
