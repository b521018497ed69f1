"""Angular impulses on a rigid body or heavy top: ``M`` jumps by ``J`` (body frame) at ``t``.

An impulse is the time integral of a short, strong torque; over its vanishing duration
``R`` does not move, so ``M(t+) = M(t-) + J`` and the work done is the jump of the kinetic
energy, ``E(M + J) - E(M)`` (Euler's equations with a torque; for generalised impulses,
Lagrange's ``dT/dq_dot_r = Q_r'``). Kept apart from :mod:`dirac.flows.torques` so that a
problem without a torque never imports the expression parser.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from dirac.errors import InputError
from dirac.validate import validate_array, validate_finite

__all__ = ["AngularImpulse", "validate_impulses"]


@dataclass(frozen=True)
class AngularImpulse:
    """An angular impulse ``J`` (body frame) at time ``t``: ``M`` jumps by ``J``.

    Raises
    ------
    InputError
        ``t`` negative or not finite, ``J`` not three finite numbers.
    """

    t: float
    vector: np.ndarray

    def __post_init__(self) -> None:
        t = validate_finite(self.t, "impulse time t")
        if t < 0:
            raise InputError(f"an impulse at t = {t:g} is before the start of the run (t = 0); give t >= 0")
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "vector", validate_array(self.vector, "angular_impulse", (3,)))


def validate_impulses(impulses: Sequence[object]) -> tuple[AngularImpulse, ...]:
    """The impulses as :class:`AngularImpulse`, sorted by time (``(t, [a, b, c])`` pairs or
    :class:`AngularImpulse`); two at the same time are added."""
    result: list[AngularImpulse] = []
    for item in impulses:
        if isinstance(item, AngularImpulse):
            result.append(item)
            continue
        if isinstance(item, dict) and set(item) == {"t", "angular_impulse"}:
            result.append(AngularImpulse(item["t"], item["angular_impulse"]))  # type: ignore[arg-type]
            continue
        if isinstance(item, (tuple, list)) and len(item) == 2:
            result.append(AngularImpulse(item[0], item[1]))  # type: ignore[arg-type]
            continue
        raise InputError(f"an angular impulse is a pair (t, [a, b, c]) or an AngularImpulse, got {item!r}")
    result.sort(key=lambda impulse: impulse.t)
    merged: list[AngularImpulse] = []
    for impulse in result:
        if merged and math.isclose(merged[-1].t, impulse.t, rel_tol=0.0, abs_tol=0.0):
            merged[-1] = AngularImpulse(impulse.t, merged[-1].vector + impulse.vector)
        else:
            merged.append(impulse)
    return tuple(merged)

