"""Special parameter values: the one-site Proca model at ``M = 0`` and for generic ``M``.

``L = 1/2 (A1_dot - A0)^2 - M^2/2 (A1^2 - A0^2)``: ``p_A0 = 0`` (primary),
``p_A1 = A1_dot - A0``, ``H_c = p_A1^2/2 + A0 p_A1 + M^2/2 (A1^2 - A0^2)``.
``{p_A0, H_c} = -(p_A1 - M^2 A0)``: secondary ``chi = p_A1 - M^2 A0``;
``{chi, H_T} = -M^2 A1 - M^2 u`` fixes ``u = -A1`` when ``M != 0``, and
``{p_A0, chi} = M^2``: generic ``M`` gives two second-class constraints and
``(4 - 2)/2 = 1`` degree of freedom. At ``M = 0``: ``chi = p_A1``, ``{p_A1, H_c} = 0``
ends the chain, ``{p_A0, p_A1} = 0``: two first class, ``u`` free, ``(4 - 4)/2 = 0``.
The rank of ``C`` (2 -> 0) and of ``{Phi_a, p_A0}`` (1 -> 0) drop at ``M = 0``.
"""

from __future__ import annotations

import json
import warnings

import pytest

import dirac
from dirac.errors import DiracWarning

PROCA = '''[system]
name = "proca"
coordinates = ["A0", "A1"]
lagrangian = "(A1_dot - A0)**2/2 - M**2/2*(A1**2 - A0**2)"
parameters = {{ M = {M} }}
'''


@pytest.fixture
def proca_file(tmp_path):
    def write(M: str) -> str:
        path = tmp_path / f"proca_{M}.toml"
        path.write_text(PROCA.format(M=M))
        return str(path)

    return write


def test_generic_mass_is_massive_and_reports_the_special_value(proca_file):
    with warnings.catch_warnings():
        warnings.simplefilter("error", DiracWarning)  # M = 1.3 is not special: no warning
        a = dirac.analyze(dirac.load_system(proca_file("1.3")))
    assert len(a.second_class) == 2 and a.first_class == []
    assert a.physical_degrees_of_freedom == 1
    assert [s.name for s in a.parameters] == ["M"]
    special = a.to_json()["special_parameter_values"]
    assert [(s["parameter"], s["value"]) for s in special] == [("M", "0")]
    assert "rank of the bracket matrix C drops from 2 to 0" in special[0]["where"]


def test_file_value_zero_is_analysed_at_the_value(proca_file):
    with pytest.warns(DiracWarning, match=r"M = 0, the value given.*special parameter value.*generic values the structure differs"):
        a = dirac.analyze(dirac.load_system(proca_file("0.0")))
    assert len(a.first_class) == 2 and a.second_class == []
    assert a.physical_degrees_of_freedom == 0
    assert a.undetermined_multipliers == list(a.primary_multipliers)
    assert a.parameters == ()
    assert any("special parameter value" in n for n in a.notes)
    assert a.to_json()["special_parameter_values"][0]["parameter"] == "M"


@pytest.mark.parametrize("value, first, second, dof, warns", [("0", 2, 0, 0, True), ("2", 0, 2, 1, False)])
def test_param_on_the_command_line(run_cli, proca_file, value, first, second, dof, warns):
    status, out, err = run_cli("analyze", proca_file("1.0"), "--param", f"M={value}", "--json")
    assert status == 0, err
    data = json.loads(out)
    assert (len(data["first_class"]), len(data["second_class"]), data["physical_degrees_of_freedom"]) == (first, second, dof)
    assert data["parameters"] == []
    lines = [line for line in err.splitlines() if line.strip()]
    if warns:
        assert len(lines) == 1 and lines[0].startswith("warning: M = 0") and "special parameter value" in lines[0]
    else:
        assert lines == []


def test_file_value_warns_on_the_command_line(run_cli, proca_file):
    status, out, err = run_cli("analyze", proca_file("0.0"))
    assert status == 0, err
    assert err.startswith("warning: M = 0")
    assert "first class: 2" in out and "special parameter value: M = 0" in out


def test_hessian_special_value_of_the_pendulum():
    """``W = m 1`` (2x2): its rank drops from 2 to 0 at ``m = 0``."""
    a = dirac.analyze(dirac.load_system("pendulum"))
    assert [s.to_json() for s in a.special_parameter_values] == [
        {"parameter": "m", "value": "0", "equation": "m = 0", "where": "rank of the Hessian drops from 2 to 0"}
    ]
