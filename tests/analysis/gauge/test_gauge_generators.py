"""Gauge generators by Castellani's algorithm, against hand derivations.

Castellani's chain: ``G_N = PFC``, ``G_(k-1) + {G_k, H'} = PFC``, ``{G_0, H'} = PFC``;
``G = sum_k eps^(k) G_k`` and ``delta z = {z, G}``. Each test derives the chain by hand
and checks, independently of the construction, that the transformation leaves the
action invariant (``delta L`` is a total time derivative), which is what makes it a
gauge symmetry of the equations of motion.
"""

from __future__ import annotations

import pytest
import sympy

import dirac


def _lagrangian_variation(analysis, generator):
    """``delta L`` of the transformation ``delta q = {q, G}`` with ``eps = eps(t)`` a function
    and the momenta replaced by ``dL/dq_dot`` (the Legendre map), on a curve ``q(t)``."""
    lagrangian = analysis.lagrangian
    t = sympy.Dummy("time", real=True)  # not "t": the einbein particle has a coordinate t
    eps = sympy.Function("eps")(t)
    q = lagrangian.coordinates
    v = lagrangian.velocities
    curve = {qi: sympy.Function(qi.name)(t) for qi in q}
    curve_v = {vi: sympy.diff(curve[qi], t) for qi, vi in zip(q, v)}
    momenta = {analysis.symbols[f"p_{qi.name}"]: sympy.diff(lagrangian.expression, vi) for qi, vi in zip(q, v)}
    parameters = {e: sympy.diff(eps, t, k) for k, e in enumerate(generator.parameter_symbols())}
    L = lagrangian.expression.xreplace(curve_v).xreplace(curve)
    delta_q = {qi: generator.delta.get(qi, sympy.S.Zero).xreplace(parameters).xreplace(momenta) for qi in q}
    delta_q = {qi: d.xreplace(curve_v).xreplace(curve) for qi, d in delta_q.items()}
    variation = sum(
        (sympy.diff(L, curve[qi]) * delta_q[qi] + sympy.diff(L, curve_v[vi]) * sympy.diff(delta_q[qi], t))
        for qi, vi in zip(q, v)
    )
    return variation, L, eps, curve, t


def test_christ_lee_generator_is_the_gauss_law_and_p_xi():
    """gauge_system (the Christ-Lee model, xi called z), by hand:
    H_c = (p_x^2 + p_y^2)/2 + k r^2/2 + z (y p_x - x p_y); G_1 = p_z (primary first class);
    G_0 = -{p_z, H_c} = y p_x - x p_y; {G_0, H_c} = 0 (rotation invariance, {J, z J} = 0),
    so the chain closes: G = eps (y p_x - x p_y) + eps_dot p_z, and
    delta x = eps y, delta y = -eps x, delta z = eps_dot: a rotation by -eps with
    z -> z + eps_dot, under which x_dot - z y and y_dot + z x rotate and L is invariant."""
    analysis = dirac.analyze(dirac.load_system("gauge_system"))
    s = analysis.symbols
    [gen] = analysis.gauge_generators
    G0, G1 = gen.terms
    assert gen.order == 1 and gen.multiplier == "u_1"
    c = sympy.cancel(G1 / s["p_z"])
    assert c.is_number and c != 0  # G_1 proportional to p_z
    gauss = s["y"] * s["p_x"] - s["x"] * s["p_y"]
    rest = sympy.expand(G0 - c * gauss)  # G_0 = c * Gauss law + (multiple of p_z)
    assert sympy.expand(rest - sympy.diff(rest, s["p_z"]) * s["p_z"]) == 0
    eps, eps_dot = gen.parameter_symbols()
    assert sympy.simplify(gen.delta[s["x"]] - c * eps * s["y"]) == 0
    assert sympy.simplify(gen.delta[s["y"]] + c * eps * s["x"]) == 0
    assert sympy.simplify(gen.delta[s["z"]] - c * eps_dot) == 0
    variation, *_ = _lagrangian_variation(analysis, gen)
    assert sympy.simplify(variation) == 0
    assert analysis.gauge_structure.without_transformation == []


