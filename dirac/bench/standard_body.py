"""The standard free body of the benchmarks: ``I = (2, 1, 2/3)``, ``M(0) = (cos 1.1, 0, sin 1.1)``.

Hairer, Lubich & Wanner's rigid-body example (docs/conventions.md), with ``R(0) = 1``. It
is no physical body (``1 + 2/3 < 2`` breaks the triangle inequality of the moments), so
building it warns; :func:`quietly` builds a problem without that warning.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from typing import TypeVar

__all__ = ["STANDARD_INERTIA", "STANDARD_M0", "quietly"]

T = TypeVar("T")

#: The standard body (no physical body: 1 + 2/3 < 2; warned about).
STANDARD_INERTIA = (2.0, 1.0, 2.0 / 3.0)
STANDARD_M0 = (math.cos(1.1), 0.0, math.sin(1.1))


def quietly(factory: Callable[[], T]) -> T:
    """``factory()`` with the project's warnings (e.g. the triangle inequality) silenced."""
    from dirac.errors import DiracWarning

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DiracWarning)
        return factory()
