"""Divisors read off the trees of expressions too long to factor, and what is proven about them.

An exact solve by elimination nests its pivots: the multiplier solution of the rigid body's
Lagrangian (228) prints to tens of millions of characters. Its divisors are the bases of its
negative powers, read off its graph (each shared node once, :func:`structural_divisors`), and
decided on the constraint surface: proven nonzero (:func:`value_on_surface`), found to vanish,
or left open with the reason.
"""

from __future__ import annotations

import pytest
import sympy

import dirac
from dirac.analysis.core.divisors import (
    MULTIPLIERS_SINGULAR,
    PIVOT_SINGULAR,
    Undecided,
    structural_divisors,
    value_on_surface,
)

x, y, a = sympy.symbols("x y a", real=True)


def test_the_bases_of_negative_powers_are_the_divisors_and_a_nested_base_is_kept_whole():
    """By hand: ``(x + 1/(x - 1)) / (y + 1/(x - 1))`` divides by ``x - 1`` and by ``y + 1/(x - 1)``
    (kept whole: it holds a division, and factoring it would take ``together``); the parameter
    ``a`` in ``1/a`` is no phase-space variable, so no divisor."""
    inner = 1 / (x - 1)
    expr = (x + inner) / (y + inner) + 1 / a
    found = structural_divisors(expr, [x, y])
    assert set(found) == {x - 1, y + inner}


def test_the_graph_is_walked_once_not_the_tree():
    """``e_(k+1) = e_k + 1/(e_k + x)``, ``e_0 = y``: 60 levels make a tree of more than ``2^60``
    nodes but a graph of a few hundred; the divisors are the 60 bases ``e_k + x`` (by
    construction), found without printing or expanding anything."""
    e = y
    bases = []
    for _ in range(60):
        bases.append(e + x)
        e = e + 1 / (e + x)
    found = structural_divisors(e, [x, y])
    assert len(found) == 60 and set(found) == set(bases[1:]) | {x + y}


def test_a_tree_too_large_to_walk_is_said_so():
    """With fewer nodes allowed than the graph has, no answer (``None``), never an empty list."""
    assert structural_divisors((x + 1 / (x - 1)) / (y + 1 / (x - 1)), [x, y], limit=3) is None


def test_the_pivots_of_a_matrix_constant_on_the_surface_are_proven_nonzero_node_by_node():
    """On the circle ``x^2 + y^2 = 1`` the matrix ``A = [[x^2 + y^2, 2], [3, x^2 + y^2 + 3]]`` is
    ``K = [[1, 2], [3, 4]]`` (by hand). Its elimination divides by the pivots ``x^2 + y^2`` (``= 1``)
    and ``x^2 + y^2 + 3 - 6/(x^2 + y^2)`` (``= 4 - 6 = -2 = det K / 1``): both nonzero constants
    on the surface, proven from the parts. ``x - y/(x^2 + y^2)`` is no constant there: no proof."""
    circle = [x**2 + y**2 - 1]
    r2 = x**2 + y**2
    memo: dict = {}
    cache: dict = {}
    assert value_on_surface(r2, circle, [x, y], memo, cache) == 1
    assert value_on_surface(r2 + 3 - 6 / r2, circle, [x, y], memo, cache) == -2
    assert value_on_surface(x - y / r2, circle, [x, y], memo, cache) is None


def test_a_division_by_a_part_that_vanishes_somewhere_is_no_proof():
    """``1/(x^2 + y^2 - 1 + x)`` on the circle is ``1/x``: the base is not a constant (it vanishes
    at ``x = 0``), so the node has no value, even though ``x^2 + y^2`` has one."""
    circle = [x**2 + y**2 - 1]
    assert value_on_surface(1 / (x**2 + y**2 - 1 + x), circle, [x, y], {}, {}) is None


def test_an_undecided_divisor_says_why_and_prints_no_long_expression():
    """The report line of a divisor left open names the stage, what divides and the reason, and a
    divisor longer than the shown limit is described, not printed."""
    long = sum(sympy.Symbol(f"q_{i}") ** 2 for i in range(200))
    text = str(Undecided(long, 3, MULTIPLIERS_SINGULAR, "no point found, which is no proof"))
    assert text.startswith("not ruled out at stage 3: whether the multiplier solution divides by zero")
    assert "not printed" in text and "q_199" not in text and text.endswith("no point found, which is no proof")


