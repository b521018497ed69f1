"""The name ``t`` in the input: time in L and the constraints, unless a coordinate is called t.

A rheonomic system (a bead on a hoop turning at rate ``w``, a pendulum of changing
length) writes its constraints as ``chi(q, t) = 0``; ``t`` is then the real time symbol
:attr:`Lagrangian.time`. In the relativistic particle ``t`` is a coordinate (the
coordinate time) and stays one. A parameter called ``t`` would silently freeze the time
(the partial derivative ``d chi/d t`` in the consistency conditions would be missing), so
it is refused.
"""

from __future__ import annotations

import textwrap

import pytest
import sympy
from sympy.physics.mechanics import dynamicsymbols

from dirac.errors import InputError
from dirac.model.lagrangian import TIME, Lagrangian
from dirac.model.system_file import read_system_file

T = sympy.Symbol("t", real=True)

HOOP = dict(
    name="hoop",
    coordinates=["x", "y", "z"],
    lagrangian="m/2*(x_dot**2 + y_dot**2 + z_dot**2) - m*g*z",
    constraints=["x*sin(w*t) - y*cos(w*t)", "x**2 + y**2 + z**2 - R**2"],
    parameters={"m": 1.0, "g": 9.81, "w": 2.0, "R": 1.0},
)


def test_t_in_a_constraint_is_the_real_time_symbol():
    hoop = Lagrangian.from_strings(**HOOP)
    x, y, _ = hoop.coordinates
    w = hoop.parameter_symbols["w"]
    assert hoop.time == T and hoop.time.is_real
    assert hoop.is_time_dependent
    assert hoop.constraints[0] == x * sympy.sin(w * T) - y * sympy.cos(w * T)


def test_a_system_without_t_is_not_time_dependent_but_still_has_a_time():
    pendulum = Lagrangian.from_strings("pendulum", ["x", "y"], "(x_dot**2 + y_dot**2)/2 - y", ["x**2 + y**2 - 1"])
    assert pendulum.time == T
    assert not pendulum.is_time_dependent


def test_t_in_the_lagrangian_only_makes_the_system_time_dependent():
    driven = Lagrangian.from_strings("driven", ["x"], "x_dot**2/2 - x**2/2 + x*cos(t)")
    assert driven.is_time_dependent and driven.constraints == ()


def test_t_as_a_coordinate_stays_a_coordinate():
    """The relativistic particle's coordinate time: no explicit time, t_dot is its velocity."""
    particle = Lagrangian.from_strings("particle", ["t", "x"], "-m*sqrt(t_dot**2 - x_dot**2)", parameters={"m": 1.0})
    assert particle.time is None
    assert not particle.is_time_dependent
    assert particle.coordinates[0] == T
    assert [v.name for v in particle.velocities] == ["t_dot", "x_dot"]


def test_t_as_a_parameter_is_refused_with_the_fix():
    with pytest.raises(InputError, match=r"'t' is time.*cannot be a parameter.*rename the parameter"):
        Lagrangian.from_strings("frozen", ["x", "y"], "(x_dot**2 + y_dot**2)/2", ["x - y*t"], parameters={"t": 1.0})


def test_t_as_a_parameter_is_refused_from_symbols_too():
    x, x_dot = sympy.symbols("x x_dot", real=True)
    with pytest.raises(InputError, match="cannot be a parameter"):
        Lagrangian("frozen", (x,), (x_dot,), x_dot**2 / 2 - T * x, (), {T: 1.0})


def test_unknown_name_message_lists_the_declared_names_only():
    with pytest.raises(InputError, match=r"unknown name 's'; if it is a parameter, add it to parameters \(with its "
                                         r"value\); if a coordinate, to coordinates; the names allowed here are: "
                                         r"x, x_dot$"):
        Lagrangian.from_strings("bad", ["x"], "x_dot**2/2 - s*x")


def test_from_sympy_takes_the_real_time_symbol():
    x = dynamicsymbols("x")
    t = dynamicsymbols._t
    forced = Lagrangian.from_sympy(x.diff(t) ** 2 / 2 - x**2 * sympy.cos(T) / 2, [x], name="forced")
    assert forced.is_time_dependent and forced.parameters == {}
    assert T in forced.expression.free_symbols


def test_from_sympy_never_makes_t_a_parameter_it_is_the_time():
    xs, v, t = sympy.Symbol("x"), sympy.Symbol("x_dot"), sympy.Symbol("t")  # t without real=True
    system = Lagrangian.from_sympy(v**2 / 2 - t * xs, [xs], name="plain")
    assert system.parameters == {} and system.is_time_dependent
    assert system.expression.free_symbols == {system.coordinates[0], system.velocities[0], TIME}


def test_system_file_accepts_t(tmp_path):
    path = tmp_path / "pendulum_of_changing_length.toml"
    path.write_text(
        textwrap.dedent(
            """
            [system]
            name = "growing_pendulum"
            coordinates = ["x", "y"]
            lagrangian = "m/2*(x_dot**2 + y_dot**2) - m*g*y"
            constraints = ["x**2 + y**2 - (l0 + a*t)**2"]
            parameters = { m = 1.0, g = 9.81, l0 = 1.0, a = 0.1 }
            """
        ),
        encoding="utf-8",
    )
    system = read_system_file(path)
    x, y = system.coordinates
    l0, a = system.parameter_symbols["l0"], system.parameter_symbols["a"]
    assert system.is_time_dependent
    assert sympy.expand(system.constraints[0] - (x**2 + y**2 - (l0 + a * T) ** 2)) == 0


def test_fix_keeps_the_time():
    hoop = Lagrangian.from_strings(**HOOP).fix(w=2.0)
    assert hoop.is_time_dependent and T in hoop.constraints[0].free_symbols
