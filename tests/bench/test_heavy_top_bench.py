"""The heavy-top part of ``dirac bench``: its cases, rows, anchor and equal-CPU comparison
(no timing assertions)."""

from __future__ import annotations

import numpy as np
import pytest

from dirac.bench.heavy_top import (
    ASYMMETRIC_TOP,
    HeavyTopCase,
    anchor_exact_kick,
    heavy_top_cases,
    run_heavy_top_case,
    spin_over_gravity,
)
from dirac.bench.suite import MethodGrid
from dirac.bench.targets import heavy_top_equal_cpu_target
from dirac.flows import HeavyTopProblem, integrate
from dirac.flows.methods.registry import get_method


@pytest.mark.parametrize("quick", [True, False])
def test_the_fast_top_is_fast_and_the_slow_top_slow(quick):
    """``H_0(M0) = sum M_i^2 / (2 I_i)`` against ``m g |chi|``: for ``M0 = 5 (1, 0.5, 2)``,
    ``I = (1, 2, 3)``: ``H_0 = 25/2 (1 + 0.25/2 + 4/3) = 30.73``, ``m g |chi| = 0.5 sqrt(0.3)
    = 0.2739``, ratio 112.2 (at least the 100 the comparison is about); ``M0 / 10``: 1.12."""
    fast, slow = heavy_top_cases(quick)
    for case, expected in ((fast, 112.2), (slow, 1.122)):
        ratio = spin_over_gravity(case.inertia, case.M0, case.mass_gravity, case.center_of_mass)
        assert ratio == pytest.approx(expected, rel=1e-3)
    assert {g.method for g in fast.grids} >= {"lie-poisson-4", "exact-kick-4"}


@pytest.mark.parametrize("name", ["exact-kick-4", "exact-kick-8"])
def test_the_hand_written_anchor_is_the_same_algorithm(name):
    """The anchor evaluates the same composition by another route (Jacobi functions at
    ``u0 + lam t``, two values of Legendre's ``Pi``, kicks not merged); both are exact flows
    composed in the same order, so they agree to round-off."""
    inertia, M0, mass_gravity, chi = ASYMMETRIC_TOP
    problem = HeavyTopProblem(list(inertia), list(M0), mass_gravity=mass_gravity, center_of_mass=list(chi))
    gammas = np.array(get_method(name).data, dtype=float)
    M, R = np.array(M0), np.eye(3)
    anchor_exact_kick(M, R, 1.0 / np.array(inertia), mass_gravity * np.array(chi), gammas, 0.05, 200)
    package = integrate(problem, name, t_end=10.0, dt=0.05, samples=1, outputs=["M", "R"])
    assert np.abs(package["M"][-1] - M).max() < 1e-11
    assert np.abs(package["R"][-1] - R).max() < 1e-11


def test_heavy_top_rows_carry_errors_against_the_reference():
    """A 4th-order method: halving dt divides the error by about 16; the heavy top keeps
    ``R^T R = 1`` and the vertical lab momentum to round-off, not ``|M|^2`` (left empty)."""
    case = HeavyTopCase("tiny top", "tiny", (1.0, 0.5, 2.0), 2.0,
                        (MethodGrid("exact-kick-4", (0.1, 0.05), "dt"),))
    rows = run_heavy_top_case(case, 1, lambda message: None)
    assert [(r["method"], r["value"]) for r in rows] == [("exact-kick-4", 0.1), ("exact-kick-4", 0.05)]
    assert 10 < rows[0]["error"] / rows[1]["error"] < 24
    for row in rows:
        assert row["casimir_error"] is None
        assert row["orthogonality_error"] < 1e-13 and row["lab_momentum_z_error"] < 1e-13
        assert row["reference_error"] < 1e-10


def _row(method, cpu, error):
    return {"problem": "heavy top (fast)", "method": method, "value": 0.01, "cpu_s": cpu, "error": error}


def test_equal_cpu_comparison_interpolates_log_log():
    """On the log-log line through ``lie-poisson-4``'s (1 ms, 1e-4) and (4 ms, 1e-6) the
    error falls 10x per doubling of CPU, so at 2 ms it is 1e-5: an exact-kick-4 run at 2 ms
    with error 1e-6 is 10x better. A run outside the CPU range is not compared."""
    rows = [_row("lie-poisson-4", 1e-3, 1e-4), _row("lie-poisson-4", 4e-3, 1e-6),
            _row("exact-kick-4", 2e-3, 1e-6), _row("exact-kick-4", 8e-3, 1e-3)]
    target = heavy_top_equal_cpu_target(rows)
    assert target.value == pytest.approx(10.0)
    assert target.met
    assert "over 1 exact-kick-4 runs" in target.detail
    alone = heavy_top_equal_cpu_target([_row("exact-kick-4", 2e-3, 1e-6)])
    assert alone.value is None and alone.met is None
