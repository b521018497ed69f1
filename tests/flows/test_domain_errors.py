"""A run that leaves the real domain of the system's expressions stops with an IntegrationError.

The interpreted kernels raised Python's own ``ValueError('math domain error')`` or
``ZeroDivisionError`` out of ``dirac.integrate`` (a traceback); the compiled ones give
``nan``, which the loop's finiteness check turns into an ``IntegrationError``. Both roads
now end in an ``IntegrationError`` with the part of the run done so far.
"""

from __future__ import annotations

import pytest

import dirac
from dirac.errors import IntegrationError
from dirac.flows.integration import is_domain_error

# a particle drifting to x < 0 with a tiny potential eps*sqrt(x), defined for x >= 0 only:
# x(t) = 0.5 - t up to O(eps), so the domain ends near t = 0.5
DRIFT = dirac.Lagrangian.from_strings("drift", ["x", "y"], "x_dot**2/2 + y_dot**2/2 - eps*sqrt(x)",
                                      parameters={"eps": 1e-9})
MESSAGES = ("left the real domain", "non-finite values")  # interpreted tier / compiled tier (nan)


@pytest.mark.parametrize("method", ["rattle-2", "midpoint"])
def test_a_run_that_leaves_the_domain_stops_with_the_run_so_far(method):
    problem = dirac.ConstrainedProblem(DRIFT, q0=[0.5, 0.0], p0=[-1.0, 0.0])
    with pytest.raises(IntegrationError) as stopped:
        dirac.integrate(problem, method, t_end=1.0, dt=1e-3, samples=101)
    assert any(m in str(stopped.value) for m in MESSAGES), str(stopped.value)
    partial = stopped.value.partial
    assert partial is not None and not partial.complete
    assert 0.45 <= partial.t[-1] <= 0.5  # the last sample before x = 0.5 - t reaches 0
    assert abs(partial["q"][-1, 0] - (0.5 - partial.t[-1])) < 1e-6


def test_an_initial_state_outside_the_domain_is_an_integration_error():
    problem = dirac.ConstrainedProblem(DRIFT, q0=[-1.0, 0.0], p0=[0.0, 0.0])
    with pytest.raises(IntegrationError, match="no real value at the initial state|non-finite values"):
        dirac.integrate(problem, "rattle-2", t_end=1.0, dt=1e-2, samples=2)


def test_only_domain_errors_are_taken_for_one():
    assert is_domain_error(ValueError("math domain error"))
    assert is_domain_error(ZeroDivisionError("float division by zero"))
    assert is_domain_error(OverflowError("math range error"))
    assert not is_domain_error(ValueError("operands could not be broadcast together"))
