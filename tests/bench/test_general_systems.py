"""The general-systems table of ``dirac bench``: its hand-written anchors run the same
algorithm as the package (same states to round-off), and the table and targets are
built from the measured rows (no timing assertions)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from dirac.bench import general_anchors
from dirac.bench.general_systems import GeneralRow, _agreement, _cases, format_general_rows, general_system_targets


@pytest.fixture(scope="module")
def cases():
    return _cases()


def test_every_anchor_runs_the_package_algorithm(cases):
    """After 1000 steps the hand-written kernel and the package's method reach the same
    state to round-off: the same iteration on the same equations (a different algorithm,
    or the same one with another step or tolerance, would differ by its truncation error,
    1e-7 or more here)."""
    assert [case.method for case in cases] == ["rattle-2", "rattle-2", "rattle-2", "midpoint"]
    for case in cases:
        assert _agreement(case) <= 1e-11, case.system


def test_pendulum_anchor_keeps_the_constraints_and_the_energy():
    """The anchor is RATTLE: x^2 + y^2 = l^2 and x p_x + y p_y = 0 to round-off, and the
    energy H = |p|^2/2 + g y is kept to O(dt^2) (symplectic, bounded error)."""
    theta = 1.0
    q = np.array([math.sin(theta), -math.cos(theta)])
    p = np.zeros(2)
    energy0 = 9.81 * q[1]
    assert general_anchors.pendulum_rattle(q, p, 1.0, 9.81, 1.0, 1e-3, 5000, 1e-12, 50) == 5000
    assert abs(q @ q - 1.0) <= 1e-12 and abs(q @ p) <= 1e-12
    assert abs(p @ p / 2 + 9.81 * q[1] - energy0) <= 1e-4


def test_first_order_anchor_is_the_harmonic_rotation():
    """L = x y_dot - (x^2 + y^2)/2 gives x_dot = -y, y_dot = x: a rotation at unit rate,
    which the midpoint rule follows with a phase error O(dt^2) and no growth of x^2 + y^2
    (a quadratic invariant, kept exactly)."""
    z = np.array([1.0, 0.0, 0.0, 0.0, 1.0, 0.0])
    n = 1000
    assert general_anchors.first_order_midpoint(z, 1e-3, n, 1e-12, 50) == n
    assert z[0] ** 2 + z[1] ** 2 == pytest.approx(1.0, abs=1e-12)
    assert z[:2] == pytest.approx([math.cos(1.0), math.sin(1.0)], abs=1e-6)
    assert z[3] == 0.0 and z[4] == pytest.approx(z[0], abs=1e-14)


def test_targets_and_table_come_from_the_rows():
    rows = [GeneralRow("pendulum (Cartesian, m = 1)", "rattle-2", 60.0, 40.0, 1e-15, 100),
            GeneralRow("pendulum (polar, M = diag(m, m r^2))", "rattle-2", 300.0, 150.0, 1e-13, 100)]
    targets = general_system_targets(rows)
    assert [t.name for t in targets] == ["general: rattle-2 step / hand-written numba RATTLE, pendulum"]
    assert targets[0].value == pytest.approx(1.5) and targets[0].met
    table = format_general_rows(rows)
    assert "pendulum (polar" in table and "2.00" in table
