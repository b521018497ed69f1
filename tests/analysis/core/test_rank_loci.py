"""Sample points kept away from loci where a rank the analysis reads drops (dirac.analysis.core.rank_loci)."""

from __future__ import annotations

import numpy as np
import pytest
import sympy

import dirac
from dirac.analysis.core.numeric import Numerics
from dirac.analysis.core.phase_space import PhaseSpace
from dirac.analysis.core.rank_loci import (
    POLE_DISTANCE,
    SINGULAR_MINOR,
    BracketBlocks,
    DivisorLocus,
    magnitude,
    near_rank_drop,
)
from dirac.errors import AnalysisError

q1, q2, p1, p2 = sympy.symbols("q1 q2 p1 p2", real=True)


def test_magnitude_takes_every_sum_and_product_of_absolute_values():
    """By hand: the size of ``p2 (p1 - 2) - 8 q2^2`` is ``|p2| (|p1| + 2) + 8 q2^2``, and bounds the value."""
    expr = p2 * (p1 - 2) - 8 * q2**2
    assert sympy.simplify(magnitude(expr) - (sympy.Abs(p2) * (sympy.Abs(p1) + 2) + 8 * q2**2)) == 0
    rng = np.random.default_rng(1)
    f = sympy.lambdify((p1, p2, q2), expr)
    g = sympy.lambdify((p1, p2, q2), magnitude(expr))
    for _ in range(50):
        x = rng.normal(size=3) * 3
        assert abs(f(*x)) <= g(*x) * (1 + 1e-15)


def test_near_rank_drop_flags_cancellation_not_round_off_nor_small_parameters():
    """The band ``ZERO_TOLERANCE < s < SINGULAR_MINOR`` of the equilibrated singular values."""
    sizes = np.array([[0.0, 2.0], [2.0, 0.0]])

    def antisymmetric(c: float) -> np.ndarray:
        return np.array([[0.0, c], [-c, 0.0]])

    # C_12 = 2.4e-6 left of terms of size 2: next to the locus where C vanishes
    assert near_rank_drop(antisymmetric(2.4e-6), sizes) == 1.2e-6
    assert near_rank_drop(antisymmetric(0.5), sizes) is None  # a regular point
    assert near_rank_drop(antisymmetric(2e-17), sizes) is None  # rank 0 everywhere: round-off, no locus
    # a small parameter is not a cancellation: diag(1, 1e-6) with entries of those sizes has full rank cleanly
    small = np.diag([1.0, 1e-6])
    assert near_rank_drop(small, small) is None
    # an unsimplified zero entry (8 q (2 - p) + 8 q (p - 2)) of large size does not hide a small one
    assert near_rank_drop(np.array([[0.0, 1e-6], [-1e-6, 0.0]]), np.array([[0.0, 1.0], [1.0, 10.0]])) is not None


def _analysis():
    """``L = -q1' q2' - q2 q1' q3' + 2 q1' - 2 q2^2`` (found by the random-Lagrangian invariants).

    By hand: ``p1 = 2 - q2' - q2 q3'``, ``p2 = -q1'``, ``p3 = -q2 q1'``, so
    ``phi_1 = p3 - q2 p2`` is primary; ``H_c = -p1 p2 + 2 p2 + 2 q2^2`` and
    ``{phi_1, H_c} = phi_2 = p2 (p1 - 2) + 4 q2^2`` is secondary; ``{phi_1, phi_2} =
    -p2 (p1 - 2) + 8 q2^2 = 12 q2^2`` on the surface. Both are second class where
    ``q2 != 0`` (2 degrees of freedom); at ``q2 = 0`` the matrix ``C`` has rank 0.
    """
    lagrangian = dirac.Lagrangian.from_strings(
        "jacobi", ["q1", "q2", "q3"], "-q1_dot*q2_dot - q2*q1_dot*q3_dot + 2*q1_dot - 2*q2**2"
    )
    return dirac.analyze(lagrangian)


