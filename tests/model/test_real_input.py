"""A Lagrangian, its constraints and forces are real: a part with a complex value is refused.

Before this check, ``-sqrt(-2)*y`` in a Lagrangian ended the analysis with a ``TypeError``
(the numerics cannot store a complex value), and ``acos(2)*x`` was analysed with the
imaginary part dropped. The values in the messages are by hand: ``sqrt(-2) = sqrt(2) i``,
``log(-1) = i pi``, ``acos(2) = i acosh(2) = 1.31696 i``, ``(-8)**(1/3) = 2 e^{i pi/3} =
1 + 1.73205 i`` (the principal root), ``asin(3) = pi/2 - i acosh(3) = 1.5708 - 1.76275 i``.
"""

from __future__ import annotations

import math

import pytest
import sympy

from dirac.errors import InputError
from dirac.model.expressions import non_real_constant
from dirac.model.lagrangian import Lagrangian

FREE = "x_dot**2/2 + y_dot**2/2"


@pytest.mark.parametrize(
    ("term", "part", "value"),
    [
        ("-sqrt(-2)*y", "-sqrt(2)*I", "0-1.41421 I"),  # the sign is a factor of the constant part
        ("log(-1)*x", "I*pi", "0+3.14159 I"),
        ("acos(2)*x", "acos(2)", "0+1.31696 I"),
        ("(-8)**(1/3)*x", "2*(-1)**(1/3)", "1+1.73205 I"),
    ],
)
def test_a_complex_constant_in_the_lagrangian_is_refused_with_its_value(term, part, value):
    with pytest.raises(InputError) as refused:
        Lagrangian.from_strings("c", ["x", "y"], f"{FREE} + {term}")
    message = str(refused.value)
    assert f"the Lagrangian of 'c' is not real: its part {part} = {value} is complex" in message
    assert "write a real constant" in message


def test_a_complex_constraint_and_force_are_refused():
    with pytest.raises(InputError, match=r"constraint 1 \(x - asin\(3\)\) is not real: its part -asin\(3\) = "
                                         r"-1\.5708\+1\.76275 I"):
        Lagrangian.from_strings("c", ["x", "y"], FREE, constraints=["x - asin(3)"])
    with pytest.raises(InputError, match=r"the force on 'x' is not real: its part -I = 0-1 I"):
        Lagrangian.from_strings("c", ["x", "y"], FREE, forces={"x": "-sqrt(-1)*x_dot"})


def test_a_parameter_value_outside_the_real_domain_is_refused_naming_it():
    text = f"{FREE} + sqrt(m)*x*y"
    with pytest.raises(InputError, match=r"is not real with m = -1\.0: its part sqrt\(m\) = 0\+1 I is complex.*"
                                         r"give the parameter a value in its real domain"):
        Lagrangian.from_strings("c", ["x", "y"], text, parameters={"m": -1.0})
    symbolic = Lagrangian.from_strings("c", ["x", "y"], text, parameters={"m": None})  # no value: nothing to test
    with pytest.raises(InputError, match=r"is not real with m = -4\.0: its part sqrt\(m\) = 0\+2 I"):
        symbolic.fix(m=-4)
    assert symbolic.fix(m=4.0).fixed_values == {"m": 4.0}


def test_real_constants_written_with_complex_intermediates_pass():
    """``(1 + I)*(1 - I) = 2`` and ``exp(I*pi) = -1`` are real; ``asin(1/2) = pi/6`` has no imaginary part."""
    system = Lagrangian.from_strings("c", ["x", "y"], f"{FREE} - asin(1/2)*x*y - cos(2)*x")
    assert non_real_constant(system.expression) is None
    x = system.coordinates[0]
    assert non_real_constant(sympy.Mul(1 + sympy.I, 1 - sympy.I, x, evaluate=False)) is None
    assert non_real_constant(sympy.exp(sympy.I * sympy.pi, evaluate=False) * x) is None
    assert non_real_constant(sympy.sqrt(-2) * x) is not None
    assert math.isclose(float(system.expression.coeff(x * system.coordinates[1])), -math.pi / 6)


def test_the_command_line_says_it_in_one_line(tmp_path, run_cli):
    system = tmp_path / "system.toml"
    system.write_text('[system]\nname = "c"\ncoordinates = ["x", "y"]\nparameters = { m = -1.0 }\n'
                      f'lagrangian = "{FREE} + sqrt(m)*x*y"\nconstraints = ["x - y"]\n')
    status, out, err = run_cli("analyze", str(system))
    assert status == 2 and out == ""
    assert err.startswith("error: ") and err.count("\n") == 1
    assert "with m = -1.0: its part sqrt(m)" in err
