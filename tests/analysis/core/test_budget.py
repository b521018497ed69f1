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


def _spin(seconds: float) -> None:
    """Burn ``seconds`` of this thread's CPU time in pure Python."""
    end = time.thread_time() + seconds
    while time.thread_time() < end:
        pass


def test_the_clock_leaves_out_a_full_collection_of_a_large_heap():
    """A full collection walks every object of the process: its cost is the heap's size, not the step's work.

    With 400,000 container objects alive, ``gc.collect()`` takes tens of milliseconds of CPU; the
    budget's clock advances by the callback's bookkeeping only."""
    import gc

    from dirac.analysis.core.budget import cpu_clock

    heap = [[i] for i in range(400_000)]
    process, clock = time.process_time(), cpu_clock()
    for _ in range(3):
        gc.collect()
    spent_process, spent_clock = time.process_time() - process, cpu_clock() - clock
    assert len(heap) == 400_000
    assert spent_process > 0.01
    assert spent_clock < 0.2 * spent_process


def test_another_thread_does_not_spend_the_budget():
    """Another thread burns 0.6 s of CPU while the step burns 0.3 s of its own inside a budget of 0.5 s.

    The process's CPU time passes 0.5 s (the profiling timer fires), yet the step's thread has used
    only 0.3 s: the timer is set again for what is left and the step runs to its end."""
    import threading

    other = threading.Thread(target=_spin, args=(0.6,))
    budget = CpuBudget(0.5)
    process = time.process_time()
    other.start()
    with budget.interrupting():
        _spin(0.3)
    other.join()
    assert time.process_time() - process > 0.5  # the process did spend more than the budget
    assert not budget.spent


def test_a_step_past_its_budget_is_still_interrupted_while_another_thread_runs():
    import threading

    other = threading.Thread(target=_spin, args=(0.3,))
    budget = CpuBudget(0.1)
    other.start()
    with pytest.raises(OverBudget):
        with budget.interrupting():
            _spin(30.0)
    other.join()
    assert budget.spent
