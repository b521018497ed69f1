"""Generalized forces on a Lagrangian: the three ways in, and refusals of bad input."""

from __future__ import annotations

import textwrap

import pytest
import sympy
from sympy.physics.mechanics import dynamicsymbols

from dirac import Lagrangian
from dirac.errors import InputError
from dirac.model.system_file import read_system_file

OSCILLATOR = dict(name="osc", coordinates=["x"], lagrangian="m/2*x_dot**2 - k/2*x**2",
                  parameters={"m": 1.0, "k": 1.0, "c": 0.1, "F": 0.5, "w": 2.0})


def test_from_strings_reads_forces_in_coordinates_velocities_time_and_parameters():
    system = Lagrangian.from_strings(**OSCILLATOR, forces={"x": "-c*x_dot + F*cos(w*t) + x"})
    x, x_dot = system.coordinates[0], system.velocities[0]
    c, F, w = (system.parameter_symbols[n] for n in ("c", "F", "w"))
    t = sympy.Symbol("t", real=True)
    assert sympy.simplify(system.forces[x] - (-c * x_dot + F * sympy.cos(w * t) + x)) == 0
    assert system.force_vector == (system.forces[x],)
    assert system.is_forced


def test_fix_substitutes_parameters_in_the_forces():
    system = Lagrangian.from_strings(**OSCILLATOR, forces={"x": "-c*x_dot"}).fix(c=0.25)
    x, x_dot = system.coordinates[0], system.velocities[0]
    assert system.forces[x] == -x_dot / 4


def test_from_sympy_with_dynamicsymbols_makes_the_velocity_x_dot_and_new_names_parameters():
    x = dynamicsymbols("x")
    t, m, k, c = sympy.symbols("t m k c")
    system = Lagrangian.from_sympy(m / 2 * x.diff(t) ** 2 - k / 2 * x**2, [x], forces={x: -c * x.diff(t)})
    q, v = system.coordinates[0], system.velocities[0]
    assert system.forces[q] == -system.parameter_symbols["c"] * v
    assert set(system.parameter_values) == {"m", "k", "c"}


def test_system_file_reads_forces(tmp_path):
    path = tmp_path / "damped.toml"
    path.write_text(textwrap.dedent("""
        [system]
        name = "damped"
        coordinates = ["x", "y"]
        parameters = { m = 1.0, g = 9.81, l = 1.0, c = 0.3 }
        lagrangian = "m/2*(x_dot**2 + y_dot**2) - m*g*y"
        constraints = ["x**2 + y**2 - l**2"]
        forces = { x = "-c*x_dot", y = "-c*y_dot" }
    """))
    system = read_system_file(path)
    assert [q.name for q in system.forces] == ["x", "y"]


@pytest.mark.parametrize("forces, fragment", [
    ({"y": "-c*x_dot"}, "a force is given on 'y', which is not a coordinate"),
    ({"xx": "-c*x_dot"}, "did you mean 'x'"),
    ({"x": "-c*xdot"}, "did you mean 'x_dot'"),
    ({"x": "-cc*x_dot"}, "unknown name 'cc' (did you mean 'c'?)"),
])
def test_bad_forces_are_input_errors_naming_the_problem(forces, fragment):
    with pytest.raises(InputError) as error:
        Lagrangian.from_strings(**OSCILLATOR, forces=forces)
    assert fragment in str(error.value)


def test_forces_keyed_by_symbols_check_their_names():
    system = Lagrangian.from_strings(**OSCILLATOR)
    stray = sympy.Symbol("z", real=True)
    with pytest.raises(InputError, match="unknown names: z"):
        Lagrangian(system.name, system.coordinates, system.velocities, system.expression,
                   parameters=system.parameters, forces={system.coordinates[0]: stray})
