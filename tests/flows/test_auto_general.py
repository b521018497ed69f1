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


def _double_pendulum_rhs(t, y, g=9.81):
    """Landau & Lifshitz, *Mechanics*, Sect. 5, problem 1, unit masses and rods, solved by hand
    for the angular accelerations (the mass matrix ``[[2, c], [c, 1]]``, ``c = cos(a - b)``,
    inverted in closed form)."""
    import math

    a, b, wa, wb = y
    s, c = math.sin(a - b), math.cos(a - b)
    den = 2.0 - c * c
    return [wa, wb, (-s * (wb * wb + wa * wa * c) - 2.0 * g * math.sin(a) + g * math.sin(b) * c) / den,
            (s * (2.0 * wa * wa + wb * wb * c) + 2.0 * g * (math.sin(a) * c - math.sin(b))) / den]


@pytest.mark.parametrize("tolerance", [1e-6, 1e-8])
def test_auto_meets_the_tolerance_on_the_double_pendulum_in_its_angles(tolerance):
    """The double pendulum in its angles (configuration-dependent mass, no closed form) from
    ``(1, 0.5)`` at rest over ``t = 40``: the largest error of the angles at 41 samples against
    a tight reference (scipy's DOP853 at ``rtol = atol = 1e-13`` on the hand-derived equations
    of motion, which agrees with ``rtol = 1e-12`` to about 1e-11 here) is below ``tolerance``
    and not a thousand times below it."""
    from scipy.integrate import solve_ivp

    from dirac.flows import ConstrainedProblem
    from dirac.model.lagrangian import Lagrangian

    t_end = 40.0
    times = np.linspace(0.0, t_end, 41)
    reference = solve_ivp(_double_pendulum_rhs, (0.0, t_end), [1.0, 0.5, 0.0, 0.0], method="DOP853", rtol=1e-13,
                          atol=1e-13, t_eval=times).y[:2].T
    system = Lagrangian.from_strings("double_pendulum_angles", ["a", "b"],
                                     "a_dot**2 + b_dot**2/2 + a_dot*b_dot*cos(a - b) + 2*g*cos(a) + g*cos(b)",
                                     parameters={"g": 9.81})
    solution = integrate(ConstrainedProblem(system, [1.0, 0.5], [0.0, 0.0]), t_end=t_end, samples=41,
                         outputs=["q"], tolerance=tolerance)
    assert solution.method.startswith("rattle-")
    error = float(np.max(np.abs(np.asarray(solution["q"]) - reference)))
    assert tolerance / 1000 < error < tolerance