def test_sample_points_stay_away_from_where_C_drops_rank():
    """Gauss–Newton steps onto ``phi_2 = 0`` drew half the points to ``q2 ~ 1e-3`` (C ~ 1e-6): no more."""
    a = _analysis()
    assert (len(a.first_class), len(a.second_class), a.physical_degrees_of_freedom) == (0, 2, 2)
    names = [str(v) for v in a.phase_space]
    for z in a._points:
        v = dict(zip(names, z))
        size = abs(v["p_q2"]) * (abs(v["p_q1"]) + 2) + 8 * v["q2"] ** 2
        assert 12 * v["q2"] ** 2 >= SINGULAR_MINOR * size, (v, a.notes)
    assert not any("lie next to a locus" in n for n in a.notes)


def test_points_that_cannot_avoid_a_locus_are_used_with_a_note():
    """A block small against its terms on the whole surface: the points are kept, and the user is told.

    ``{x + (1 + 1e-6) y, p_x - p_y} = 1 - (1 + 1e-6) = -1e-6`` from terms of size 2.
    """
    x, y, px, py = sympy.symbols("x y p_x p_y", real=True)
    numerics = Numerics(PhaseSpace((x, y), (px, py)), {})
    rows = [x + (1 + sympy.Rational(1, 10**6)) * y, px - py]
    block = BracketBlocks(numerics, rows, {"the test block": ([0, 1], [0, 1])})
    points = numerics.surface_points(rows, 3, minors=[block])
    assert len(points) == 3
    assert len(numerics.notes) == 1 and "3 of 3 sample points" in numerics.notes[0] and "the test block" in numerics.notes[0]
    # the same block with 1 in place of 1 + 1e-6 is round-off (rank 0 cleanly): no note
    numerics = Numerics(PhaseSpace((x, y), (px, py)), {})
    rows = [x + y, px - py]
    numerics.surface_points(rows, 3, minors=[BracketBlocks(numerics, rows, {"the test block": ([0, 1], [0, 1])})])
    assert numerics.notes == []


def test_a_hessian_whose_rank_drops_on_the_constraint_surface_is_refused():
    """``L = -q1' q2' - q2 q1' q3' - q2' q3'`` under ``q2 = 0`` (found by the random-Lagrangian invariants).

    By hand: ``W = [[0, -1, -q2], [-1, 0, -1], [-q2, -1, 0]]`` has ``det W = -2 q2``, rank 3
    where ``q2 != 0`` and rank 2 on the constraint surface ``q2 = 0``. The velocities solved
    from ``W`` divide by ``q2``, so the total Hamiltonian was not tangent to the surface
    (``{chi, H_T}`` of order ``1e16`` at its points) while counts were reported.
    """
    lagrangian = dirac.Lagrangian.from_strings(
        "drop", ["q1", "q2", "q3"], "-q1_dot*q2_dot - q2*q1_dot*q3_dot - q2_dot*q3_dot", constraints=["-2*q2"]
    )
    with pytest.raises(AnalysisError, match=r"has rank 3 at generic configurations, but rank 2 on the constraint surface"):
        dirac.analyze(lagrangian)
    # the same Lagrangian under q1 = 0 keeps rank 3 on its surface and is analysed
    assert dirac.analyze(lagrangian.__class__.from_strings(
        "kept", ["q1", "q2", "q3"], "-q1_dot*q2_dot - q2*q1_dot*q3_dot - q2_dot*q3_dot", constraints=["q1"]
    )).hessian_rank == 3


def test_stage_points_keep_off_the_poles_of_the_canonical_hamiltonian(monkeypatch):
    """The paper's (228), the rigid body in its matrix coordinates: ``H_c`` divides by ``det R``.

    On the primary surface (``p_lambda = 0``, ``R p_R^T`` symmetric) Gauss–Newton projections
    were drawn to ``det R = 0``: three of four stage-1 points within ``1e-11`` of it, one with
    ``det R = 0.0`` exactly, where the consistency matrix is not finite and the analysis was
    refused ("a rank was needed where the expressions are not finite"); on another machine the
    same points sat at ``det R ~ 1e-12``, and ranks were read at a pole. Every point the chain
    reads is now at least ``SINGULAR_MINOR`` away, relative to the size of the six products of
    ``det R`` (by hand: the cofactor expansion).
    """
    from dirac.analysis.chain.constraint_chain import ConstraintChain

    read: list[np.ndarray] = []
    original = ConstraintChain._stage_points

    def recording(self, *args, **kwargs):
        points = original(self, *args, **kwargs)
        read.extend(points)
        return points

    monkeypatch.setattr(ConstraintChain, "_stage_points", recording)
    analysis = dirac.analyze(dirac.load_system("rigid_body_momentum"))
    assert (len(analysis.second_class), analysis.physical_degrees_of_freedom) == (24, 3)
    assert len(read) >= 8
    for z in read:
        r = np.asarray(z[:9]).reshape(3, 3)
        products = [r[0, i] * r[1, j] * r[2, k] for i, j, k in ((0, 1, 2), (1, 2, 0), (2, 0, 1), (0, 2, 1), (1, 0, 2), (2, 1, 0))]
        det = products[0] + products[1] + products[2] - products[3] - products[4] - products[5]
        assert abs(det) >= SINGULAR_MINOR * sum(abs(p) for p in products), r


