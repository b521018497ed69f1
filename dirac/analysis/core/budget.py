"""CPU-time budgets for optional symbolic steps of the analysis.

A symbolic step whose cost cannot be told in advance (a determinant of rational
functions with square roots, a multivariate gcd, the factorisation of a large
polynomial) runs inside a :class:`CpuBudget`. The budget counts CPU time, not the wall
time, so that the same analysis takes the same road on a busy machine as on a quiet one:
the CPU time of the thread that runs the step, less the time of the full garbage
collections in it (:func:`cpu_clock`). Neither the other threads of the process (a dask
client's, a notebook's) nor a full collection, whose cost is the size of the whole heap of
the process and not the step's doing, spend the step's budget: in a process that had built
half a million objects before, one full collection took 0.6 s, and a search that needs a
quarter of its 2 s budget in a fresh process ran over it. Past the budget the step is
interrupted (:class:`OverBudget`) and the caller takes its numeric road or says in a note
what was not done.

The interruption uses the process's CPU-time interval timer (``ITIMER_PROF``, POSIX, main
thread), which counts every thread and every collection: when it fires before the step's
own clock is spent, it is set again for what is left. Where that timer is not available, or
is already used by someone else (a sampling profiler), the budget is checked only between
steps (:meth:`CpuBudget.check`). :class:`OverBudget` derives from ``BaseException``, like
``KeyboardInterrupt``, so that an ``except Exception`` inside sympy does not swallow it; the
timer fires again every ``REPEAT`` seconds until the step has stopped.
"""

from __future__ import annotations

import gc
import signal
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["CpuBudget", "OverBudget", "cpu_clock"]

#: after the budget is spent, the timer fires again every REPEAT CPU seconds until disarmed
REPEAT = 0.05

_collections = threading.local()  # per thread: CPU seconds in full collections, and the start of one running


def _count_full_collections(phase: str, info: dict) -> None:
    """``gc.callbacks`` entry: adds the CPU time of each full collection (generation 2) to its thread's tally."""
    if info.get("generation") != 2:
        return
    if phase == "start":
        _collections.started = time.thread_time()
    else:
        started = getattr(_collections, "started", None)
        if started is not None:
            _collections.seconds = getattr(_collections, "seconds", 0.0) + time.thread_time() - started
            _collections.started = None


gc.callbacks.append(_count_full_collections)


def cpu_clock() -> float:
    """CPU seconds of the calling thread, less those of its full garbage collections.

    ``time.thread_time()`` minus the time spent in collections of generation 2 (counted by
    a ``gc.callbacks`` entry, Python docs, "gc — Garbage Collector interface"): the clock
    of every budget and deadline of the analysis (see the module docstring for why).
    """
    return time.thread_time() - getattr(_collections, "seconds", 0.0)


class OverBudget(BaseException):  # noqa: N818 - a signal, like KeyboardInterrupt, not an error
    """A step ran over its CPU-time budget."""


class CpuBudget:
    """``seconds`` of CPU time of the constructing thread (:func:`cpu_clock`), counted from construction.

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
        self.deadline = cpu_clock() + self.seconds
        self.interrupted = False  # the timer fired: spent by the kernel's count of the CPU time

    def left(self) -> float:
        """CPU seconds left (negative when spent)."""
        return self.deadline - cpu_clock()

    @property
    def spent(self) -> bool:
        """Whether the budget is used up: by :func:`cpu_clock`, or by the profiling timer that interrupted a step.

        The timer interrupts only once the clock shows less than a millisecond left; ``interrupted`` keeps
        the answer consistent with that interruption (a test saw ``spent`` False after one under load).
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
            left = self.left()
            # the timer counted other threads or a full collection: set it again for what is left; and never
            # raise inside the collector's callback, where the exception would be lost ("Exception ignored")
            if left > 1e-3 or (frame is not None and getattr(frame, "f_code", None) is _count_full_collections.__code__):
                signal.setitimer(signal.ITIMER_PROF, max(left, 1e-3), REPEAT)
                return
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
