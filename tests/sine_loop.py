"""A small step loop for the tier tests: ``n_steps`` of ``x <- x + sin(x) / 8``, with the
arguments a tier may split (``x, t, dt, n_steps, info``), and the same loop by hand (one
place, so that the interpreted, tape and compiled tests run the same source)."""

from __future__ import annotations

import math

#: the generated-module text of the loop; ``for a test`` is replaced by a per-test tag so that
#: each test gets a module (and caches) of its own
SINE_LOOP = '''"""loop -- generated for a test"""
import math
import numpy as np
import numba


@numba.njit(cache=True)
def run(x, t, dt, n_steps, info):
    """n_steps of x <- x + sin(x) / 8 from time t (a step loop with the arguments a tier may split)."""
    evals = 0.0
    for step in range(n_steps):
        x[0] = x[0] + math.sin(x[0]) / 8.0
        evals += 1.0
    info[0] = n_steps
    info[1] = 0.0
    info[2] = evals
    info[3] = 0.0
'''


def hand_loop(x: float, steps: int) -> float:
    """``steps`` of ``x <- x + sin(x) / 8`` in Python floats: the loop's value by hand."""
    for _ in range(steps):
        x = x + math.sin(x) / 8.0
    return x
