"""Loading systems by built-in name or by path (docs/api.md)."""

from __future__ import annotations

import pytest

import dirac
from dirac.errors import InputError


def test_load_builtin_keeps_parameters_symbolic_until_fixed():
    lag = dirac.load_system("pendulum")
    assert set(lag.parameter_values) == {"m", "g", "l"}
    fixed = dirac.load_system("pendulum", l=2.0, g=9.81)
    assert set(fixed.parameter_values) == {"m"}
    x, y = fixed.coordinates
    assert fixed.constraints[0] == x**2 + y**2 - 4


def test_unknown_system_lists_the_builtin_names():
    with pytest.raises(InputError, match="unknown system 'pendullum'.*pendulum"):
        dirac.load_system("pendullum")


def test_unknown_option_is_refused():
    with pytest.raises(InputError, match="no parameter 'mass'"):
        dirac.load_system("pendulum", mass=1.0)


def test_load_by_path(tmp_path):
    path = tmp_path / "free.toml"
    path.write_text('[system]\nname = "free"\ncoordinates = ["x"]\nlagrangian = "x_dot**2/2"\n')
    assert dirac.load_system(str(path)).name == "free"
