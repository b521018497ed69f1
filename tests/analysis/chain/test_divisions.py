"""Every division by a phase-space function is checked against the constraint surface.

A division ``N / f`` is exact only where ``f != 0``. Where ``f`` vanishes on a part of the
set on which the consistency conditions hold, the division lost a branch (the chain keeps
the factor: fraction-free elimination); where it vanishes on a lower-dimensional locus of
the surface, the analysis reports a singular locus (``analysis.singular_loci``). One test
per place that divides: the elimination of multipliers, the null vectors of the multiplier
solution, the solved velocities (the Legendre map) and the Dirac bracket (``det C``).
"""

from __future__ import annotations

import warnings

import pytest
import sympy

import dirac
from dirac.analysis.core.divisors import LEGENDRE_SINGULAR, MULTIPLIERS_SINGULAR
from dirac.errors import AnalysisError

#: first order, L = a(q).q_dot - V with a = (x z - 2 z^2/3, 2 y z, y), V = -x z
TWO_BRANCHES = "x*x_dot*z + x*z - 2*x_dot*z**2/3 + 2*y*y_dot*z + y*z_dot"


def _two_branches() -> dirac.Lagrangian:
    return dirac.Lagrangian.from_strings("two_branches", ["x", "y", "z"], TWO_BRANCHES, [])


def _counts(a) -> tuple[int, int, int]:
    return len(a.first_class), len(a.second_class), a.physical_degrees_of_freedom


def test_the_elimination_of_multipliers_keeps_the_factor_it_divided_by_and_both_branches_are_named():
    """By hand (first order, ``L = a(q).q_dot - V``): the primaries are ``phi_i = p_i - a_i`` with
    ``a = (x z - 2 z^2/3, 2 y z, y)``; ``{phi_i, phi_j} = F_ij = d_i a_j - d_j a_i`` gives
    ``F_xy = 0``, ``F_xz = 4 z/3 - x``, ``F_yz = 1 - 2 y``, and ``H_c = V = -x z`` gives
    ``b = {phi, H_c} = (z, 0, x)``. Consistency asks ``b + F u = 0``: the row of ``y`` is
    ``(1 - 2 y) u_z = 0``, the row of ``x`` is ``z + F_xz u_z = 0``. Eliminating ``u_z``
    fraction-free, ``(1 - 2 y) z = 0``: two branches, ``z = 0`` and ``y = 1/2``, which meet
    (at ``z = 0, y = 1/2``). Dividing the row of ``y`` by ``1 - 2 y`` (``u_z = 0``) lost the
    branch ``y = 1/2``, and the stage-2 constraint came out as ``z = 0`` alone. No single
    regular surface holds both branches: the analysis is refused, naming both."""
    with pytest.raises(AnalysisError, match="union of the branches") as caught:
        dirac.analyze(_two_branches())
    text = str(caught.value)
    assert "z = 0" in text and "2*y - 1 = 0" in text


def test_each_branch_against_the_hand_counts():
    """The branches of the test above, each picked with ``--assume``. By hand:

    * ``z = 0``: ``u_z = 0`` keeps it, and the row of ``z`` fixes ``x - F_xz u_x - (1 - 2 y) u_y
      = 0`` one combination of ``u_x, u_y``; the four constraints ``phi_x, phi_y, phi_z, z`` have
      ``{phi_z, z} = -1`` and ``C`` of rank 2: 2 first class, 2 second class,
      ``(6 - 4 - 2)/2 = 0`` degrees of freedom;
    * ``y = 1/2`` (``F_yz = 0``): nothing forces ``z = 0``; ``u_y = 0`` keeps ``y = 1/2`` and
      ``u_z = -z/F_xz``, ``u_x = x/F_xz``: every multiplier fixed, the four constraints
      ``phi_x, phi_y, phi_z, 2 y - 1`` second class, ``(6 - 4)/2 = 1`` degree of freedom."""
    assert _counts(dirac.analyze(_two_branches(), assume=["z = 0"])) == (2, 2, 0)
    on_half = dirac.analyze(_two_branches(), assume=["2*y - 1 = 0"])
    assert _counts(on_half) == (0, 4, 1)


def test_assuming_one_branch_away_gives_the_other_and_the_singular_locus_of_its_multipliers():
    """With ``1 - 2 y != 0`` assumed, the branch ``y = 1/2`` is set aside and the surface is
    ``z = 0`` (counts of the test above: 2, 2, 0). On it the multiplier solution (hand: the row
    of ``z``, ``x - F_xz u_x - (1 - 2 y) u_y = 0``, solved for ``u_x`` with ``u_y = v`` free)
    is ``u_x = (x - (1 - 2 y) v)/F_xz`` with ``F_xz = 4 z/3 - x = -x`` on ``z = 0``: it divides
    by zero on the locus ``x = 0`` of the surface (there ``u_y`` is fixed to 0 and ``u_x`` is
    free instead). The locus is reported, in text and JSON."""
    a = dirac.analyze(_two_branches(), assume=["1 - 2*y != 0"])
    assert [len(s) for s in a.stages] == [3, 1]
    assert a.stages[1] == [sympy.Symbol("z", real=True)]
    assert _counts(a) == (2, 2, 0)
    loci = [locus for locus in a.singular_loci if locus.what == MULTIPLIERS_SINGULAR]
    assert [(locus.where, locus.stage) for locus in loci] == [("x = 0", 2)]
    assert "singular locus: x = 0" in a.to_text()
    assert {"expression": "3*x - 4*z", "where": "x = 0", "stage": 2, "what": MULTIPLIERS_SINGULAR} in a.to_json()["singular_loci"]