def test_einbein_particle_generator_is_reparametrisation():
    """relativistic_particle, by hand: H_c = e C, C = (m^2 - p_t^2 + p_x^2 + p_y^2 + p_z^2)/2;
    G_1 = p_e, G_0 = -{p_e, H_c} = C, {C, e C} = 0: G = eps C + eps_dot p_e.
    delta x^i = eps p_i = eps x_dot^i/e, delta t = -eps p_t = eps t_dot/e, delta e = eps_dot:
    with xi = eps/e this is the reparametrisation delta q = xi q_dot, delta e = d(xi e)/dt,
    under which delta L = d(xi L)/dt."""
    analysis = dirac.analyze(dirac.load_system("relativistic_particle"))
    s = analysis.symbols
    m = sympy.Symbol("m", real=True)
    [gen] = analysis.gauge_generators
    G0, G1 = gen.terms
    c = sympy.cancel(G1 / s["p_e"])
    assert c.is_number and c != 0
    shell = (m**2 - s["p_t"] ** 2 + s["p_x"] ** 2 + s["p_y"] ** 2 + s["p_z"] ** 2) / 2
    rest = sympy.expand(G0 - c * shell)
    assert sympy.expand(rest - sympy.diff(rest, s["p_e"]) * s["p_e"]) == 0
    variation, L, eps, curve, t = _lagrangian_variation(analysis, gen)
    e = curve[analysis.lagrangian.coordinates[-1]]
    assert analysis.lagrangian.coordinates[-1].name == "e"
    assert sympy.simplify(variation - sympy.diff(c * eps / e * L, t)) == 0


def test_two_step_chain_gives_a_second_derivative_of_the_parameter():
    """L = (x_dot - y)^2/2 + (y_dot - z)^2/2, by hand: p_x = x_dot - y, p_y = y_dot - z, p_z = 0;
    H_c = p_x^2/2 + p_y^2/2 + y p_x + z p_y. {p_z, H_c} = -p_y, {p_y, H_c} = -p_x, {p_x, H_c} = 0:
    first-class chain p_z -> p_y -> p_x (three stages), and Castellani's chain
    G_2 = p_z, G_1 = p_y, G_0 = p_x: G = eps p_x + eps_dot p_y + eps_ddot p_z, i.e.
    delta x = eps, delta y = eps_dot, delta z = eps_ddot, which leaves both x_dot - y and
    y_dot - z unchanged."""
    L = dirac.Lagrangian.from_strings("chain3", ["x", "y", "z"], "(x_dot - y)**2/2 + (y_dot - z)**2/2")
    analysis = dirac.analyze(L)
    s = analysis.symbols
    assert [len(stage) for stage in analysis.stages] == [1, 1, 1]
    [gen] = analysis.gauge_generators
    assert gen.order == 2
    assert list(gen.terms) == [s["p_x"], s["p_y"], s["p_z"]]
    eps, eps_dot, eps_ddot = gen.parameter_symbols()
    assert [e.name for e in (eps, eps_dot, eps_ddot)] == ["eps_1", "eps_1_dot", "eps_1_ddot"]
    assert gen.delta == {s["x"]: eps, s["y"]: eps_dot, s["z"]: eps_ddot}
    variation, *_ = _lagrangian_variation(analysis, gen)
    assert sympy.simplify(variation) == 0


def test_first_class_combination_beside_second_class_constraints():
    """Circle twice, L = |x_dot|^2/2 - lambda_1 (r^2 - 1) - lambda_2 (2 r^2 - 2), by hand:
    the multipliers enter only through lambda_1 + 2 lambda_2, so gamma = p_lambda_2 - 2 p_lambda_1
    is primary first class, {gamma, H_c} = -2(r^2 - 1) + 2(r^2 - 1) = 0: G = eps gamma (no
    derivative), delta lambda_1 = -2 eps, delta lambda_2 = eps (up to the normalisation of gamma)."""
    L = dirac.Lagrangian.from_strings(
        "twice", ["x", "y"], "(x_dot**2 + y_dot**2)/2", constraints=["x**2 + y**2 - 1", "2*x**2 + 2*y**2 - 2"]
    )
    analysis = dirac.analyze(L)
    s = analysis.symbols
    [gen] = analysis.gauge_generators
    assert gen.order == 0
    [G0] = gen.terms
    ratio = sympy.cancel(G0 / (s["p_lambda_2"] - 2 * s["p_lambda_1"]))
    assert ratio.is_number and ratio != 0
    eps = gen.parameter_symbols()[0]
    assert set(gen.delta) == {s["lambda_1"], s["lambda_2"]}
    assert sympy.simplify(gen.delta[s["lambda_1"]] + 2 * gen.delta[s["lambda_2"]]) == 0
    assert sympy.simplify(gen.delta[s["lambda_2"]] - ratio * eps) == 0


