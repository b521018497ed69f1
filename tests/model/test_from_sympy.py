"""`Lagrangian.from_sympy`: plain symbols and `sympy.physics.mechanics.dynamicsymbols` give the
same Lagrangian, and the same Dirac-Bergmann analysis, as the string form."""

from __future__ import annotations

import pytest
import sympy
from sympy.physics.mechanics import dynamicsymbols

import dirac
from dirac.errors import InputError
from dirac.model.lagrangian import Lagrangian

PARAMETERS = {"m": 1.0, "g": 9.81, "l": 1.0}


def string_pendulum() -> Lagrangian:
    return Lagrangian.from_strings("pendulum", ["x", "y"], "m/2*(x_dot**2 + y_dot**2) - m*g*y",
                                   constraints=["x**2 + y**2 - l**2"], parameters=PARAMETERS)


def dynamic_pendulum() -> Lagrangian:
    x, y = dynamicsymbols("x y")
    t = dynamicsymbols._t
    m, g, l = sympy.symbols("m g l", positive=True)
    L = m / 2 * (x.diff(t) ** 2 + y.diff(t) ** 2) - m * g * y
    return Lagrangian.from_sympy(L, [x, y], constraints=[x**2 + y**2 - l**2],
                                 parameters={m: 1.0, g: 9.81, l: 1.0}, name="pendulum")


def test_dynamicsymbols_give_the_string_form():
    assert dynamic_pendulum() == string_pendulum()


def test_plain_symbols_give_the_string_form():
    x, y, x_dot, y_dot, m, g, l = sympy.symbols("x y x_dot y_dot m g l")  # no assumptions: made real
    L = m / 2 * (x_dot**2 + y_dot**2) - m * g * y
    built = Lagrangian.from_sympy(L, [x, y], [x**2 + y**2 - l**2], parameters=PARAMETERS, name="pendulum")
    assert built == string_pendulum()


def test_dynamicsymbols_pendulum_has_the_same_analysis_as_the_string_form():
    # pendulum of docs/conventions.md: four second-class constraints in four stages
    # (p_lambda = 0, chi = 0, its time derivative, its second derivative), no gauge freedom
    a, b = dirac.analyze(dynamic_pendulum()), dirac.analyze(string_pendulum())
    assert [len(s) for s in a.stages] == [1, 1, 1, 1]
    assert [[sympy.simplify(c - d) for c, d in zip(s, r)] for s, r in zip(a.stages, b.stages)] == [[0]] * 4
    assert len(a.first_class) == 0 and len(a.second_class) == 4
    assert a.physical_degrees_of_freedom == 1
    x, y, px, py = (a.symbols[n] for n in ("x", "y", "p_x", "p_y"))
    for f, g in [(x, px), (x, y), (px, py), (x, py)]:
        assert sympy.simplify(a.dirac_bracket(f, g) - b.dirac_bracket(f, g)) == 0
    # by hand: {x, p_x}* = 1 - x^2/(x^2+y^2) = y^2/l^2 on the circle; {x, y}* = 0
    assert sympy.simplify(a.dirac_bracket(x, px).subs(y**2, 1 - x**2) - (1 - x**2)) == 0
    assert a.dirac_bracket(x, y) == 0


def test_parameters_none_makes_the_other_symbols_parameters_without_default():
    q = dynamicsymbols("q")
    t = dynamicsymbols._t
    m, k = sympy.symbols("m k")
    L = Lagrangian.from_sympy(m / 2 * q.diff(t) ** 2 - k / 2 * q**2, [q], name="oscillator")
    assert [s.name for s in L.coordinates] == ["q"] and [s.name for s in L.velocities] == ["q_dot"]
    assert L.parameter_values == {"k": None, "m": None}


@pytest.mark.parametrize("make, message", [
    (lambda q, t: (q.diff(t, 2) + q.diff(t) ** 2, [q]), "no accelerations"),
    (lambda q, t: (q.diff(t) ** 2 + q.func(sympy.Symbol("s")), [q]), "is not a coordinate"),
    (lambda q, t: (q.diff(t) ** 2, [q, q]), "listed twice"),
    (lambda q, t: (q.diff(t) ** 2, [q**2]), "must be a sympy Symbol or a function of time"),
])
def test_refusals_say_what_to_do(make, message):
    q = dynamicsymbols("q")
    L, coordinates = make(q, dynamicsymbols._t)
    with pytest.raises(InputError, match=message):
        Lagrangian.from_sympy(L, coordinates)


def test_sympys_time_is_the_engines_time():
    # dynamicsymbols._t is Symbol('t') without real=True: it is the explicit time, not a parameter
    x = dynamicsymbols("x")
    t = dynamicsymbols._t
    w, m = sympy.symbols("w m")
    built = Lagrangian.from_sympy(m / 2 * x.diff(t) ** 2, [x], [x - sympy.cos(w * t)], {m: 1.0, w: 2.0})
    assert built.time == dirac.TIME and built.is_time_dependent
    assert built.constraints[0].free_symbols == {built.coordinates[0], dirac.TIME, built.parameter_symbols["w"]}
    plain = Lagrangian.from_sympy(sympy.Symbol("x_dot") ** 2 / 2, [sympy.Symbol("x")], [sympy.Symbol("x") - sympy.Symbol("t")])
    assert plain.constraints[0].free_symbols == {plain.coordinates[0], dirac.TIME} and plain.parameters == {}


