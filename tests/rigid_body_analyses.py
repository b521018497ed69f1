"""Shared helpers of the rigid-body engine tests (a plain module, not a conftest).

The engine analyses of the rigid-body systems take seconds each, so every test file
reuses one analysis per system for the whole session.
"""

from __future__ import annotations

import numpy as np
import pytest

import dirac


def cached_analysis(config: pytest.Config, name: str):
    """One engine analysis per built-in system for the whole test session."""
    store = config.__dict__.setdefault("_dirac_rigid_body_analyses", {})
    if name not in store:
        store[name] = dirac.analyze(dirac.load_system(name))
    return store[name]


def eps(i: int, j: int, k: int) -> int:
    """Levi-Civita symbol of indices in 1..3."""
    return int((i - j) * (j - k) * (k - i) / 2)


def hat(w: np.ndarray) -> np.ndarray:
    """``hat(w) v = w x v`` (docs/conventions.md)."""
    return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]], dtype=float)
