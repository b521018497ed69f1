"""Streaming per-member summaries, updated sample by sample inside a chunk.

A reduction sees the members' state at each sample time ``t_k`` (the scene's sample
grid) and keeps O(1) numbers per member, so an ensemble of 1e7 members that asks only
for reductions needs neither the memory nor the disk of its trajectories.

* ``flip_time`` -- the body axis ``e_a`` turns over with respect to the conserved lab
  angular momentum ``m = R M``: its projection ``(R e_a) . m / |m| = M_a / |M|``
  changes sign. The first sign change of ``M_a`` after ``t = 0`` is located between
  the samples bracketing it by linear interpolation,
  ``t* = t_{k-1} + (t_k - t_{k-1}) M_a(t_{k-1}) / (M_a(t_{k-1}) - M_a(t_k))``.
  ``a`` is a fixed axis or each member's intermediate axis (the tennis-racket flip;
  Ashbaugh, Chicone & Cushman 1991). NaN if no flip happens by ``t_end`` or if
  ``M_a(0) = 0``. Sign changes between two samples that cancel are not seen: choose
  a sample spacing well below the rotation period ``2 pi I_a / |M|``.
* ``max_energy_error`` -- ``max_k |H_0(t_k) - H_0(0)| / H_0(0)``, ``H_0`` of (247).
* ``max_casimir_error`` -- ``max_k ||M(t_k)|^2 - |M(0)|^2| / |M(0)|^2``, Casimir (248).
* ``final_state`` -- ``M`` and ``R`` at ``t_end``.
* ``initial_state`` -- the member's initial ``M``, ``R`` and inertia.
"""

from __future__ import annotations

import numpy as np

__all__ = ["Reduction", "make_reductions", "reduction_arrays"]


def energy_of(M: np.ndarray, inv_inertia: np.ndarray) -> np.ndarray:
    """``H_0 = sum_i M_i^2 / (2 I_i)`` (247) of each member (rows of ``M``).

    The row-wise form of :func:`dirac.rigidbody.euler_poisson.energy` with the members'
    ``1/I`` precomputed; kept separate so stored ensemble arrays keep their bits.
    """
    return 0.5 * np.einsum("ij,ij->i", M * inv_inertia, M)


def casimir_of(M: np.ndarray) -> np.ndarray:
    """``|M|^2``, the Casimir (248), of each member (rows of ``M``)."""
    return np.einsum("ij,ij->i", M, M)


def reduction_arrays(name: str) -> dict[str, tuple[int, ...]]:
    """The arrays a reduction stores: array name -> shape of one member's entry."""
    layouts: dict[str, dict[str, tuple[int, ...]]] = {
        "flip_time": {"flip_time": ()},
        "max_energy_error": {"max_energy_error": ()},
        "max_casimir_error": {"max_casimir_error": ()},
        "final_state": {"final_M": (3,), "final_R": (3, 3)},
        "initial_state": {"initial_M": (3,), "initial_R": (3, 3), "inertia": (3,)},
    }
    return layouts[name]


class Reduction:
    """A streaming summary: :meth:`start` at ``t = 0``, :meth:`update` at each later sample,
    :meth:`result` at the end (arrays with the chunk's members along axis 0)."""

    def start(self, M: np.ndarray, R: np.ndarray, inertia: np.ndarray) -> None:
        """Called with the chunk's initial state (``t = 0``)."""
        raise NotImplementedError  # pragma: no cover - abstract

    def update(self, t_prev: float, t: float, M: np.ndarray, R: np.ndarray) -> None:
        """Called after the members were advanced from ``t_prev`` to ``t``."""

    def result(self) -> dict[str, np.ndarray]:
        """The arrays of :func:`reduction_arrays` for the chunk's members."""
        raise NotImplementedError  # pragma: no cover - abstract


class FlipTime(Reduction):
    """First sign change of ``M_a`` (see the module docstring)."""

    def __init__(self, axis: int | None) -> None:
        self.axis = axis

    def start(self, M: np.ndarray, R: np.ndarray, inertia: np.ndarray) -> None:
        n = M.shape[0]
        self.rows = np.arange(n)
        if self.axis is None:
            self.cols = np.argsort(inertia, axis=1, kind="stable")[:, 1]
        else:
            self.cols = np.full(n, self.axis)
        self.a0 = M[self.rows, self.cols].copy()
        self.prev = self.a0.copy()
        self.time = np.full(n, np.nan)

    def update(self, t_prev: float, t: float, M: np.ndarray, R: np.ndarray) -> None:
        a = M[self.rows, self.cols]
        new = np.isnan(self.time) & (a * self.a0 < 0.0)
        if np.any(new):
            p = self.prev[new]
            self.time[new] = t_prev + (t - t_prev) * (p / (p - a[new]))
        self.prev = a

    def result(self) -> dict[str, np.ndarray]:
        return {"flip_time": self.time}


class MaxRelativeError(Reduction):
    """``max_k |f(t_k) - f(0)| / |f(0)|`` of an invariant ``f`` (absolute if ``f(0) = 0``)."""

    def __init__(self, name: str) -> None:
        self.name = name

    def _value(self, M: np.ndarray) -> np.ndarray:
        if self.name == "max_energy_error":
            return energy_of(M, self.inv)
        return casimir_of(M)

    def start(self, M: np.ndarray, R: np.ndarray, inertia: np.ndarray) -> None:
        self.inv = 1.0 / inertia
        self.f0 = self._value(M)
        self.scale = np.where(self.f0 != 0.0, np.abs(self.f0), 1.0)
        self.error = np.zeros(M.shape[0])

    def update(self, t_prev: float, t: float, M: np.ndarray, R: np.ndarray) -> None:
        np.maximum(self.error, np.abs(self._value(M) - self.f0) / self.scale, out=self.error)

    def result(self) -> dict[str, np.ndarray]:
        return {self.name: self.error}


class FinalState(Reduction):
    """``M`` and ``R`` at the last sample."""

    def start(self, M: np.ndarray, R: np.ndarray, inertia: np.ndarray) -> None:
        self.M, self.R = M, R

    def update(self, t_prev: float, t: float, M: np.ndarray, R: np.ndarray) -> None:
        self.M, self.R = M, R

    def result(self) -> dict[str, np.ndarray]:
        return {"final_M": self.M.copy(), "final_R": self.R.copy()}


class InitialState(Reduction):
    """The member's initial data."""

    def start(self, M: np.ndarray, R: np.ndarray, inertia: np.ndarray) -> None:
        self.data = {"initial_M": M.copy(), "initial_R": R.copy(), "inertia": inertia.copy()}

    def result(self) -> dict[str, np.ndarray]:
        return self.data


def make_reductions(names: tuple[str, ...], flip_axis: int | None) -> list[Reduction]:
    """Fresh reduction objects for one chunk, in the scene's order."""
    made: list[Reduction] = []
    for name in names:
        if name == "flip_time":
            made.append(FlipTime(flip_axis))
        elif name in ("max_energy_error", "max_casimir_error"):
            made.append(MaxRelativeError(name))
        elif name == "final_state":
            made.append(FinalState())
        elif name == "initial_state":
            made.append(InitialState())
        else:  # pragma: no cover - the scene parser rejects unknown names
            raise KeyError(name)
    return made
