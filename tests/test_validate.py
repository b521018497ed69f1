"""The input checks of :mod:`dirac.validate`: bad input is refused with the input named,
good input comes back cleaned (float, int, bool, float64 array)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from dirac.errors import InputError
from dirac.validate import (
    contains_boolean,
    is_real_number,
    validate_array,
    validate_boolean,
    validate_finite,
    validate_integer,
    validate_non_negative,
    validate_positive,
)

NOT_NUMBERS = [True, False, np.bool_(True), "1.0", None, [1.0], {"x": 1.0}]


def test_is_real_number_takes_python_and_numpy_numbers_but_not_booleans():
    assert all(is_real_number(v) for v in (0, -3, 2.5, math.nan, math.inf, np.int64(4), np.float32(0.5)))
    assert not any(is_real_number(v) for v in NOT_NUMBERS) and not is_real_number(1 + 2j)


def test_contains_boolean_looks_inside_lists_and_arrays():
    assert contains_boolean(True) and contains_boolean([1.0, [2.0, False]])
    assert contains_boolean(np.array([True, False])) and contains_boolean(np.array([1.0, True], dtype=object))
    assert not contains_boolean([1, 2.0, np.float64(3.0)]) and not contains_boolean(np.zeros(3))


@pytest.mark.parametrize("bad", [*NOT_NUMBERS, math.nan, math.inf, -math.inf])
def test_validate_finite_refuses_non_numbers_and_non_finite_values(bad):
    with pytest.raises(InputError, match=r"^s.toml: \[run\] dt = .* must be a finite number$"):
        validate_finite(bad, "s.toml: [run] dt")


def test_validate_finite_returns_a_float():
    for good, expected in ((3, 3.0), (-2.5, -2.5), (np.int64(4), 4.0), (np.float32(0.5), 0.5)):
        value = validate_finite(good, "x")
        assert type(value) is float and value == expected
    with pytest.raises(InputError, match=r"m = nan must be a finite number \(the mass\)"):
        validate_finite(math.nan, "m", hint="the mass")


@pytest.mark.parametrize("bad", [*NOT_NUMBERS, math.nan, math.inf, 0, 0.0, -1e-300])
def test_validate_positive_refuses_zero_negative_and_non_numbers(bad):
    with pytest.raises(InputError, match=r"^t_end = .* must be a finite number > 0$"):
        validate_positive(bad, "t_end")


def test_validate_positive_returns_a_float():
    assert validate_positive(2, "t_end") == 2.0 and type(validate_positive(2, "t_end")) is float
    assert validate_positive(1e-300, "t_end") == 1e-300


@pytest.mark.parametrize("bad", [*NOT_NUMBERS, math.nan, -math.inf, -1, -1e-300])
def test_validate_non_negative_refuses_negative_values_and_non_numbers(bad):
    with pytest.raises(InputError, match=r"^mass_gravity = .* must be a finite number >= 0 \(the product m g\)$"):
        validate_non_negative(bad, "mass_gravity", hint="the product m g")


def test_validate_non_negative_returns_a_float():
    assert validate_non_negative(0, "std") == 0.0 and type(validate_non_negative(0, "std")) is float
    assert validate_non_negative(2.5, "std") == 2.5


@pytest.mark.parametrize("bad", [*NOT_NUMBERS, 2.0, 0, -3, math.nan])
def test_validate_integer_refuses_floats_booleans_and_values_below_the_minimum(bad):
    with pytest.raises(InputError, match=r"^\[run\] samples = .* must be an integer >= 1$"):
        validate_integer(bad, "[run] samples")


def test_validate_integer_bounds_and_result():
    assert validate_integer(5, "count") == 5 and type(validate_integer(np.int64(5), "count")) is int
    assert validate_integer(0, "seed", minimum=0) == 0
    with pytest.raises(InputError, match=r"samples = 1 must be an integer >= 2"):
        validate_integer(1, "samples", minimum=2)
    with pytest.raises(InputError, match=r"iterations = 11 must be an integer in \[1, 10\] \(Newton\)$"):
        validate_integer(11, "iterations", maximum=10, hint="Newton")
    assert validate_integer(10, "iterations", maximum=10) == 10


@pytest.mark.parametrize("bad", [0, 1, "true", "yes", None, 1.0])
def test_validate_boolean_refuses_everything_but_true_and_false(bad):
    with pytest.raises(InputError, match=r"^\[initial\] project must be true or false$"):
        validate_boolean(bad, "[initial] project")


def test_validate_boolean_returns_a_bool():
    assert validate_boolean(True, "project") is True and validate_boolean(np.bool_(False), "project") is False


@pytest.mark.parametrize(
    ("bad", "fragment"),
    [
        ([True, 2.0, 3.0], r"\[initial\] M = \[True, 2.0, 3.0\] contains true/false; give \(3,\) real numbers"),
        (np.array([1.0, 0.0, 1.0]) > 0, "contains true/false"),
        (["a", 1.0, 1.0], r"\[initial\] M = \['a', 1.0, 1.0\] is not numeric"),
        ([1.0, 2.0], r"\[initial\] M has shape \(2,\); it must have shape \(3,\)"),
        ([1.0, math.nan, 1.0], r"\[initial\] M = \[1.0, nan, 1.0\] has non-finite entries"),
        ([1.0, 1.0, -math.inf], "non-finite"),
    ],
)
def test_validate_array_refuses_booleans_non_numbers_wrong_shapes_and_non_finite_entries(bad, fragment):
    with pytest.raises(InputError, match=fragment):
        validate_array(bad, "[initial] M", (3,))


def test_validate_array_returns_a_new_float_array():
    source = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1]])
    array = validate_array(source, "R", (3, 3))
    assert array.dtype == np.float64 and np.array_equal(array, np.eye(3))
    array[0, 0] = 5.0
    assert source[0, 0] == 1  # a copy, never a view of the input
    assert validate_array([[1.0, 2.0]], "q").shape == (1, 2)  # any shape when none is asked for
    assert np.isnan(validate_array([math.nan], "q", finite=False)[0])
    with pytest.raises(InputError, match="M0 = .* contains true/false; give real numbers"):
        validate_array([[1.0, 0.0, False]], "M0")


def test_the_problems_and_integrate_refuse_booleans_and_bad_numbers_through_these_checks(pendulum_problem_parts):
    from dirac.flows import ConstrainedProblem, HeavyTopProblem, RigidBodyProblem, integrate

    with pytest.raises(InputError, match=r"M0 = \[\[1.0, 0.0, False\]\] contains true/false"):
        RigidBodyProblem([1.0, 2.0, 2.5], [[1.0, 0.0, False]])
    with pytest.raises(InputError, match=r"^R0 = \[\[True, False, False\], \[False, True, False\], \[False, False, True\]\] contains true/false; give real numbers$"):
        RigidBodyProblem([1.0, 2.0, 2.5], [1.0, 0.0, 0.0], np.eye(3) > 0.5)
    with pytest.raises(InputError, match=r"mass_gravity = -1.0 must be a finite number >= 0 \(the product m g\)"):
        HeavyTopProblem([1.0, 1.0, 0.5], [0.0, 0.0, 1.0], mass_gravity=-1.0)
    with pytest.raises(InputError, match=r"center_of_mass = \[0, 0, True\] contains true/false"):
        HeavyTopProblem([1.0, 1.0, 0.5], [0.0, 0.0, 1.0], center_of_mass=[0, 0, True])
    mechanics, q, p = pendulum_problem_parts
    with pytest.raises(InputError, match=r"initial q = \[True, 0.0\] contains true/false"):
        ConstrainedProblem(mechanics, [True, 0.0], p)
    problem = ConstrainedProblem(mechanics, q, p)
    with pytest.raises(InputError, match=r"^t_end = True must be a finite number > 0$"):
        integrate(problem, "rattle-2", t_end=True, dt=0.1)
    with pytest.raises(InputError, match=r"^samples = 2.0 must be an integer >= 1 \(1 stores only the final state\)$"):
        integrate(problem, "rattle-2", t_end=1.0, dt=0.1, samples=2.0)
    with pytest.raises(InputError, match=r"^max_newton_iterations = 0 must be an integer in \[1, 1000000\]$"):
        integrate(problem, "rattle-2", t_end=1.0, dt=0.1, max_newton_iterations=0)


@pytest.fixture(scope="module")
def pendulum_problem_parts():
    from dirac.flows import MechanicalSystem
    from dirac.model.systems import load_system

    return MechanicalSystem.from_lagrangian(load_system("pendulum")), [0.0, -1.0], [0.0, 0.0]


def test_did_you_mean_offers_the_closest_known_names_or_nothing():
    from dirac.validate import did_you_mean

    assert did_you_mean("sampels", ["dt", "samples"]) == " (did you mean 'samples'?)"
    assert did_you_mean("samples", ["dt", "samples"]) == ""  # never the name itself ("'auto' (did you mean 'auto'?)")
    assert did_you_mean("L", ["g", "l", "m"]) == " (did you mean 'l'?)"  # upper and lower case first
    assert did_you_mean("Theta", ["theta", "phi", "Thetas"]) == " (did you mean 'theta' or 'Thetas'?)"
    assert did_you_mean("sample", ["dt", "samples", "sample_rate"]) == " (did you mean 'samples' or 'sample_rate'?)"
    assert did_you_mean("colour", ["dt", "samples"]) == ""


def test_unknown_name_error_names_the_source_suggests_and_sorts_the_known_names():
    from dirac.validate import unknown_name_error

    error = unknown_name_error("method", "rattle2", ["rattle-4", "auto", "rattle-2"], source="s.toml: [run] method")
    assert isinstance(error, InputError)
    assert str(error) == (
        "s.toml: [run] method: unknown method 'rattle2' (did you mean 'rattle-2' or 'rattle-4'?); "
        "known methods: auto, rattle-2, rattle-4"
    )
    assert str(unknown_name_error("system", "xyzzy", ["pendulum"], hint="or give a path")) == (
        "unknown system 'xyzzy'; known systems: pendulum; or give a path"
    )


def test_check_known_keys_refuses_unknown_keys_with_suggestions():
    from dirac.validate import check_known_keys

    check_known_keys({"dt": 1}, {"dt", "samples"}, "[run]", "s.toml")  # all known: nothing raised
    with pytest.raises(InputError) as error:
        check_known_keys({"sample": 1, "dt": 1}, {"dt", "samples"}, "[run]", "s.toml")
    assert str(error.value) == "s.toml: [run] has an unknown key 'sample' (did you mean 'samples'?); known keys: dt, samples"
