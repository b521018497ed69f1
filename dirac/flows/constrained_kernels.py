"""Calling the ``numba.cfunc`` functions of :mod:`dirac.codegen.numba_backend` from Python.

The step loops of general systems are no longer here: every mechanical and analysed
system gets its own kernel module from :mod:`dirac.codegen.kernel_source` (RATTLE, the
Dirac field, the midpoint rule, energies and residuals, with its expressions inlined).
What remains evaluates a generated ``f(x, params, out)`` at one point.
"""

import warnings

import numba
import numpy as np


def _experimental_feature_warning() -> type[Warning]:
    """First-class function types are flagged experimental by numba; they are what we need."""
    try:
        from numba.core.errors import NumbaExperimentalFeatureWarning
    except ImportError:  # pragma: no cover
        return Warning
    return NumbaExperimentalFeatureWarning


NumbaExperimentalFeatureWarning = _experimental_feature_warning()


class quiet(warnings.catch_warnings):
    """Context that hides numba's 'first-class function type is experimental' warning,
    which numba issues on every call of a kernel taking the generated functions."""

    def __enter__(self):
        result = super().__enter__()
        warnings.filterwarnings("ignore", category=NumbaExperimentalFeatureWarning)
        return result


@numba.njit(cache=True)
def evaluate(f, x, params, out):
    """Call a generated function from Python: ``f(x, params, out)``."""
    f(x, params, out)


def call(f: object, x: np.ndarray, params: np.ndarray, size: int) -> np.ndarray:
    """``f(x, params, out)`` from Python with a fresh flat ``out`` of ``size`` entries, returned."""
    out = np.empty(size)
    with quiet():
        evaluate(f, np.ascontiguousarray(x, dtype=float), params, out)
    return out