def test_no_gauge_freedom_gives_no_generator():
    """The pendulum's constraints are all second class: no gauge parameter."""
    analysis = dirac.analyze(dirac.load_system("pendulum"))
    assert analysis.gauge_generators == []
    assert analysis.to_json()["gauge_generators"] == []


@pytest.mark.parametrize("name", ["gauge_system", "relativistic_particle"])
def test_json_terms_are_the_generator_terms(name):
    analysis = dirac.analyze(dirac.load_system(name))
    data = analysis.to_json()
    assert data["gauge_generators"] == [{"terms": [str(g) for g in gen.terms]} for gen in analysis.gauge_generators]
    assert len(data["gauge_generators"]) == len(analysis.undetermined_multipliers) == 1
    assert data["first_class_without_gauge_transformation"] == []
    assert data["gauge_conditions"] == []
    text = analysis.to_text()
    assert "gauge generators (Castellani): 1" in text
    assert r"\varepsilon_{1}" in analysis.to_latex()


SO3_TOY = (
    "((x1_dot - (a2*x3 - a3*x2))**2 + (x2_dot - (a3*x1 - a1*x3))**2 + (x3_dot - (a1*x2 - a2*x1))**2"
    " + (y1_dot - (a2*y3 - a3*y2))**2 + (y2_dot - (a3*y1 - a1*y3))**2 + (y3_dot - (a1*y2 - a2*y1))**2)/2"
    " - k/2*(x1**2 + x2**2 + x3**2 + y1**2 + y2**2 + y3**2)"
)


def test_yang_mills_type_toy_needs_the_covariant_derivative():
    """Two particles in R^3 with an so(3) gauge field a: L = sum |x_dot - a x x|^2/2 - k/2 (|x|^2 + |y|^2).
    By hand: p_a = 0, H_c = |p|^2/2 + k/2 r^2 + a . J with J = x x p_x + y x p_y,
    {J_i, J_j} = eps_ijk J_k (non-abelian). G_1 = p_a_i, R = {p_a_i, H_c} = -J_i and
    {R, H_c} = -{J_i, a . J} = -eps_ijk a_j J_k, which is no primary combination: with
    S_k = {p_a_k, H_c} = -J_k it is c_k S_k, c_k = eps_ijk a_j, so Castellani's free PFC term
    gives G_0 = -R + c_k p_a_k = J_i + (a x p_a)_i, and {G_0, H_c} ~ 0 mod p_a.
    Then delta x = eps x x, delta a = eps_dot + eps x a (the covariant derivative), under which
    x_dot - a x x turns with the rotation and L is invariant. Three gauge parameters."""
    names = ["x1", "x2", "x3", "y1", "y2", "y3", "a1", "a2", "a3"]
    analysis = dirac.analyze(dirac.Lagrangian.from_strings("so3_toy", names, SO3_TOY, parameters={"k": 1.0}))
    s = analysis.symbols
    assert [len(st) for st in analysis.stages] == [3, 3] and analysis.physical_degrees_of_freedom == 3
    generators = analysis.gauge_generators
    assert len(generators) == 3
    x = sympy.Matrix([s["x1"], s["x2"], s["x3"]])
    a = sympy.Matrix([s["a1"], s["a2"], s["a3"]])
    for i, gen in enumerate(generators):
        eps, eps_dot = gen.parameter_symbols()
        e = sympy.Matrix([eps if j == i else 0 for j in range(3)])
        e_dot = sympy.Matrix([eps_dot if j == i else 0 for j in range(3)])
        delta_x = e.cross(x)
        delta_a = e_dot + e.cross(a)
        for j in range(3):
            assert sympy.expand(gen.delta.get(x[j], 0) - delta_x[j]) == 0
            assert sympy.expand(gen.delta.get(a[j], 0) - delta_a[j]) == 0
        variation, *_ = _lagrangian_variation(analysis, gen)
        assert sympy.simplify(variation) == 0
    assert analysis.gauge_structure.without_transformation == []


