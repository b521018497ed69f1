"""Pass/fail criteria of ``dirac bench --stress`` shared by its parts.

* The energy ``H_0`` (247) error of a long run must not grow secularly: its maximum over the
  last tenth of the run may exceed that over the first tenth by at most a factor 2 plus a
  round-off allowance ``10 eps sqrt(steps) |H_0|`` (a linear drift gives a factor of about
  10) -- :func:`energy_drift_verdict`.
* Invariants kept by construction (the Casimir ``|M|^2``, ``R^T R = 1``) may move by the
  round-off random walk of ``1e7`` steps: :data:`INVARIANT_LIMIT`.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["EPS", "INVARIANT_LIMIT", "energy_drift_verdict"]

EPS = float(np.finfo(float).eps)

#: Largest deviation of ``|M|^2`` and of ``R^T R`` from 1 allowed in a long run.
INVARIANT_LIMIT = 2e-12


def energy_drift_verdict(energy_error: np.ndarray, steps: int, energy: float) -> tuple[float, float, bool]:
    """``(max over first tenth, max over last tenth, bounded?)`` of an energy error series.

    Bounded means ``last <= 2 first + 10 eps sqrt(steps) |energy|`` (module docstring).
    """
    error = np.abs(np.asarray(energy_error, dtype=float))
    tenth = max(1, error.shape[0] // 10)
    first = float(np.max(error[1 : tenth + 1])) if error.shape[0] > 1 else float(error[0])
    last = float(np.max(error[-tenth:]))
    allowance = 10.0 * EPS * math.sqrt(max(steps, 1)) * abs(energy)
    return first, last, bool(last <= 2.0 * first + allowance)
