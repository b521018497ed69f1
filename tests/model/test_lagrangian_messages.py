"""Messages of `Lagrangian.from_strings` for input of the wrong Python type or with missing names."""

from __future__ import annotations

import pytest

from dirac.errors import InputError
from dirac.model.lagrangian import Lagrangian

L = "m/2*(x_dot**2 + y_dot**2) - m*g*y"


@pytest.mark.parametrize("parameters", [["m", "g", "l"], ("m", "g", "l"), "m"])
def test_parameters_that_are_not_a_mapping_are_an_input_error(parameters):
    with pytest.raises(InputError, match=r"parameters must be a mapping name -> value, e.g. \{'m': 1.0"):
        Lagrangian.from_strings("p", ["x", "y"], L, ["x**2 + y**2 - l**2"], parameters)


def test_a_parameter_missing_from_parameters_gets_the_fix_and_a_typo_gets_a_suggestion():
    with pytest.raises(InputError, match=r"unknown name 'l'; if it is a parameter, add it to parameters"):
        Lagrangian.from_strings("p", ["x", "y"], L, ["x**2 + y**2 - l**2"], {"m": 1.0, "g": 9.81})
    with pytest.raises(InputError, match=r"unknown name 'G' \(did you mean 'g'\?\)") as typo:
        Lagrangian.from_strings("p", ["x", "y"], "m/2*(x_dot**2 + y_dot**2) - m*G*y", [], {"m": 1.0, "g": 9.81})
    assert "add it to parameters" not in str(typo.value)


def test_a_constraint_offers_no_velocities():
    with pytest.raises(InputError) as refused:
        Lagrangian.from_strings("p", ["x", "y"], L, ["x**2 + y**2 - k**2"], {"m": 1.0, "g": 9.81, "l": 1.0})
    assert str(refused.value).endswith("the names allowed here are: g, l, m, x, y")
