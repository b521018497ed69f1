"""`dirac analyze`: text, --json (docs/file_formats.md), --latex, --param, and error exits."""

from __future__ import annotations

import json

import pytest

EXPECTED_KEYS = {
    "system",
    "coordinates",
    "phase_space_dimension",
    "stages",
    "first_class",
    "second_class",
    "multipliers",
    "physical_degrees_of_freedom",
}


def test_json_follows_the_contract(run_cli):
    status, out, err = run_cli("analyze", "pendulum", "--json")
    assert status == 0, err
    data = json.loads(out)
    assert EXPECTED_KEYS <= set(data)
    assert data["system"] == "pendulum"
    assert data["coordinates"] == ["x", "y", "lambda_1"]
    assert data["phase_space_dimension"] == 6
    assert [s["stage"] for s in data["stages"]] == [1, 2, 3, 4]
    assert data["stages"][0]["constraints"] == ["p_lambda_1"]
    assert data["stages"][1]["constraints"] == ["-l**2 + x**2 + y**2"]
    assert len(data["second_class"]) == 4 and data["first_class"] == []
    assert set(data["multipliers"]) == {"u_1"}
    assert data["physical_degrees_of_freedom"] == 1


def test_text_report_lists_the_stages(run_cli):
    status, out, err = run_cli("analyze", "gauge_system")
    assert status == 0, err
    assert "stage 1 (primary): 1 constraint(s)" in out
    assert "stage 2" in out
    assert "u_1: undetermined" in out
    assert "first class: 2" in out
    assert "physical degrees of freedom: (6 - 2*2 - 0)/2 = 1" in out


def test_latex_and_param(run_cli):
    status, out, err = run_cli("analyze", "pendulum", "--param", "l=2", "--param", "m=0.5", "--latex")
    assert status == 0, err
    assert r"\begin{align*}" in out
    assert "x^{2} + y^{2} - 4" in out


@pytest.mark.parametrize(
    "argv, message",
    [
        (("analyze", "pendulum", "--param", "l"), "NAME=VALUE"),
        (("analyze", "pendulum", "--param", "l=abc"), "not a number"),
        (("analyze", "pendulum", "--param", "mass=2"), "unknown parameter 'mass'; known parameters: g, l, m"),
        (("analyze", "no_such_system"), "unknown system"),
    ],
)
def test_bad_input_exits_2(run_cli, argv, message):
    status, out, err = run_cli(*argv)
    assert status == 2
    assert err.startswith("error:") and message in err


def test_inconsistent_system_file_exits_2(run_cli, tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text('[system]\nname = "bad"\ncoordinates = ["x", "y"]\nlagrangian = "x_dot**2/2 + y"\n')
    status, out, err = run_cli("analyze", str(path))
    assert status == 2
    assert err.startswith("error:") and "1 = 0" in err
