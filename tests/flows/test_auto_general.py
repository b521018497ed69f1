"""``auto`` on general (constrained) systems: the error it promises, at a sensible price.

Checked against the closed form of the pendulum released from rest (Jacobi's elliptic
functions, ``tests/flows/test_flow_convergence.pendulum_exact``) over many periods, where
the old single pilot at ``t_end / 1000`` with a halved step reached errors 50 times below
the tolerance with 100 times the steps.
"""

from __future__ import annotations

import numpy as np
import pytest

from dirac.flows.integration import integrate
from dirac.flows.methods.auto import newton_tolerance_for


@pytest.mark.parametrize("tolerance", [1e-5, 1e-7])
def test_auto_meets_the_tolerance_over_many_periods_without_overdoing_it(pendulum_system, tolerance):
    """A pendulum at 1 rad (period about 2.15) over ``t = 30``: the largest error of ``q`` and
    ``p`` at 31 samples is below ``tolerance`` and not a thousand times below it."""
    from test_flow_convergence import pendulum_exact

    from dirac.flows import ConstrainedProblem

    theta = 1.0
    problem = ConstrainedProblem(pendulum_system, [np.sin(theta), -np.cos(theta)], [0.0, 0.0])
    solution = integrate(problem, "auto", t_end=30.0, samples=31, outputs=["q", "p"], tolerance=tolerance)
    assert solution.method.startswith("rattle-")
    errors = []
    for k, t in enumerate(np.linspace(0.0, 30.0, 31)):
        q, p = pendulum_exact(theta, t)
        errors.append(max(np.abs(solution["q"][k] - q).max(), np.abs(solution["p"][k] - p).max()))
    assert tolerance / 1000 < max(errors) < tolerance


def test_the_newton_floor_lies_below_the_tolerance():
    """``tolerance * 1e-6`` within ``[1e-14, 1e-12]`` (module docstring of auto)."""
    assert newton_tolerance_for(1e-8) == 1e-14
    assert newton_tolerance_for(1e-7) == pytest.approx(1e-13)
    assert newton_tolerance_for(1e-3) == 1e-12
    assert newton_tolerance_for(1e-12) == 1e-14
