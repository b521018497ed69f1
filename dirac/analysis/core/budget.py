"""CPU-time budgets for optional symbolic steps of the analysis.

A symbolic step whose cost cannot be told in advance (a determinant of rational
functions with square roots, a multivariate gcd, the factorisation of a large
polynomial) runs inside a :class:`CpuBudget`. The budget counts the CPU time of the
process (``time.process_time``), not the wall time, so that the same analysis takes the
same road on a busy machine as on a quiet one. Past the budget the step is interrupted
(:class:`OverBudget`) and the caller takes its numeric road or says in a note what was not
done.

The interruption uses the process's CPU-time interval timer (``ITIMER_PROF``, POSIX, main
thread). Where that timer is not available, or is already used by someone else (a
sampling profiler), the budget is checked only between steps (:meth:`CpuBudget.check`).
:class:`OverBudget` derives from ``BaseException``, like ``KeyboardInterrupt``, so that an
``except Exception`` inside sympy does not swallow it; the timer fires again every
``REPEAT`` seconds until the step has stopped.
"""

from __future__ import annotations

import signal
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["CpuBudget", "OverBudget"]

#: after the budget is spent, the timer fires again every REPEAT CPU seconds until disarmed
REPEAT = 0.05


class OverBudget(BaseException):  # noqa: N818 - a signal, like KeyboardInterrupt, not an error
    """A step ran over its CPU-time budget."""


class CpuBudget:
    """``seconds`` of process CPU time, counted from construction.

    Examples
    --------
    >>> budget = CpuBudget(2.0)
    >>> try:
    ...     with budget.interrupting():
    ...         pass  # a long symbolic step
    ... except OverBudget:
    ...     pass  # the numeric road, or a note
    >>> budget.left() > 0
    True
    """

    def __init__(self, seconds: float) -> None:
        self.seconds = float(seconds)
        self.deadline = time.process_time() + self.seconds
        self.interrupted = False  # the timer fired: spent by the kernel's count of the CPU time

    def left(self) -> float:
        """CPU seconds left (negative when spent)."""
        return self.deadline - time.process_time()

    @property
    def spent(self) -> bool:
        """Whether the budget is used up: by ``process_time``, or by the profiling timer that interrupted a step.

        The two count the same CPU time with different granularity: under load the timer fired while
        ``process_time`` still showed a little left (a test saw ``spent`` False after the interruption).
        """
        return self.interrupted or self.left() <= 0.0

    def check(self) -> None:
        """Raise :class:`OverBudget` when the budget is spent."""
        if self.spent:
            raise OverBudget

    @contextmanager
    def interrupting(self) -> Iterator[None]:
        """Run the enclosed step and interrupt it with :class:`OverBudget` when the budget is spent."""
        self.check()
        usable = (
            hasattr(signal, "setitimer")
            and threading.current_thread() is threading.main_thread()
            and signal.getsignal(signal.SIGPROF) in (signal.SIG_DFL, None)
            and signal.getitimer(signal.ITIMER_PROF) == (0.0, 0.0)
        )
        if not usable:
            yield
            self.check()
            return

        def over(signum: int, frame: object) -> None:
            self.interrupted = True
            raise OverBudget

        previous = signal.signal(signal.SIGPROF, over)
        try:
            signal.setitimer(signal.ITIMER_PROF, max(self.left(), 1e-3), REPEAT)
            try:
                yield
            finally:
                signal.setitimer(signal.ITIMER_PROF, 0.0)
        finally:
            signal.signal(signal.SIGPROF, previous)
