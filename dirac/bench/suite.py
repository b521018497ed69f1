"""The benchmark suite: problems, methods and the step sizes / tolerances of each.

Methods: the documented names (docs/integrators.md) plus ``lie-poisson-sym-*``, the compositions
of the symmetric-top splitting (Fassò 2003; registered package methods).

Rigid bodies (the standard test case of docs/conventions.md and two variants), integrated to ``T = 100`` with ``M`` and
``R``; the pendulum and the double pendulum (Cartesian coordinates, holonomic
constraints) with RATTLE and the scipy baselines. ``quick`` selects a subset of the same
grid so that ``dirac bench --quick`` stays under a minute.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from dirac.bench.standard_body import STANDARD_INERTIA, STANDARD_M0

__all__ = ["RigidBodyCase", "ConstrainedCase", "rigid_body_cases", "constrained_cases", "MethodGrid"]


@dataclass(frozen=True)
class MethodGrid:
    """A method and its parameters: step sizes (fixed-step) or tolerances (adaptive)."""

    method: str
    values: tuple[float | None, ...]
    parameter: str  # "dt", "tolerance" or "" (exact)


@dataclass(frozen=True)
class RigidBodyCase:
    """A free rigid body with ``R(0) = 1``."""

    name: str
    description: str
    inertia: tuple[float, float, float]
    M0: tuple[float, float, float]
    t_end: float
    grids: tuple[MethodGrid, ...] = field(default=())


@dataclass(frozen=True)
class ConstrainedCase:
    """A constrained planar system (built-in system name) with its initial angles."""

    name: str
    description: str
    system: str
    angles: tuple[float, ...]
    periods: float  # pendulum: whole periods; double pendulum: t_end
    grids: tuple[MethodGrid, ...] = field(default=())


def _rigid_grids(quick: bool) -> tuple[MethodGrid, ...]:
    if quick:
        return (
            MethodGrid("lie-poisson-2", (0.01, 0.001), "dt"),
            MethodGrid("lie-poisson-4", (0.1, 0.025), "dt"),
            MethodGrid("lie-poisson-6", (0.2, 0.1), "dt"),
            MethodGrid("lie-poisson-8", (0.5, 0.25, 0.125), "dt"),
            MethodGrid("lie-poisson-sym-6", (0.25,), "dt"),
            MethodGrid("lie-poisson-sym-8", (0.5, 0.35, 0.25), "dt"),
            MethodGrid("midpoint", (0.01,), "dt"),
            MethodGrid("exact", (None,), ""),
            MethodGrid("scipy-RK45", (1e-6, 1e-9), "tolerance"),
            MethodGrid("scipy-DOP853", (1e-8, 1e-10, 1e-12), "tolerance"),
        )
    return (
        MethodGrid("lie-poisson-2", (0.1, 0.03, 0.01, 0.003, 0.001, 0.0003, 0.0001), "dt"),
        MethodGrid("lie-poisson-4", (0.2, 0.1, 0.05, 0.025, 0.0125, 0.00625), "dt"),
        MethodGrid("lie-poisson-6", (0.4, 0.3, 0.2, 0.1, 0.05, 0.025), "dt"),
        MethodGrid("lie-poisson-8", (0.5, 0.35, 0.25, 0.18, 0.125, 0.09, 0.0625), "dt"),
        MethodGrid("lie-poisson-sym-4", (0.1, 0.05, 0.025, 0.0125), "dt"),
        MethodGrid("lie-poisson-sym-6", (0.5, 0.35, 0.25, 0.18, 0.125, 0.09), "dt"),
        MethodGrid("lie-poisson-sym-8", (0.7, 0.5, 0.35, 0.25, 0.18, 0.125), "dt"),
        MethodGrid("midpoint", (0.05, 0.02, 0.01, 0.005, 0.002), "dt"),
        MethodGrid("exact", (None,), ""),
        MethodGrid("scipy-RK45", (1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10), "tolerance"),
        MethodGrid(
            "scipy-DOP853",
            (1e-6, 1e-7, 1e-8, 3e-9, 1e-9, 3e-10, 1e-10, 3e-11, 1e-11, 1e-12, 1e-13),
            "tolerance",
        ),
    )


def rigid_body_cases(quick: bool) -> list[RigidBodyCase]:
    """The rigid bodies of the suite (``quick``: the standard body only)."""
    grids = _rigid_grids(quick)
    near = np.array([1e-3, 1.0, 1e-3])
    near = near / np.linalg.norm(near)
    cases = [
        RigidBodyCase(
            "standard",
            "I = (2, 1, 2/3), M(0) = (cos 1.1, 0, sin 1.1), T = 100 (the standard test case of Hairer, Lubich & Wanner)",
            STANDARD_INERTIA,
            STANDARD_M0,
            100.0,
            grids,
        ),
        RigidBodyCase(
            "variant",
            "I = (1.6, 1, 2/3), M(0) = (cos 0.9, 0, sin 0.9), T = 100",
            (1.6, 1.0, 2.0 / 3.0),
            (math.cos(0.9), 0.0, math.sin(0.9)),
            100.0,
            grids,
        ),
        RigidBodyCase(
            "separatrix",
            "I = (1, 2, 3), M(0) = (1e-3, 1, 1e-3)/|.| (near the separatrix), T = 100",
            (1.0, 2.0, 3.0),
            (float(near[0]), float(near[1]), float(near[2])),
            100.0,
            grids,
        ),
    ]
    return cases[:1] if quick else cases


def constrained_cases(quick: bool) -> list[ConstrainedCase]:
    """The pendulum (10 periods) and the double pendulum (``T = 10``)."""
    pendulum_grids: tuple[MethodGrid, ...]
    double_grids: tuple[MethodGrid, ...]
    if quick:
        # no scipy baseline here: its first use compiles the Dirac vector field of each
        # system, too slow for a first --quick run on a fresh install (the full run has it)
        pendulum_grids = (
            MethodGrid("rattle-2", (0.01, 0.001), "dt"),
            MethodGrid("rattle-4", (0.02, 0.005), "dt"),
        )
        double_grids = (
            MethodGrid("rattle-2", (0.001,), "dt"),
            MethodGrid("rattle-4", (0.01,), "dt"),
        )
    else:
        pendulum_grids = (
            MethodGrid("rattle-2", (0.02, 0.01, 0.005, 0.002, 0.001, 0.0005), "dt"),
            MethodGrid("rattle-4", (0.05, 0.02, 0.01, 0.005, 0.002), "dt"),
            MethodGrid("midpoint", (0.01,), "dt"),
            MethodGrid("scipy-RK45", (1e-6, 1e-8), "tolerance"),
            MethodGrid("scipy-DOP853", (1e-7, 1e-9, 1e-11), "tolerance"),
        )
        double_grids = (
            MethodGrid("rattle-2", (0.005, 0.002, 0.001, 0.0005), "dt"),
            MethodGrid("rattle-4", (0.02, 0.01, 0.005, 0.002), "dt"),
            MethodGrid("scipy-RK45", (1e-6,), "tolerance"),
            MethodGrid("scipy-DOP853", (1e-7, 1e-9), "tolerance"),
        )
    return [
        ConstrainedCase(
            "pendulum",
            "planar pendulum (x, y), l = g/9.81 = m = 1, released at 1 rad, 10 exact periods",
            "pendulum",
            (1.0,),
            10.0,
            pendulum_grids,
        ),
        ConstrainedCase(
            "double pendulum",
            "planar double pendulum (x1, y1, x2, y2), released at (0.6, 0.3) rad, T = 10",
            "double_pendulum",
            (0.6, 0.3),
            10.0,
            double_grids,
        ),
    ]