def test_a_null_vector_that_divides_by_zero_on_a_locus_is_reported():
    """``L = x y y' + x y z'`` (first order, ``a = (0, x y, x y)``, ``V = 0``). By hand:
    ``F_xy = y``, ``F_xz = y``, ``F_yz = x``; ``H_c = 0`` so consistency is ``F u = 0``, whose
    solutions are multiples of ``(F_yz, -F_xz, F_xy) = (x, -y, y)``: no new constraint, rank 2
    (2 second class, 1 first class combination), ``(6 - 2 - 2)/2 = 1`` degree of freedom.
    Any null vector with one component set to 1 divides by ``x`` or by ``y``, which vanish on
    the surface (the primaries leave ``x, y, z`` free): a singular locus of the multiplier
    solution at stage 1."""
    L = dirac.Lagrangian.from_strings("null_vector", ["x", "y", "z"], "x*y*y_dot + x*y*z_dot", [])
    a = dirac.analyze(L)
    assert _counts(a) == (1, 2, 1)
    [vector] = a.multiplier_solution.null_vectors
    denominators = {sympy.fraction(sympy.together(e))[1] for e in vector.values()} - {1}
    loci = {locus.where for locus in a.singular_loci if locus.what == MULTIPLIERS_SINGULAR}
    assert loci and loci <= {"x = 0", "y = 0"}
    assert {str(d) for d in denominators} == {w.removesuffix(" = 0") for w in loci}


def test_the_velocities_solved_from_a_hessian_that_vanishes_on_a_locus_are_reported():
    """The spherical pendulum in polar angles, ``L = m l^2 (theta'^2 + sin(theta)^2 phi'^2)/2 +
    m g l cos(theta)``: ``W = m l^2 diag(1, sin(theta)^2)``, ``det W = m^2 l^4 sin(theta)^2``,
    so ``phi' = p_phi/(m l^2 sin(theta)^2)`` divides by zero at the poles ``sin(theta) = 0``
    (Goldstein, Sect. 1.6 / 3.? spherical pendulum): a coordinate singularity, reported at stage 1."""
    L = dirac.Lagrangian.from_strings(
        "polar", ["theta", "phi"], "m*l**2*(theta_dot**2 + sin(theta)**2*phi_dot**2)/2 + m*g*l*cos(theta)", [],
        parameters={"m": 1.0, "l": 1.0, "g": 9.8},
    )
    a = dirac.analyze(L)
    assert [(locus.where, locus.stage, locus.what) for locus in a.singular_loci] == [("sin(theta) = 0", 1, LEGENDRE_SINGULAR)]


def test_a_bracket_matrix_that_vanishes_on_a_locus_is_reported():
    """``L = x^2 y'/2`` (first order, ``a = (0, x^2/2)``, ``V = 0``). By hand: ``phi_x = p_x``,
    ``phi_y = p_y - x^2/2``, ``C = {phi_x, phi_y} = x`` (up to sign), ``H_c = 0``: the
    multipliers are 0 where ``x != 0``, both constraints are second class, ``(4 - 2)/2 = 1``
    degree of freedom. The Dirac bracket (240) divides by ``det C = x^2``: the locus ``x = 0``
    of the surface (where ``C`` drops rank) is reported."""
    L = dirac.Lagrangian.from_strings("bracket", ["x", "y"], "x**2*y_dot/2", [])
    a = dirac.analyze(L)
    assert _counts(a) == (0, 2, 1)
    assert [(locus.where, locus.stage) for locus in a.singular_loci if "det C" in locus.what] == [("x = 0", 1)]


