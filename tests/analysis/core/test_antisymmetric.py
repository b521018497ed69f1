"""The bracket matrix read off its entries above the diagonal (dirac.analysis.core.antisymmetric)."""

from __future__ import annotations

import numpy as np
import sympy

from dirac.analysis.chain.special_values import RankUse, _Scanner
from dirac.analysis.classes.classification import bracket_matrix, bracket_values
from dirac.analysis.core.antisymmetric import mirrored
from dirac.analysis.core.numeric import Numerics
from dirac.analysis.core.phase_space import PhaseSpace
from dirac.analysis.core.scaled_function import terms_of


def test_mirrored_reads_each_entry_off_its_upper_mirror():
    where = [(0, 1), (2, 0), (1, 0), (0, 2)]
    upper, pick, sign = mirrored(where)
    assert upper == [0, 3]  # (0, 1) and (0, 2)
    u = np.array([5.0, 7.0])  # the values of (0, 1) and (0, 2)
    assert list(sign * u[pick]) == [5.0, -7.0, -5.0, 7.0]


def test_mirrored_refuses_a_pattern_that_is_not_antisymmetric():
    assert mirrored([(0, 1)]) is None  # no mirror
    assert mirrored([(0, 1), (1, 0), (1, 1)]) is None  # a diagonal entry


def _spherical_pendulum():
    x, y, z, lam = sympy.symbols("x y z lambda_1", real=True)
    px, py, pz, pl = sympy.symbols("p_x p_y p_z p_lambda_1", real=True)
    m = sympy.Symbol("m", positive=True)
    space = PhaseSpace((x, y, z, lam), (px, py, pz, pl), (m,))
    # the constraints of the spherical pendulum (hand): p_lambda, the sphere, its two time derivatives
    constraints = [
        pl,
        x**2 + y**2 + z**2 - 1,
        (x * px + y * py + z * pz) / m,
        (px**2 + py**2 + pz**2) / m**2 - lam * (x**2 + y**2 + z**2) / m - z / m,
    ]
    return space, constraints, m


def test_bracket_values_are_the_entries_evaluated_one_by_one():
    space, constraints, m = _spherical_pendulum()
    numerics = Numerics(space, {m: 1.3})
    points = numerics.surface_points(constraints[:2], 4)
    C = bracket_matrix(space, constraints)
    entries = C.todok()
    where = list(entries)
    assert mirrored(where) is not None
    fast = bracket_values(numerics, entries, where, points)
    direct = Numerics(space, {m: 1.3}).evaluate([entries[k] for k in where], points)  # every entry compiled, as before
    sizes = Numerics(space, {m: 1.3}).term_scale([entries[k] for k in where], points)
    # the same functions: equal to round-off of their terms (the summation order of C_ba may differ)
    assert np.all(np.abs(fast - direct) <= 1e-14 * sizes)
    upper = [k for k, (i, j) in enumerate(where) if i < j]
    assert np.array_equal(fast[:, upper], direct[:, upper])  # the entries above the diagonal are those very values
    for k, (i, j) in enumerate(where):
        assert np.array_equal(fast[:, k], -fast[:, where.index((j, i))])


def test_the_scan_reads_the_same_ranks_from_the_upper_triangle():
    space, constraints, m = _spherical_pendulum()
    C = bracket_matrix(space, constraints)
    generic = {m: 1.3}
    numerics = Numerics(space, generic)
    starts = numerics.surface_points(constraints, 4)
    both = []
    for antisymmetric in (False, True):
        use = RankUse("bracket matrix C", C, C, 4, on_surface=True, antisymmetric=antisymmetric)
        scanner = _Scanner(space, generic, use, constraints, seed=7, time=None, starts=starts)
        assert (scanner.upper is not None) == antisymmetric
        points = starts[:3]
        scales, values = scanner._values(points)
        both.append((scales, values, [scanner.rank(m, v) for v in (0.5, 2.0, -1.0)]))
    (s0, v0, r0), (s1, v1, r1) = both
    assert r0 == r1 == [4, 4, 4]  # rank 4 for every non-zero mass (hand: all four constraints second class)
    terms = [len(terms_of(e)) for e in C]
    assert np.all(np.abs(v1 - v0) <= 1e-14 * s0)
    assert np.all(np.abs(s1 - s0) <= 1e-14 * s0 * max(terms))
