"""A guard that stops a run near a coordinate singularity of its chart.

The equations of motion of ``L = q_dot^T W(q) q_dot / 2 - V(q)`` solve the velocities
from the momenta, ``q_dot = W^{-1} p``: they divide by ``det W``. Where ``det W``
vanishes on a locus of configurations (``sin(theta) = 0`` for Euler angles, the poles of
a sphere in polar angles) the coordinates, not the motion, are singular (a coordinate
singularity: Arnold, "Mathematical Methods of Classical Mechanics", Sect. 30; Goldstein,
Sect. 4.4 on the gimbal-lock of Euler angles). Near it the velocities grow like
``1/det W`` and a fixed step loses its accuracy without a word (a top in Euler angles
passing ``theta = 4e-4`` keeps a 1 % energy error), or its Newton iteration fails.

:class:`ChartGuard` measures how close a configuration is to the locus by the Hadamard
ratio ``r(q) = |det W| / prod_i |W_i|`` (``|W_i|`` the Euclidean norm of row ``i``;
``0 <= r <= 1`` by Hadamard's inequality, 1 for orthogonal rows, 0 on the locus; ``r ~
sin(theta)^2`` for Euler angles), compiled as one scalar function. The loop of
:func:`dirac.flows.integrate` evaluates it every ``GUARD_STEPS`` steps, every step once
``r < WATCH_RATIO``, and stops with :class:`~dirac.errors.CoordinateSingularityError`
when ``r < STOP_RATIO``, naming the locus, the time and another chart. Systems whose
``det W`` is constant or never vanishes (Cartesian coordinates, a rotation matrix) have no
guard and run exactly as before.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

__all__ = ["ChartGuard", "chart_guard", "GUARD_STEPS", "WATCH_RATIO", "STOP_RATIO"]

#: steps between two evaluations of the guard away from the locus
GUARD_STEPS = 32
#: below this ratio the guard is evaluated at every step
WATCH_RATIO = 1e-2
#: below this ratio the run stops (``sin(theta) ~ 1e-2`` for Euler angles)
STOP_RATIO = 1e-4
#: largest number of coordinates for which ``det W`` is formed symbolically
MAX_GUARD_DIMENSION = 8

REMEDY = (
    "describe the motion in another chart: for a rigid body or a top, its rotation matrix (the rigid-body or "
    "heavy-top scene, HeavyTopProblem, or the rigid_body_matrix system); otherwise Cartesian coordinates with a "
    "holonomic constraint (a spherical pendulum as x, y, z with x**2 + y**2 + z**2 = l**2)"
)


class ChartGuard:
    """The Hadamard ratio of the mass matrix ``W(q, t)`` of one system, compiled (see the module docstring).

    Attributes
    ----------
    locus
        The locus as text (``"sin(theta) = 0"``): the factors of ``det W`` that can vanish.
    """

    def __init__(self, ratio: Callable[..., list[float]], locus: str, time: bool, params: np.ndarray) -> None:
        self._ratio = ratio
        self.locus = locus
        self._time = time
        self._params = [float(c) for c in params]

    def ratio(self, q: np.ndarray, t: float = 0.0) -> float:
        """The smallest ``r(q)`` over a batch of configurations ``q`` (shape ``(n,)`` or ``(B, n)``)."""
        rows = np.atleast_2d(np.asarray(q, dtype=float))
        extra = [float(t)] if self._time else []
        values = [self._ratio(*row.tolist(), *extra, *self._params)[0] for row in rows]
        finite = [v for v in values if np.isfinite(v)]
        return 0.0 if len(finite) < len(values) else float(min(finite))

    def message(self, system: str, ratio: float, where: str) -> str:
        """The error text: the locus, how near, where (time, step, method) and the remedy."""
        return (
            f"the run of {system!r} came near a coordinate singularity of its coordinates, {self.locus} "
            f"(det W = 0, W = d^2 L/dq_dot^2; |det W| is {ratio:.1e} of the product of its row norms) {where}: "
            f"the equations of motion divide by det W there, so a fixed step loses its accuracy; {REMEDY}"
        )


def _build(mechanics: Any) -> ChartGuard | None:
    import sympy  # not at import: a run without a guard never needs it

    from dirac.analysis.core.divisors import denominator_factors
    from dirac.codegen.scalar_backend import scalar_function

    symbolic = mechanics.symbolic
    W = symbolic.get("mass")
    q = list(symbolic.get("coordinates") or ())
    if W is None or not q or mechanics.constant_mass is not None or W.shape[0] > MAX_GUARD_DIMENSION:
        return None
    W = sympy.Matrix(W)
    det = W.det(method="berkowitz")
    locus = denominator_factors(1 / det, q)
    if not locus:
        return None  # det W constant or never zero: nothing to guard
    params = list(symbolic.get("parameters") or ())
    time = mechanics.time_symbol
    norms = sympy.Mul(*[sympy.sqrt(sum(W[i, j] ** 2 for j in range(W.shape[1]))) for i in range(W.shape[0])])
    arguments = [*q, *([time] if time is not None else []), *params]
    try:
        compiled = scalar_function(arguments, [sympy.Abs(det) / norms])
    except Exception:  # an unusual function in W: no guard (the run is as before)  # noqa: BLE001
        return None
    return ChartGuard(compiled, " and ".join(f"{f} = 0" for f in locus), time is not None, mechanics.params)


def chart_guard(mechanics: Any) -> ChartGuard | None:
    """The :class:`ChartGuard` of a :class:`~dirac.flows.mechanics.MechanicalSystem` (built once), or ``None``."""
    cached = getattr(mechanics, "_chart_guard", False)
    if cached is False:
        cached = _build(mechanics)
        try:
            mechanics._chart_guard = cached
        except AttributeError:  # a frozen system: build again next time
            pass
    return cached
