"""Special parameter values under a budget: radicals, the numeric road, and what is said.

The relativistic particle on an ellipse, ``L = -m c^2 sqrt(1 - (x_dot^2 + y_dot^2)/c^2)``
held on ``x^2/a^2 + y^2/b^2 - 1 = 0`` (multiplier ``lambda_1``), by hand:
``p = m v / sqrt(1 - v^2/c^2)`` inverts to ``v = c p / sqrt(m^2 c^2 + p^2)`` and
``H_c = c sqrt(m^2 c^2 + p^2) + lambda_1 chi`` with ``chi = x^2/a^2 + y^2/b^2 - 1``. The
Hessian in ``(x_dot, y_dot, lambda_1_dot)`` has rank 2: stage 1 is ``p_lambda_1 = 0``;
``{p_lambda_1, H_c} = -chi``: stage 2 is ``chi``; with ``s = sqrt(m^2 c^2 + p^2)``,
``{chi, H_c} = 2 c (x p_x/a^2 + y p_y/b^2) / s``: stage 3 is ``psi``, the velocity along the
normal; ``{psi, H_c}`` holds ``lambda_1 {psi, chi}`` with ``{chi, psi} = 4 c (x^2/a^4 +
y^2/b^4) / s`` on the surface (the derivative of ``1/s`` multiplies ``psi ~ 0``), non-zero
for ``c != 0``: stage 4 is a condition that fixes ``lambda_1``, and its bracket with
``p_lambda_1`` (the same non-zero factor) fixes the multiplier ``u`` of ``p_lambda_1``.
The 4 x 4 bracket matrix of the four constraints is invertible
(its Pfaffian is the product of ``{p_lambda_1, stage 4}`` and ``{chi, stage 3}``, both
non-zero), so all four are second class and ``(6 - 4)/2 = 1`` degree of freedom remains.
At ``c = 0``, ``H_c = lambda_1 chi`` only: ``{chi, H_c} = 0`` ends the chain at stage 2,
and the ranks of ``{Phi_a, phi_k}`` (1 -> 0) and of ``C`` (4 -> 0) drop: ``c = 0`` is a
special value.

The one-site Proca model (tests/analysis/chain/test_special_values.py) has the special
value ``M = 0``; the model of Rothe & Rothe (tests/analysis/chain/test_special_curves.py)
the curve ``b - a**2 = 0``.
"""

from __future__ import annotations

from pathlib import Path

import sympy

import dirac
import dirac.analysis.chain.special_values as special_values
from dirac.analysis.chain.special_values import _radical_free_numerator
from dirac.model.lagrangian import Lagrangian

ROTHE = Path(__file__).parent / "systems" / "rothe.toml"
PROCA = Lagrangian.from_strings(
    "proca", ["A0", "A1"], "(A1_dot - A0)**2/2 - M**2/2*(A1**2 - A0**2)", parameters={"M": 1.3}
)


def _budget_notes(analysis) -> list[str]:
    return [n for n in analysis.notes if "budget" in n]


def test_relativistic_particle_on_an_ellipse_counts_and_special_value():
    """Hand count in the module docstring: stages 1, 1, 1, 1; 4 second class; 1 degree of freedom; c = 0 special."""
    conic = Lagrangian.from_strings(
        "relativistic_conic", ["x", "y"], "-m*c**2*sqrt(1 - (x_dot**2 + y_dot**2)/c**2)",
        ["x**2/a**2 + y**2/b**2 - 1"], parameters={"m": 1.0, "c": 1.0, "a": 2.0, "b": 1.0},
    )
    a = dirac.analyze(conic)
    assert [len(stage) for stage in a.stages] == [1, 1, 1, 1]
    assert len(a.second_class) == 4 and a.first_class == []
    assert a.physical_degrees_of_freedom == 1
    special = {(s.parameter, str(s.value)) for s in a.special_parameter_values}
    assert ("c", "0") in special
    assert _budget_notes(a) == []  # searched in full, within the budget


