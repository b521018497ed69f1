"""Validation of the Lagrangian input and of system files: bad names, expressions and
constraints are refused with a message that names them."""

from __future__ import annotations

import textwrap

import pytest
import sympy

from dirac.errors import InputError
from dirac.model.lagrangian import Lagrangian
from dirac.model.system_file import read_system_file

PENDULUM = dict(
    name="pendulum",
    coordinates=["x", "y"],
    lagrangian="m/2*(x_dot**2 + y_dot**2) - m*g*y",
    constraints=["x**2 + y**2 - l**2"],
    parameters={"m": 1.0, "g": 9.81, "l": 1.0},
)


def test_from_strings_builds_symbols_with_contract_names():
    lag = Lagrangian.from_strings(**PENDULUM)
    assert [q.name for q in lag.coordinates] == ["x", "y"]
    assert [v.name for v in lag.velocities] == ["x_dot", "y_dot"]
    assert set(lag.parameter_values) == {"m", "g", "l"}
    x, y, l = (lag.symbols[n] for n in ("x", "y", "l"))
    assert lag.constraints == (x**2 + y**2 - l**2,)


def test_fix_substitutes_exact_rationals_and_keeps_the_rest_symbolic():
    lag = Lagrangian.from_strings(**PENDULUM).fix(l=0.5)
    x, y = lag.coordinates
    assert lag.constraints[0] == x**2 + y**2 - sympy.Rational(1, 4)
    assert set(lag.parameter_values) == {"m", "g"}


@pytest.mark.parametrize(
    "change, fragment",
    [
        ({"lagrangian": "x_dot**2 + zeta"}, "unknown name 'zeta'"),
        ({"constraints": ["x*y_dot - 1"]}, "not holonomic|only holonomic"),
        ({"coordinates": ["x", "x"]}, "used twice"),
        ({"parameters": {"x": 1.0, "m": 1.0, "g": 1.0, "l": 1.0}}, "used twice"),
        ({"parameters": {"m": float("nan"), "g": 1.0, "l": 1.0}}, "not finite"),
        ({"parameters": {"m": float("inf"), "g": 1.0, "l": 1.0}}, "not finite"),
        ({"lagrangian": ""}, "empty"),
        ({"lagrangian": "0"}, "empty"),
        ({"constraints": ["0"]}, "identically zero"),
        ({"constraints": ["l - 1"]}, "does not depend on any coordinate"),
        ({"coordinates": ["p_y", "y"], "lagrangian": "y_dot**2"}, "clashes"),
        ({"coordinates": ["lambda_1", "y"], "lagrangian": "y_dot**2"}, "clashes"),
        ({"coordinates": ["sin"]}, "reserved"),
        ({"coordinates": ["2x"]}, "not a valid name"),
        ({"parameters": {"m": "heavy", "g": 1.0, "l": 1.0}}, "not a number"),
    ],
)
def test_bad_lagrangians_are_refused_naming_the_item(change, fragment):
    with pytest.raises(InputError, match=fragment):
        Lagrangian.from_strings(**{**PENDULUM, **change})


def test_fix_refuses_unknown_parameter_and_non_finite_value():
    lag = Lagrangian.from_strings(**PENDULUM)
    with pytest.raises(InputError, match=r"^system 'pendulum': unknown parameter 'q'; known parameters: g, l, m$"):
        lag.fix(q=1.0)
    with pytest.raises(InputError, match=r"unknown parameter 'gg' \(did you mean 'g'\?\); known parameters: g, l, m$"):
        lag.fix(gg=1.0)
    with pytest.raises(InputError, match="finite"):
        lag.fix(l=float("nan"))


def write(tmp_path, text, name="system.toml"):
    path = tmp_path / name
    path.write_text(textwrap.dedent(text))
    return path


def test_toml_system_file_round_trip(tmp_path):
    path = write(
        tmp_path,
        """
        [system]
        name = "pendulum"
        coordinates = ["x", "y"]
        parameters = { m = 1.0, g = 9.81, l = 1.0 }
        lagrangian = "m/2*(x_dot**2 + y_dot**2) - m*g*y"
        constraints = ["x**2 + y**2 - l**2"]
        """,
    )
    lag = read_system_file(path)
    assert lag.name == "pendulum" and len(lag.constraints) == 1


def test_toml_unknown_keys_are_errors_naming_the_file_and_the_closest_keys(tmp_path):
    path = write(
        tmp_path,
        """
        [system]
        name = "free"
        coordinates = ["x"]
        lagrangian = "x_dot**2/2"
        colour = "red"
        constraint = []
        """,
    )
    with pytest.raises(InputError) as error:
        read_system_file(path)
    assert str(error.value) == (
        f"{path}: [system] has unknown keys 'colour', 'constraint' (did you mean 'constraints'?); "
        "known keys: constraints, coordinates, description, forces, lagrangian, name, parameters"
    )


@pytest.mark.parametrize(
    "text, fragment",
    [
        ("[system\nname=1", "not valid TOML"),
        ("[other]\nname = 'x'", "missing \\[system\\]"),
        ("[system]\nname = 'a'\ncoordinates = ['x']", "lacks the required key 'lagrangian'"),
        ("[system]\nname = 'a'\ncoordinates = 'x'\nlagrangian = 'x_dot**2'", "list of names"),
        ("[system]\nname = 'a'\ncoordinates = ['x']\nlagrangian = 'x_dot**2'\nconstraints = 'x'", "list of string"),
        ("[system]\nname = 'a'\ncoordinates = ['x']\nlagrangian = 'x_dot**2 + q'", "unknown name 'q'"),
    ],
)
def test_bad_system_files_are_refused(tmp_path, text, fragment):
    with pytest.raises(InputError, match=fragment):
        read_system_file(write(tmp_path, text))


def test_missing_file_and_wrong_suffix(tmp_path):
    with pytest.raises(InputError, match="does not exist"):
        read_system_file(tmp_path / "nope.toml")
    other = tmp_path / "system.yaml"
    other.write_text("x")
    with pytest.raises(InputError, match=".toml or .py"):
        read_system_file(other)


def test_python_system_file(tmp_path):
    path = write(
        tmp_path,
        """
        from dirac import Lagrangian

        def system():
            return Lagrangian.from_strings("free", ["x"], "x_dot**2/2")
        """,
        name="free.py",
    )
    assert read_system_file(path).name == "free"
    broken = write(tmp_path, "def system():\n    return 42\n", name="broken.py")
    with pytest.raises(InputError, match="not a dirac.Lagrangian"):
        read_system_file(broken)
    raising = write(tmp_path, "raise RuntimeError('boom')\n", name="raising.py")
    with pytest.raises(InputError, match="boom"):
        read_system_file(raising)


def test_validator_sees_every_fixed_parameter_and_can_refuse():
    seen = []

    def validator(values):
        seen.append(dict(values))
        if values.get("l", 1.0) <= 0:
            raise InputError(f"l = {values['l']} must be positive")

    lag = Lagrangian.from_strings(**PENDULUM)
    lag = Lagrangian(
        lag.name, lag.coordinates, lag.velocities, lag.expression, lag.constraints, lag.parameters, validator=validator
    )
    fixed = lag.fix(m=2.0).fix(g=9.81)
    assert seen == [{"m": 2.0}, {"m": 2.0, "g": 9.81}]
    assert fixed.fixed_values == {"m": 2.0, "g": 9.81}
    with pytest.raises(InputError, match="l = -1.0 must be positive"):
        fixed.fix(l=-1.0)