def test_the_four_point_masses_have_no_singular_locus_and_nothing_left_open():
    """Lagrangian (19), four point masses at fixed distances. By hand: the block of the
    consistency conditions that fixes the multipliers has entries ``sum_n (1/m_n) dphi_a/dr_n .
    dphi_b/dr_n``, dot products of differences ``r_i - r_j``, and every such dot product is,
    by polarization, a constant combination of the six squared distances the constraints fix.
    So the block is a constant matrix on the surface, every pivot of its elimination a nonzero
    constant (the block is regular), and the multiplier solution divides by zero nowhere:
    no singular locus, and none of its divisors left open (they used to be "not searched")."""
    a_ = dirac.analyze(dirac.load_system("rigid_body_particles"))
    assert a_.singular_loci == ()
    assert a_.singular_loci_unsearched == ()


@pytest.mark.slow
def test_the_angular_momentum_lagrangian_divides_by_pivots_only_where_its_multipliers_are_finite():
    """Lagrangian (228). The paper solves the multipliers of ``R^T R = 1`` with the inertia tensor
    and ``R`` (``R^-1 = R^T`` on the surface): they are finite on the whole surface. The engine's
    exact solve eliminates with pivots chosen at sample points, the first of them ``R_11`` (the
    entries of the block are quadratic in ``R``), which vanishes on a part of the surface
    (rotations with ``R_11 = 0``). That locus is reported as one of the solved form only: there
    the block the solve inverts is regular, so the multipliers are finite. No locus says that the
    multipliers themselves divide by zero, and the Legendre map's divisor ``det R`` is proven
    nonzero (``det R^2 = 1`` on the surface), so it is no locus either."""
    a_ = dirac.analyze(dirac.load_system("rigid_body_momentum"))
    loci = a_.singular_loci
    assert ("R_11 = 0", PIVOT_SINGULAR) in {(locus.where, locus.what) for locus in loci}
    assert not [locus for locus in loci if locus.what == MULTIPLIERS_SINGULAR]
    assert not [locus for locus in loci if "Legendre" in locus.what]
    assert "singular locus: R_11 = 0 (divisor R_11, stage 3): the multiplier solution as written" in a_.to_text()


def test_the_divisions_of_many_entries_are_the_factors_of_their_denominators_whatever_form_the_variables_take():
    """By hand: ``0``, ``3`` and ``x y`` divide by nothing, ``1/x`` and ``y/(x (x^2 + 1))`` by ``x`` (``x^2 + 1`` has
    no real zero), ``1/(x^2 - y^2)`` by ``x - y`` and ``x + y``; ``1/m`` by no variable. The variables given as a
    list or as a set give the same divisions (a large multiplier solution passes them as a set, once)."""
    from dirac.analysis.core.divisors import divisions

    m = sympy.Symbol("m", real=True)  # x, y: real (module level), so that x^2 + 1 has no zero
    entries = [sympy.S.Zero, sympy.Integer(3), x * y, 1 / x, y / (x * (x**2 + 1)), 1 / (x**2 - y**2), 1 / m]
    for variables in ([x, y], {x, y}):
        found = {d.divisor for d in divisions(entries, 2, "the multiplier solution divides by zero", variables)}
        assert found == {x, x - y, x + y}


class _NoSearch:
    """Numerics that must not be asked: a certificate decides without sampling."""

    def surface_points(self, *args, **kwargs):
        raise AssertionError("the divisor was searched although a certificate proves it nonzero")


def test_a_divisor_read_off_a_tree_with_a_mass_in_its_denominators_is_proven_as_a_polynomial():
    """By hand: on the rod ``x^2 + y^2 = l^2`` of a bob of mass ``m``, ``4 x^2/m + 4 y^2/m = 4 l^2/m``, a
    nonzero constant. Read off the tree of a long multiplier solution it was taken for a nested pivot
    (it holds ``1/m``) and searched, then left "not ruled out"; a division by a parameter is no pivot,
    and the identity proves it without a search."""
    from dirac.analysis.core.divisors import Division, singular_loci

    m, l_ = sympy.symbols("m l", positive=True)
    divisor = 4 * x**2 / m + 4 * y**2 / m
    undecided: list = []
    loci = singular_loci([Division(divisor, 4, MULTIPLIERS_SINGULAR, structural=True)], [x**2 + y**2 - l_**2],
                         _NoSearch(), [x, y], undecided=undecided)
    assert loci == () and undecided == []