def test_a_radical_is_removed_by_its_defining_relation():
    """``sqrt(a) - 2`` vanishes at ``a = 4``: the resultant with ``r**2 - a`` is ``a - 4`` (up to a sign)."""
    a = sympy.Symbol("a")
    numerator = _radical_free_numerator(sympy.Matrix([[sympy.sqrt(a) - 2]]))
    assert sympy.expand(numerator**2 - (a - 4) ** 2) == 0


def test_a_search_cut_by_the_budget_scans_numerically_and_says_so(monkeypatch):
    """With no budget for the symbolic search, the scan at simple values still finds Proca's M = 0, and a note says what was not searched."""
    monkeypatch.setattr(special_values, "SEARCH_SECONDS", 0.0)
    a = dirac.analyze(PROCA)
    assert [(s.parameter, str(s.value)) for s in a.special_parameter_values] == [("M", "0")]
    (note, *rest) = _budget_notes(a)
    assert "ran over its budget of 0 s CPU" in note and "scanned numerically instead: M at 0, 1, -1" in note
    assert "curves of several parameters (such as b = a**2) were not searched" in note
    assert a.physical_degrees_of_freedom == 1 and len(a.second_class) == 2  # the generic answer is unchanged


def test_a_curve_the_scan_cannot_find_is_said_not_searched(monkeypatch, tmp_path):
    """Rothe's curve b = a**2 is not found by a scan of single values: none is reported, and the note says curves were not searched."""
    monkeypatch.setattr(special_values, "SEARCH_SECONDS", 0.0)
    generic = tmp_path / "rothe_generic.toml"
    generic.write_text(ROTHE.read_text().replace("a = 2.0, b = 4.0", "a = 1.5, b = 0.7"))
    a = dirac.analyze(dirac.load_system(str(generic)))
    assert a.special_parameter_values == []
    notes = _budget_notes(a)
    assert notes and all("were not searched" in n for n in notes)


def test_when_the_scan_runs_out_too_the_parameters_left_are_named(monkeypatch):
    monkeypatch.setattr(special_values, "SEARCH_SECONDS", 0.0)
    monkeypatch.setattr(special_values, "SCAN_SECONDS", 0.0)
    a = dirac.analyze(PROCA)
    assert a.special_parameter_values == []
    notes = _budget_notes(a)
    assert notes and all("scanned numerically instead: nothing" in n and "not scanned" in n and n.endswith(": M") for n in notes)


def test_scan_leaves_out_values_the_declared_assumptions_exclude():
    """A parameter declared ``positive=True`` never takes 0 or a negative value, so those are
    no cases of the system: the symbolic road never offers them (``sympy.solve(I, I)`` is
    empty for a positive ``I``), and the numeric scan must not either."""
    positive = sympy.Symbol("I", positive=True)
    plain = sympy.Symbol("a")
    whole = sympy.Symbol("n", integer=True)
    assert [v for v in special_values.SCAN_VALUES if special_values.admissible(positive, v)] == [
        1, 2, sympy.Rational(1, 2)]
    assert all(special_values.admissible(plain, v) for v in special_values.SCAN_VALUES)
    assert not special_values.admissible(whole, sympy.Rational(1, 2))


def test_rigid_body_matrix_has_no_special_values_among_positive_moments():
    """Lagrangian (78) with principal moments ``I_1, I_2, I_3`` declared positive: its
    blocks are larger than the symbolic search takes, so they are scanned. At ``I_k = 0`` a
    rank drops (the body is degenerate), but a positive moment cannot be 0, and at the
    positive scan values ``1, 2, 1/2`` (the others generic) the mass matrix ``g`` with
    ``g_1 = (I_2 + I_3 - I_1)/2`` etc. stays invertible: no special value is reported."""
    analysis = dirac.analyze(dirac.load_system("rigid_body_matrix"))
    assert analysis.special_parameter_values == []
    assert any("assumptions exclude" in note for note in analysis.notes)
