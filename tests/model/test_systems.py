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
    with pytest.raises(InputError, match=r"unknown parameter 'll' \(did you mean 'l'\?\); known parameters: g, l, m$"):
        dirac.load_system("pendulum", ll=1.0)
    with pytest.raises(InputError, match=r"^system 'pendulum': unknown parameter 'colour'; known parameters: g, l, m$"):
        dirac.load_system("pendulum", colour=1.0)


def test_unknown_system_suggests_the_closest_built_in_names():
    with pytest.raises(InputError, match=r"^unknown system 'pendulm' \(did you mean 'pendulum' or 'double_pendulum'\?\); "
                                         r"known systems: double_pendulum, .*, spherical_pendulum; give a built-in name"):
        dirac.load_system("pendulm")
    with pytest.raises(InputError) as error:
        dirac.load_system("xyzzy")
    assert "did you mean" not in str(error.value) and "known systems: double_pendulum" in str(error.value)


def test_load_by_path(tmp_path):
    path = tmp_path / "free.toml"
    path.write_text('[system]\nname = "free"\ncoordinates = ["x"]\nlagrangian = "x_dot**2/2"\n')
    assert dirac.load_system(str(path)).name == "free"
