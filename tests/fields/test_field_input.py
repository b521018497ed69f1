"""Densities as input: FieldTheory.from_strings / from_sympy, the [field] table, and bad input."""

from __future__ import annotations

import warnings

import pytest
import sympy

import dirac
from dirac.errors import DiracWarning, InputError


def test_from_strings_reads_fields_derivatives_and_parameters():
    kg = dirac.FieldTheory.from_strings("kg", ["x"], ["phi"], "phi_t**2/2 - phi_x**2/2 - m**2*phi**2/2",
                                        parameters={"m": 2.0})
    phi, phi_t, phi_x, m = sympy.symbols("phi phi_t phi_x m", real=True)
    assert kg.density == phi_t**2 / 2 - phi_x**2 / 2 - m**2 * phi**2 / 2
    assert kg.parameters == {m: 2.0}


def test_from_sympy_takes_functions_of_space_and_time():
    t, x = sympy.symbols("t x")
    phi = sympy.Function("phi")(t, x)
    kg = dirac.FieldTheory.from_sympy("kg", ["x"], ["phi"], phi.diff(t) ** 2 / 2 - phi.diff(x) ** 2 / 2)
    phi_t, phi_x = sympy.symbols("phi_t phi_x", real=True)
    assert kg.density == phi_t**2 / 2 - phi_x**2 / 2


def test_unknown_field_derivative_gets_did_you_mean():
    with pytest.raises(InputError, match=r"unknown name 'A2_t'.*did you mean"):
        dirac.FieldTheory.from_strings("m", ["x"], ["A0", "A1"], "(A2_t - A0_x)**2/2")


def test_derivative_along_an_undeclared_direction_is_named():
    with pytest.raises(InputError, match=r"'A1_y' is a derivative of 'A1' along 'y', which is not a declared direction"):
        dirac.FieldTheory.from_strings("m", ["x"], ["A0", "A1"], "(A1_t - A0_x)**2/2 - A1_y**2")


def test_sympy_input_with_an_undeclared_direction_is_refused_not_taken_for_a_parameter():
    phi_t, phi_y = sympy.symbols("phi_t phi_y")
    with pytest.raises(InputError, match="along 'y', which is not a declared direction"):
        dirac.FieldTheory.from_sympy("kg", ["x"], ["phi"], phi_t**2 / 2 - phi_y**2 / 2)


def test_second_derivative_is_refused_saying_only_first_ones_are_taken():
    with pytest.raises(InputError, match="only first derivatives are taken"):
        dirac.FieldTheory.from_strings("m", ["x"], ["phi"], "phi_t**2/2 - phi_xx**2")


def test_density_that_is_not_real_is_refused():
    with pytest.raises(InputError, match="not real"):
        dirac.FieldTheory.from_strings("m", ["x"], ["phi"], "phi_t**2/2 + sqrt(-1)*phi*phi_x")


def test_field_that_appears_nowhere_gets_a_warning():
    with pytest.warns(DiracWarning, match="field 'B' .* appears nowhere"):
        dirac.FieldTheory.from_strings("m", ["x"], ["phi", "B"], "phi_t**2/2 - phi_x**2/2")


def test_non_quadratic_density_is_refused_naming_the_lattice_road():
    sine_gordon = dirac.FieldTheory.from_strings("sg", ["x"], ["phi"], "phi_t**2/2 - phi_x**2/2 + cos(phi)")
    with pytest.raises(InputError, match=r"dirac\.lattice\(theory, sites=N, spacing=a\).*--lattice N"):
        dirac.analyze(sine_gordon)
    quartic = dirac.FieldTheory.from_strings("phi4", ["x"], ["phi"], "phi_t**2/2 - phi_x**2/2 - phi**4")
    with pytest.raises(InputError, match="not quadratic .*phi\\*\\*4.*lattice"):
        dirac.analyze(quartic)


def test_constrained_theory_is_refused_for_the_mode_analysis():
    sigma = dirac.FieldTheory.from_strings("s", ["x"], ["n1", "n2"], "(n1_t**2 + n2_t**2 - n1_x**2 - n2_x**2)/2",
                                           constraints=["n1**2 + n2**2 - 1"])
    with pytest.raises(InputError, match="lattice"):
        dirac.analyze(sigma)


def test_theory_without_space_is_a_mechanical_system():
    """No spatial direction: one real mode; L = (x_t^2 + y_t^2)/2 - (x - y)^2/2 with a gauge-free
    regular Hessian has no constraint and 2 degrees of freedom."""
    theory = dirac.FieldTheory.from_strings("two", [], ["x", "y"], "(x_t**2 + y_t**2)/2 - (x - y)**2/2")
    a = dirac.analyze(theory)
    assert a.physical_degrees_of_freedom == 2 and a.parameter_cases == []


def test_field_file_and_load_system_hint(tmp_path):
    path = tmp_path / "kg.toml"
    path.write_text('[field]\nname = "kg"\nspace = ["x"]\nfields = ["phi"]\n'
                    'density = "phi_t**2/2 - phi_x**2/2 - m**2*phi**2/2"\nparameters = { m = 1.0 }\n')
    theory = dirac.load_field_theory(path, m=3.0)
    assert sympy.Symbol("phi", real=True) in theory.density.free_symbols
    assert sympy.Symbol("m", real=True) not in theory.density.free_symbols
    with pytest.raises(InputError, match=r"\[field\] table: it is a field theory"):
        dirac.load_system(str(path))
    bad = tmp_path / "bad.toml"
    bad.write_text('[field]\nname = "kg"\nfields = ["phi"]\ndensity = "phi_t**2"\nspaces = ["x"]\n')
    with pytest.raises(InputError, match="did you mean 'space'"):
        dirac.load_field_theory(bad)


def test_warning_free_for_a_good_theory():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        dirac.FieldTheory.from_strings("kg", ["x"], ["phi"], "phi_t**2/2 - phi_x**2/2")
