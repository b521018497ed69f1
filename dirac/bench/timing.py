"""Timing harness: medians of repeats, warm-up outside the timed region.

Every timed call is made once untimed first (compilation, caches, imports), then
``repeats`` times; the median is reported (robust against the noise of shared machines)
together with the minimum. CPU time is ``time.process_time`` (all threads of the
process); wall time is ``time.perf_counter``.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, TypeVar, overload

__all__ = ["Timing", "time_call", "median_of"]

_Input = TypeVar("_Input")


@dataclass(frozen=True)
class Timing:
    """Median and minimum of the repeats of one timed call (seconds)."""

    cpu: float
    wall: float
    cpu_min: float
    wall_min: float
    repeats: int
    result: Any = None


def median_of(values: list[float]) -> float:
    """Median of a non-empty list."""
    return float(statistics.median(values))


@overload
def time_call(function: Callable[[], Any], repeats: int, warm_up: bool = True,
              setup: None = None) -> Timing: ...


@overload
def time_call(function: Callable[[_Input], Any], repeats: int, warm_up: bool = True, *,
              setup: Callable[[], _Input]) -> Timing: ...


def time_call(function: Callable[..., Any], repeats: int, warm_up: bool = True,
              setup: Callable[[], Any] | None = None) -> Timing:
    """Time ``function()`` ``repeats`` times after one untimed warm-up call.

    Parameters
    ----------
    function : callable
        Called with no arguments; if ``setup`` is given, called as ``function(setup())``
        with ``setup`` outside the timed region (fresh input state for in-place kernels).
    repeats : int
        Number of timed calls (>= 1).
    warm_up : bool
        Make one untimed call first.
    setup : callable, optional

    Returns
    -------
    Timing
        Medians and minima of CPU and wall time; ``result`` is the last call's return value.
    """
    def call() -> tuple[float, float, Any]:
        argument = setup() if setup is not None else None
        c0 = time.process_time()
        w0 = time.perf_counter()
        result = function(argument) if setup is not None else function()
        w1 = time.perf_counter()
        c1 = time.process_time()
        return c1 - c0, w1 - w0, result

    if warm_up:
        call()
    cpus, walls = [], []
    result = None
    for _ in range(max(1, int(repeats))):
        cpu, wall, result = call()
        cpus.append(cpu)
        walls.append(wall)
    return Timing(median_of(cpus), median_of(walls), min(cpus), min(walls), len(cpus), result)
