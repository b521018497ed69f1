"""The CPU-time budget of optional symbolic steps (:mod:`dirac.analysis.core.budget`)."""

from __future__ import annotations

import time

import pytest

from dirac.analysis.core.budget import CpuBudget, OverBudget


def test_a_step_past_its_budget_is_interrupted():
    """A pure-Python loop that never ends on its own stops with OverBudget once 0.05 s of CPU are spent."""
    budget = CpuBudget(0.05)
    start = time.process_time()
    with pytest.raises(OverBudget):
        with budget.interrupting():
            while True:
                pass
    assert budget.spent
    assert time.process_time() - start < 5.0


def test_a_step_within_its_budget_runs_to_the_end_and_disarms_the_timer():
    import signal

    budget = CpuBudget(30.0)
    with budget.interrupting():
        total = sum(range(1000))
    assert total == 499500 and not budget.spent
    assert signal.getitimer(signal.ITIMER_PROF) == (0.0, 0.0)


def test_a_spent_budget_refuses_the_next_step():
    budget = CpuBudget(0.0)
    with pytest.raises(OverBudget):
        with budget.interrupting():
            pass