def test_a_real_t_substituted_for_sympys_keeps_the_coordinates():
    # x(t).subs(t, T) with T real gives x(T): still the coordinate x and its velocity
    x = dynamicsymbols("x")
    t = dynamicsymbols._t
    L = (x.diff(t) ** 2 / 2 + t * x).subs(t, dirac.TIME)
    built = Lagrangian.from_sympy(L, [x.subs(t, dirac.TIME)])
    x_, v_ = built.coordinates[0], built.velocities[0]
    assert sympy.expand(built.expression - (v_**2 / 2 + dirac.TIME * x_)) == 0


def test_a_coordinate_named_t_is_no_time():
    t, t_dot, x = sympy.symbols("t t_dot x")
    built = Lagrangian.from_sympy(t_dot**2 - x**2, [t, x])
    assert built.time is None and not built.is_time_dependent


def test_the_constructor_hint_names_the_public_time():
    x, v = sympy.Symbol("x", real=True), sympy.Symbol("x_dot", real=True)
    with pytest.raises(InputError, match=r"dirac\.TIME.*from_sympy"):
        Lagrangian("s", (x,), (v,), v**2 / 2 - sympy.Symbol("t") * x)


def hoop_method():
    from sympy.physics.mechanics import LagrangesMethod

    x, y, z = dynamicsymbols("x y z")
    t = dynamicsymbols._t
    m, g, R, w = sympy.symbols("m g R w")
    L = m / 2 * (x.diff(t) ** 2 + y.diff(t) ** 2 + z.diff(t) ** 2) - m * g * z
    return LagrangesMethod(L, [x, y, z], hol_coneqs=[x**2 + y**2 + z**2 - R**2, -sympy.sin(w * t) * x + sympy.cos(w * t) * y])


def test_a_lagranges_method_gives_its_lagrangian_coordinates_and_constraints():
    built = Lagrangian.from_sympy(hoop_method(), parameters={"m": 1.0, "g": 9.81, "R": 1.0, "w": 2.0})
    by_hand = Lagrangian.from_strings("system", ["x", "y", "z"], "m/2*(x_dot**2 + y_dot**2 + z_dot**2) - m*g*z",
                                      ["x**2 + y**2 + z**2 - R**2", "-sin(w*t)*x + cos(w*t)*y"],
                                      {"m": 1.0, "g": 9.81, "R": 1.0, "w": 2.0})
    assert built == by_hand


def test_a_lagranges_method_forcelist_becomes_generalized_forces():
    """Drag ``-c v`` on a particle at ``(x, y)`` and a torque ``tau`` on a frame turned by ``th``.

    By hand, ``Q_r = sum_i (d v_i/d q_dot_r) . F_i``: the drag gives ``Q_x = -c x_dot``,
    ``Q_y = -c y_dot``; the torque ``tau N.z`` on a frame with angular velocity ``th_dot N.z``
    gives ``Q_th = tau``.
    """
    from sympy.physics.mechanics import LagrangesMethod, Point, ReferenceFrame

    x, y, th = dynamicsymbols("x y th")
    t = dynamicsymbols._t
    c, tau = sympy.symbols("c tau")
    N = ReferenceFrame("N")
    B = N.orientnew("B", "Axis", [th, N.z])
    P = Point("P")
    P.set_vel(N, x.diff(t) * N.x + y.diff(t) * N.y)
    L = (x.diff(t) ** 2 + y.diff(t) ** 2 + th.diff(t) ** 2) / 2
    loads = [(P, -c * (x.diff(t) * N.x + y.diff(t) * N.y)), (B, tau * N.z)]
    forced = LagrangesMethod(L, [x, y, th], forcelist=loads, frame=N)
    built = Lagrangian.from_sympy(forced, parameters={"c": 0.5, "tau": 2.0})
    x_dot, y_dot = sympy.Symbol("x_dot", real=True), sympy.Symbol("y_dot", real=True)
    c_, tau_ = sympy.Symbol("c", real=True), sympy.Symbol("tau", real=True)
    assert {str(k): sympy.simplify(v) for k, v in built.forces.items()} == {"x": -c_ * x_dot, "y": -c_ * y_dot, "th": tau_}
    with pytest.raises(InputError, match="give the forces once"):
        Lagrangian.from_sympy(forced, forces={x: -c * x.diff(t)}, parameters={"c": 0.5, "tau": 2.0})


def test_a_lagranges_method_with_nonholonomic_constraints_is_refused():
    from sympy.physics.mechanics import LagrangesMethod

    x = dynamicsymbols("x")
    t = dynamicsymbols._t
    y = dynamicsymbols("y")
    rolling = LagrangesMethod((x.diff(t) ** 2 + y.diff(t) ** 2) / 2, [x, y], nonhol_coneqs=[x.diff(t) - y * y.diff(t)])
    with pytest.raises(InputError, match="non-holonomic"):
        Lagrangian.from_sympy(rolling)
    with pytest.raises(InputError, match="alone"):
        Lagrangian.from_sympy(hoop_method(), [x])