def test_a_monomial_divisor_is_kept_at_a_distance():
    """``d = q1`` is never cancellation of its terms (``|q1| / magnitude(q1) = 1``): the test of
    distance sees the pole. At ``z = (q1, q2, p1, p2) = (0.01, 1, -1, 0.5)``, by hand,
    ``|d| / |grad d| = 0.01`` over the size ``max(1, 1) = 1``: next to the pole; at ``q1 = 0.2``
    not; ``d = 1 - 2 q2`` at ``q2 = 0.5 + 1e-6`` is both cancellation (``2e-6 / 2``) and near
    (``2e-6 / 2``); at ``q2 = 0.3`` with ``q1 = 0.2`` neither fires."""
    numerics = Numerics(PhaseSpace((q1, q2), (p1, p2)), {})
    locus = DivisorLocus(numerics, [q1, 1 - 2 * q2])
    near = locus.near_rank_drop(np.array([0.01, 1.0, -1.0, 0.5]))
    assert near is not None and near[0] == pytest.approx(0.01, rel=1e-12) and "q1" in near[1]
    assert locus.near_rank_drop(np.array([0.2, 0.3, -1.0, 0.5])) is None
    both = locus.near_rank_drop(np.array([0.2, 0.5 + 1e-6, -1.0, 0.5]))
    assert both is not None and both[0] == pytest.approx(1e-6, rel=1e-6) and "1 - 2*q2" in both[1]
    # the size of the point scales the distance: q1 = 0.2 at |p1| = 10 is 0.02 of it
    assert locus.near_rank_drop(np.array([0.2, 0.3, 10.0, 0.5]))[0] == pytest.approx(0.02, rel=1e-12)


def test_sample_points_keep_off_a_monomial_pole():
    """A random Lagrangian the long run drew: ``L = -q1 q2'^2 - 2 q1' - 2 q2' - q1^2 q3'``.

    By hand: ``p1 = -2``, ``p2 = -2 q1 q2' - 2``, ``p3 = -q1^2``, so ``p1 + 2`` and ``p3 + q1^2``
    are primary and, where ``q1 != 0``, ``q2' = -(p2 + 2)/(2 q1)`` and ``H_c = -(p2 + 2)^2/(4 q1)``:
    a pole on ``q1 = 0``. Projections onto ``p3 + q1^2 = 0`` were drawn there: three of the four
    points the analysis read had ``|q1| < 0.03``, where the rate of ``p3 + q1^2`` under ``H_T``
    (with ``1 / q1^4``) was ``2e-6`` of its terms instead of round-off. Every point is now at
    least ``POLE_DISTANCE`` of its size away from ``q1 = 0``.
    """
    lagrangian = dirac.Lagrangian.from_strings("drawn", ["q1", "q2", "q3"], "-q1*q2_dot**2 - 2*q1_dot - 2*q2_dot - q1**2*q3_dot", [])
    analysis = dirac.analyze(lagrangian)
    q_1 = analysis.symbols["q1"]
    assert [locus.expression for locus in analysis.singular_loci] == [q_1]
    assert sympy.simplify(analysis.canonical_hamiltonian.subs(analysis.symbols["p_q1"], -2)
                          + (analysis.symbols["p_q2"] + 2) ** 2 / (4 * q_1)) == 0
    assert len(analysis._points) >= 4
    for z in analysis._points:
        assert abs(z[0]) >= POLE_DISTANCE * max(1.0, float(np.max(np.abs(z[:6])))), z
