"""Long runs: invariants at round-off, no secular energy growth.

Full sizes (``DIRAC_FULL_STRESS=1``): ``1e7`` steps of ``lie-poisson-2``, ``1e6`` of
``lie-poisson-4``/``-6`` on the standard body (docs/conventions.md), ``1e6`` steps of
``rattle-2`` on the pendulum and the double pendulum. CI runs them shortened by
:func:`stress_scale`. The criteria are those of :mod:`dirac.bench.stress_criteria`.
"""

from __future__ import annotations

import numpy as np
import pytest
from stress_scaling import stress_scale

from dirac.bench.long_runs import constrained_long_run, long_run
from dirac.bench.stress_criteria import energy_drift_verdict


@pytest.mark.slow
@pytest.mark.parametrize(("method", "full_steps", "dt"), [
    ("lie-poisson-2", 10_000_000, 0.01),
    ("lie-poisson-4", 1_000_000, 0.05),
    ("lie-poisson-6", 1_000_000, 0.05),
])
def test_splitting_keeps_casimir_and_orthogonality_and_bounded_energy(method, full_steps, dt):
    steps = max(10_000, int(full_steps * stress_scale()))
    row = long_run(method, steps, dt)
    assert row["steps"] == steps
    assert row["casimir_error"] <= 2e-12
    assert row["orthogonality_error"] <= 2e-12
    assert row["energy_error_first_tenth"] > 0.0  # a real measurement, not an empty slice
    assert row["passed"], row


@pytest.mark.slow
@pytest.mark.parametrize("system", ["pendulum", "double_pendulum"])
def test_rattle_keeps_the_constraints_at_tolerance_and_bounded_energy(system):
    steps = max(10_000, int(1_000_000 * stress_scale()))
    row = constrained_long_run(system, "rattle-2", steps, 0.01)
    assert row["steps"] == steps
    assert row["position_residual"] <= 1e-12 * 11  # tol (1 + |q|^2), |q|^2 <= 10 for unit rods
    assert row["passed"], row


def test_drift_verdict_tells_bounded_from_secular_growth():
    """The energy criterion itself: an oscillation passes, a linear drift fails."""
    t = np.linspace(0.0, 1000.0, 10_001)
    oscillating = 1e-6 * np.sin(3.0 * t)
    drifting = 1e-9 * t + 1e-7 * np.sin(3.0 * t)
    assert energy_drift_verdict(oscillating, 10**6, 1.0)[2]
    first, last, bounded = energy_drift_verdict(drifting, 10**6, 1.0)
    assert not bounded and last > 5 * first
