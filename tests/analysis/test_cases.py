"""The parameter case tree (:mod:`dirac.analysis.cases`) against hand derivations.

Rothe & Rothe's model ``L = q1_dot**2/2 + q2 q1_dot + (1 - a) q1 q2_dot + (b/2)(q1 - q2)**2``
(H. J. Rothe and K. D. Rothe, *Classical and Quantum Dynamics of Constrained Hamiltonian
Systems*, World Scientific, 2010). By hand (tests/analysis/chain/test_special_curves.py has
the derivation): ``phi1 = p2 + (a - 1) q1``, ``phi2 = a (p1 - q2) - b (q1 - q2)``,
``{phi1, phi2} = a**2 - b``.

* ``b != a**2``: 0 first class, 2 second class, 1 degree of freedom.
* ``a = 0, b != 0`` lies in the generic case: ``phi2 = -b (q1 - q2)`` and
  ``{phi1, phi2} = -b != 0``, the same 0 first / 2 second / 1 degree of freedom, with the same
  stage sizes 1 + 1. It is not a case of its own, and the tree does not list it.
* ``b = a**2, a != 0``: ``phi2 = a ((p1 - q2) - a (q1 - q2))`` is preserved, 2 first class,
  0 degrees of freedom.
* ``a = b = 0``: ``phi2 = 0`` identically, only ``phi1``, first class, 1 degree of freedom.
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import pytest

import dirac
from dirac.analysis.cases import parameter_cases
from dirac.analysis.constraint_analysis import ConstraintAnalysis

ROTHE = Path(__file__).parent / "chain" / "systems" / "rothe.toml"

#: condition -> (depth, stage sizes, first class, second class, degrees of freedom), by hand
ROTHE_TREE = {
    "b - a**2 != 0": (0, [1, 1], 0, 2, 1),
    "b - a**2 = 0, a != 0": (1, [1, 1], 2, 0, 0),
    "b - a**2 = 0, a = 0": (2, [1], 1, 0, 1),
}


def _counts(case) -> tuple:
    a = case.analysis
    return (case.depth, [len(s) for s in a.stages], len(a.first_class), len(a.second_class), a.physical_degrees_of_freedom)


def test_rothe_case_tree_matches_the_hand_counts():
    cases = parameter_cases(ConstraintAnalysis(dirac.load_system(str(ROTHE))))
    with pytest.warns(dirac.DiracWarning):  # the file's values lie on the curve: the tree starts from the symbolic analysis
        assert [c.condition for c in dirac.analyze(dirac.load_system(str(ROTHE)), cases=True).parameter_cases] == list(ROTHE_TREE)
    assert [c.condition for c in cases] == list(ROTHE_TREE)  # generic first, then the curve, then a = b = 0 on it
    for case in cases:
        assert _counts(case) == ROTHE_TREE[case.condition], case.condition


def test_a_zero_b_nonzero_is_the_generic_structure():
    """At ``a = 0, b = 3/2`` the hand counts are the generic ones: no separate case is missed."""
    system = dirac.load_system(str(ROTHE), a=0.0, b=1.5)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # not on a special set: no warning
        at = dirac.analyze(system)
    assert ([len(s) for s in at.stages], len(at.first_class), len(at.second_class), at.physical_degrees_of_freedom) == (
        [1, 1], 0, 2, 1,
    )


def test_a_system_without_parameters_has_one_case():
    analysis = dirac.analyze(dirac.load_system("pendulum", m=1.0, g=9.81, l=1.0), cases=True)
    cases = analysis.parameter_cases
    assert [c.condition for c in cases] == ["all parameter values"]
    assert cases[0].analysis is analysis


def test_cli_cases_json_and_text(run_cli):
    status, out, _ = run_cli("analyze", str(ROTHE), "--cases", "--json")
    assert status == 0
    listed = json.loads(out)["parameter_cases"]
    assert [(c["condition"], len(c["first_class"]), len(c["second_class"]), c["physical_degrees_of_freedom"]) for c in listed] == [
        (cond, first, second, dof) for cond, (_, _, first, second, dof) in ROTHE_TREE.items()
    ]
    assert all(set(c) >= {"condition", "stages", "first_class", "second_class", "physical_degrees_of_freedom"} for c in listed)
    status, out, _ = run_cli("analyze", str(ROTHE), "--cases")
    assert status == 0
    tree = out.split("parameter cases:")[1].splitlines()
    assert tree[1].startswith("  - b - a**2 != 0: ") and tree[3].startswith("      - b - a**2 = 0, a = 0: ")


def test_cli_cases_with_latex_is_refused(run_cli):
    status, _, err = run_cli("analyze", str(ROTHE), "--cases", "--latex")
    assert status == 2 and err.startswith("error:") and "--latex" in err