def test_an_irregular_constraint_is_regularised_and_dirac_s_conjecture_fails_for_it():
    """L = exp(y) x_dot^2/2 (Henneaux-Teitelboim's irregular example), by hand: p_y = 0 primary,
    H_c = exp(-y) p_x^2/2, {p_y, H_c} = exp(-y) p_x^2/2 = 0 at stage 2 is irregular (its gradient
    vanishes where it holds); its regular form is p_x = 0 (exp(-y) never vanishes). Both are
    first class. Castellani: G_1 = p_y and G_0 = -{p_y, H_c} = -exp(-y) p_x^2/2, weakly zero
    with a vanishing gradient, so G = eps p_y: delta y = eps, delta x = 0. The motion
    (d/dt(exp(y) x_dot) = 0 with exp(y) x_dot^2 = 0, so x_dot = 0) leaves x fixed but
    arbitrary: x is not a gauge variable, and the first-class p_x generates no gauge
    transformation (Dirac's conjecture fails); the report says so."""
    analysis = dirac.analyze(dirac.Lagrangian.from_strings("irregular", ["x", "y"], "exp(y)*x_dot**2/2"))
    s = analysis.symbols
    assert analysis.stages == [[s["p_y"]], [s["p_x"]]]
    assert any("square-free part p_x = 0" in note for note in analysis.notes)
    [gen] = analysis.gauge_generators
    assert gen.terms[-1] == s["p_y"]
    assert all(sympy.simplify(term) == 0 for term in gen.terms[:-1])
    assert gen.delta == {s["y"]: gen.parameter_symbols()[0]}
    assert analysis.gauge_structure.without_transformation == [s["p_x"]]
    assert "generates no gauge transformation" in analysis.to_text()


def test_castellani_check_rejects_a_wrong_chain():
    """The final check is not a formality: with the sign of G_0 flipped, G_0 + {G_1, H_c} =
    -2 (y p_x - x p_y) is no primary first-class combination (hand: {p_z, H_c} = -(y p_x - x p_y));
    with a non-first-class term the first-class check fails."""
    from dirac.analysis.gauge.generators import _chain_problem, _first_class_problem, _gradients

    analysis = dirac.analyze(dirac.load_system("gauge_system"))
    s = analysis.symbols
    space, numerics, points = analysis._space, analysis._numerics, analysis._points
    basis = _gradients(space, numerics, [s["p_z"]], points)
    H = analysis.canonical_hamiltonian
    gauss = s["y"] * s["p_x"] - s["x"] * s["p_y"]
    assert _chain_problem(space, numerics, [gauss, s["p_z"]], H, points, basis) == ""
    assert "fails" in _chain_problem(space, numerics, [-gauss, s["p_z"]], H, points, basis)
    assert "not a first-class" in _first_class_problem(space, numerics, [s["x"]], analysis.constraints, points)


def test_a_chain_whose_terms_swell_is_not_built_and_said_so():
    """A random three-coordinate Lagrangian (found by the never-a-traceback test) whose part
    q1 = 0 has three first-class constraints: Castellani's brackets {G_k, H'} grow 280, 925,
    53860 characters in three stages, and each expansion differentiates the last (the fourth
    ran for minutes). The chain is not built past CHAIN_TERM_LIMIT: no generator is reported,
    the report says which chain and why, and the first-class constraints' gauge transformation
    is said to be undecided, not denied."""
    from dirac.analysis.gauge.generators import CHAIN_TERM_LIMIT
    from dirac.model.lagrangian import Lagrangian

    system = Lagrangian.from_strings(
        "swelling", ["q1", "q2", "q3"],
        "q3*q1_dot*q2_dot + q1_dot*q3_dot/2 - q1*q2_dot**2/2 + q3_dot**2 - q3**2",
        constraints=["(3*q1*q3)**2"])
    with pytest.warns(dirac.DiracWarning, match="crossing branches"):
        analysis = dirac.analyze(system)
    part = next(c.analysis for c in analysis.components if c.condition == "q1 = 0")
    gauge = part.gauge_structure
    assert gauge.generators == []
    assert len(gauge.rejected) == 1 and "was not built" in gauge.rejected[0]
    assert f"longer than {CHAIN_TERM_LIMIT} characters" in gauge.rejected[0]
    assert gauge.without_transformation and all("is not decided" in gauge.account(c) for c in gauge.without_transformation)