def test_a_regular_system_has_no_singular_locus():
    """The planar pendulum in Cartesian coordinates (``x^2 + y^2 = l^2``): ``W = m 1``, ``C``
    invertible everywhere on the surface (its determinant is a power of ``x^2 + y^2 = l^2``):
    no division by zero anywhere on the surface."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        a = dirac.analyze(dirac.load_system("pendulum"))
    assert a.singular_loci == ()
    assert a.to_json()["singular_loci"] == []


def test_expressions_too_long_to_factor_are_searched_through_their_trees(monkeypatch):
    """An expression longer than ``DIVISOR_TEXT_LIMIT`` characters is not factored (a gcd of a
    large one costs more than the analysis); its divisors are read off its tree instead (the
    bases of its negative powers). The null vector of ``L = x y y' + x y z'`` divides by ``x`` or
    ``y`` (test above, by hand: the multiples of ``(x, -y, y)`` with one component set to 1).
    With the limit set below the length of its components, the same locus is found, and,
    since the consistency matrix ``F`` solved for the fixed multipliers is singular there (its
    block ``[[y, y], [0, x]]``-like minor has determinant ``x y``, by hand), it is the
    multiplier solution's own singular locus, not a pivot of its elimination: nothing of the
    multiplier solution is left unsearched (the chain's elimination of multipliers is still
    factored or said not searched, as before)."""
    from dirac.analysis.core import divisors

    monkeypatch.setattr(divisors, "DIVISOR_TEXT_LIMIT", 2)
    L = dirac.Lagrangian.from_strings("null_vector", ["x", "y", "z"], "x*y*y_dot + x*y*z_dot", [])
    a = dirac.analyze(L)
    loci = {locus.where for locus in a.singular_loci if locus.what == MULTIPLIERS_SINGULAR}
    assert loci and loci <= {"x = 0", "y = 0"}
    assert not [u for u in a.singular_loci_unsearched if u.what == MULTIPLIERS_SINGULAR]
    assert "singular locus: " in a.to_text()


def test_expressions_whose_trees_are_too_large_are_said_not_searched(monkeypatch):
    """When even the tree of an expression is too large to walk (more than ``STRUCTURAL_NODES``
    distinct nodes; here the limits are set to 0 and 2 so that the null vector of the test
    above is one), the locus ``x = 0`` or ``y = 0`` known by hand is not found, and the
    analysis says so in its result, its text and its JSON instead of passing over it."""
    from dirac.analysis.core import divisors

    monkeypatch.setattr(divisors, "DIVISOR_TEXT_LIMIT", 2)
    monkeypatch.setattr(divisors, "STRUCTURAL_NODES", 0)
    L = dirac.Lagrangian.from_strings("null_vector", ["x", "y", "z"], "x*y*y_dot + x*y*z_dot", [])
    a = dirac.analyze(L)
    assert not [locus for locus in a.singular_loci if locus.what == MULTIPLIERS_SINGULAR]
    [unsearched] = [u for u in a.singular_loci_unsearched if u.what == MULTIPLIERS_SINGULAR]
    assert unsearched.stage == 1 and unsearched.count >= 1
    assert "singular loci: not searched in" in a.to_text() and "neither found nor ruled out" in a.to_text()
    assert any(MULTIPLIERS_SINGULAR in text for text in a.to_json()["singular_loci_unsearched"])


def test_a_regular_system_searched_everything():
    """The planar pendulum's expressions are short: every one was searched (nothing to say)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        a = dirac.analyze(dirac.load_system("pendulum"))
    assert a.singular_loci_unsearched == ()
    assert a.to_json()["singular_loci_unsearched"] == []


def test_a_search_cut_by_its_budget_is_said_not_to_rule_the_locus_out(monkeypatch):
    """The null vector of ``L = x y y' + x y z'`` divides by ``x`` or ``y`` (by hand, above). With the budget of
    the searches for the loci of factors set to nothing, no point of ``x = 0`` or ``y = 0`` is looked for: the
    divisors are said not ruled out, naming the budget, and never counted as proven nonzero."""
    from dirac.analysis.core import divisors

    monkeypatch.setattr(divisors, "SEARCH_BUDGET", -1.0)
    L = dirac.Lagrangian.from_strings("null_vector", ["x", "y", "z"], "x*y*y_dot + x*y*z_dot", [])
    a = dirac.analyze(L)
    assert not [locus for locus in a.singular_loci if locus.what == MULTIPLIERS_SINGULAR]
    cut = [u for u in a.singular_loci_unsearched if u.what == MULTIPLIERS_SINGULAR]
    assert cut and all("before the budget of these searches" in u.reason for u in cut)
    assert {str(u.divisor) for u in cut} <= {"x", "y"}


def test_a_deadline_stops_the_random_starts_after_the_first():
    """``surface_points(..., deadline=...)`` past its deadline tries one start, not ``attempts``: on
    ``x^2 + 1 = 0`` (no real point) one start, then the usual error."""
    from dirac.analysis.core.numeric import Numerics
    from dirac.analysis.core.phase_space import PhaseSpace

    x, p = sympy.symbols("x p_x")
    numerics = Numerics(PhaseSpace((x,), (p,)), {})
    starts = []
    original = numerics.random_point

    def counted():
        starts.append(1)
        return original()

    numerics.random_point = counted  # type: ignore[method-assign]
    with pytest.raises(AnalysisError):
        numerics.surface_points([x**2 + 1], 1, attempts=8, deadline=0.0)
    assert len(starts) == 1
    with pytest.raises(AnalysisError):
        numerics.surface_points([x**2 + 1], 1, attempts=8)
    assert len(starts) == 1 + 8
