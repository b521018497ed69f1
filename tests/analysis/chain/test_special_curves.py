"""Special parameter sets that are curves: the two-parameter model of Rothe & Rothe.

``L = q1_dot**2/2 + q2 q1_dot + (1 - a) q1 q2_dot + (b/2)(q1 - q2)**2``
(H. J. Rothe and K. D. Rothe, *Classical and Quantum Dynamics of Constrained Hamiltonian
Systems*, World Scientific, 2010).

By hand: ``p1 = q1_dot + q2``, ``p2 = (1 - a) q1``, so ``phi1 = p2 + (a - 1) q1 = 0`` is
the one primary constraint (the Hessian ``diag(1, 0)`` has rank 1 for every ``a, b``), and
``H_c = (p1 - q2)**2/2 - (b/2)(q1 - q2)**2``. Then
``{phi1, H_c} = (p1 - q2) - b (q1 - q2) + (a - 1)(p1 - q2) = a (p1 - q2) - b (q1 - q2)``
is the secondary ``phi2`` (``{phi1, phi1} = 0`` leaves no multiplier in it), and
``{phi1, phi2} = -(b - a) + a (a - 1) = a**2 - b``.

* Generic ``b != a**2`` (``a = 0, b != 0`` included: ``phi2 = -b (q1 - q2)``,
  ``{phi1, phi2} = -b``): ``{phi1, phi2} != 0`` fixes the multiplier, two second-class
  constraints, ``(4 - 2)/2 = 1`` degree of freedom.
* ``b = a**2, a != 0``: ``phi2 = a ((p1 - q2) - a (q1 - q2))`` and
  ``{phi2, H_c} = a b (q1 - q2) - b (p1 - q2) = -a phi2 ~ 0``: the chain ends, ``{phi1, phi2} = 0``,
  two first class, ``(4 - 4)/2 = 0`` degrees of freedom (the equations leave ``q1(t)``
  arbitrary).
* ``a = b = 0``: ``phi2`` vanishes identically (``L = q1_dot**2/2 + d(q1 q2)/dt``): only
  ``phi1 = p2 - q1``, first class, ``(4 - 2)/2 = 1`` degree of freedom (``q1`` free, ``q2``
  gauge).

The only parameter-only factor of the ranks used (``{phi1, phi2}`` and ``det C = (a**2 - b)**2``)
is ``b - a**2``: the special set is the curve ``b - a**2 = 0`` (both branches ``a = +-sqrt(b)``).
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pytest
import sympy

import dirac
from dirac.analysis.chain.special_values import SpecialValue, _exact_zeros
from dirac.analysis.core.numeric import numeric_rank
from dirac.errors import DiracWarning

ROTHE = Path(__file__).parent / "systems" / "rothe.toml"

#: (a, b) -> (first class, second class, degrees of freedom, on the special curve), by hand (module docstring)
CASES = {
    "generic": ("1.5", "0.7", 0, 2, 1, False),
    "a=0": ("0.0", "1.5", 0, 2, 1, False),
    "curve a=2": ("2.0", "4.0", 2, 0, 0, True),
    "curve a=3": ("3.0", "9.0", 2, 0, 0, True),
    "curve a=-2": ("-2.0", "4.0", 2, 0, 0, True),
    "a=b=0": ("0.0", "0.0", 1, 0, 1, True),
}


def _file(tmp_path: Path, a: str, b: str) -> str:
    path = tmp_path / f"rothe_{a}_{b}.toml"
    path.write_text(ROTHE.read_text().replace("a = 2.0, b = 4.0", f"a = {a}, b = {b}"))
    return str(path)


def test_the_system_file_as_given_is_on_the_curve():
    """The file says ``a = 2, b = 4``: on ``b = a**2``, so two first class and no degree of freedom."""
    with pytest.warns(DiracWarning, match=r"a = 2, b = 4.*special parameter curve b - a\*\*2 = 0"):
        analysis = dirac.analyze(dirac.load_system(str(ROTHE)))
    assert (len(analysis.first_class), len(analysis.second_class), analysis.physical_degrees_of_freedom) == (2, 0, 0)
    assert any("b - a**2 = 0" in note for note in analysis.notes)


@pytest.mark.parametrize("case", list(CASES))
def test_values_in_the_file(tmp_path, case):
    a, b, first, second, dof, special = CASES[case]
    system = dirac.load_system(_file(tmp_path, a, b))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", DiracWarning)
        analysis = dirac.analyze(system)
    assert (len(analysis.first_class), len(analysis.second_class), analysis.physical_degrees_of_freedom) == (first, second, dof)
    warned = [w for w in caught if issubclass(w.category, DiracWarning)]
    assert len(warned) == int(special)
    equations = [s["equation"] for s in analysis.to_json()["special_parameter_values"]]
    assert equations == ["b - a**2 = 0"]


@pytest.mark.parametrize("case", list(CASES))
def test_values_by_param(run_cli, tmp_path, case):
    a, b, first, second, dof, special = CASES[case]
    status, out, err = run_cli("analyze", _file(tmp_path, "1.5", "0.7"), "--param", f"a={a}", "--param", f"b={b}", "--json")
    assert status == 0, err
    data = json.loads(out)
    assert (len(data["first_class"]), len(data["second_class"]), data["physical_degrees_of_freedom"]) == (first, second, dof)
    lines = [line for line in err.splitlines() if line.strip()]
    if special:
        assert len(lines) == 1 and lines[0].startswith("warning: ") and "b - a**2 = 0" in lines[0]
    else:
        assert lines == []


def test_generic_text_report_shows_the_curve(run_cli, tmp_path):
    status, out, err = run_cli("analyze", _file(tmp_path, "1.5", "0.7"))
    assert status == 0 and err == ""
    assert "special parameter curve: b - a**2 = 0 (rank of the consistency matrix" in out


def test_curve_json_keeps_parameter_and_value():
    """The existing keys stay: the curve is ``b = a**2`` solved for ``b``, its equation ``b - a**2 = 0``."""
    with pytest.warns(DiracWarning):
        analysis = dirac.analyze(dirac.load_system(str(ROTHE)))
    (entry,) = analysis.to_json()["special_parameter_values"]
    assert (entry["parameter"], entry["value"], entry["equation"]) == ("b", "a**2", "b - a**2 = 0")
    assert "rank of the bracket matrix C drops from 2 to 0" in entry["where"]


def test_curve_holds_on_both_branches():
    """``b - a**2 = 0`` contains ``a = sqrt(b)`` and ``a = -sqrt(b)``, and not ``a = 2, b = 4.1``."""
    a, b = sympy.symbols("a b", real=True)
    curve = SpecialValue("b", a**2, "", b - a**2)
    assert curve.is_curve and curve.equation == "b - a**2 = 0"
    assert curve.holds_at({"a": 2.0, "b": 4.0}) and curve.holds_at({"a": -3.0, "b": 9.0})
    assert curve.holds_at({"a": 0.1, "b": 0.01})  # 0.1**2 is 0.010000000000000002 in floating point
    assert not curve.holds_at({"a": 2.0, "b": 4.1}) and not curve.holds_at({"a": 2.0, "b": None})
    single = SpecialValue("M", sympy.Integer(0), "")
    assert not single.is_curve and single.equation == "M = 0"


def test_round_off_is_not_rank():
    """A matrix of pure cancellation (terms of size 1 leaving 1e-16) has rank 0 once the term size is given."""
    noise = np.array([[0.0, 1.388e-16], [-1.388e-16, 0.0]])
    assert numeric_rank(noise, scale=2.0) == 0
    assert numeric_rank(np.array([[1e-3, 0.0], [0.0, 1.0]]), scale=2.0) == 2  # a true small entry stays
    a, b = sympy.symbols("a b")
    C = sympy.Matrix([[0, a * (a - 1) + a - b], [-a * (a - 1) - a + b, 0]])
    assert _exact_zeros(C.subs(b, a**2)) == sympy.zeros(2, 2)
    assert _exact_zeros(C.subs(a, sympy.sqrt(b))) == sympy.zeros(2, 2)
    assert _exact_zeros(C.subs(a, 0)) == C.subs(a, 0)
