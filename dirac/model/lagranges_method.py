"""The parts of a ``sympy.physics.mechanics.LagrangesMethod`` that :meth:`dirac.Lagrangian.from_sympy` takes.

A ``LagrangesMethod(L, qs, hol_coneqs=...)`` holds the Lagrangian ``L``, the coordinates
``qs`` (``dynamicsymbols``) and the holonomic constraints ``chi(q, t) = 0``: exactly the
input of the Dirac–Bergmann analysis. Its multipliers ``lam1, lam2, ...`` in ``lm.eom``
are those of ``L - lam_a chi_a`` (``lam_coeffs = -d chi/dq``), the engine's ``lambda_a``;
docs/sympy_mechanics.md shows both side by side.

Its ``forcelist`` (loads ``(Point, Vector)`` and torques ``(ReferenceFrame, Vector)`` in
the inertial frame ``N``) becomes generalized forces, as ``LagrangesMethod`` forms them:

    Q_r = sum_i (d v_i / d q_dot_r) . F_i,

with ``v_i`` the velocity of the point (the angular velocity of the frame) in ``N``
(Kane & Levinson, *Dynamics: Theory and Applications*, 1985, Sect. 4.4; the "generalized
forces" of the encyclopedic treatment of Lagrange's equations).

Not taken (refused with a clear error): non-holonomic constraints (the engine treats
holonomic ones).
"""

from __future__ import annotations

from typing import Any

import sympy

from dirac.errors import InputError

__all__ = ["is_lagranges_method", "lagranges_method_parts"]


def is_lagranges_method(value: object) -> bool:
    """Whether ``value`` is a ``sympy.physics.mechanics.LagrangesMethod`` (without importing sympy's mechanics)."""
    return any(cls.__name__ == "LagrangesMethod" and cls.__module__.startswith("sympy.physics.mechanics")
               for cls in type(value).__mro__)


def lagranges_method_parts(
    method: Any,
) -> tuple[sympy.Expr, list[sympy.Expr], list[sympy.Expr], dict[sympy.Expr, sympy.Expr]]:
    """``(L, coordinates, holonomic constraints, generalized forces)`` of a ``LagrangesMethod``.

    The forces map each coordinate ``q_r(t)`` with a nonzero ``Q_r`` to it (see the
    module docstring); empty without a ``forcelist``.

    Raises
    ------
    InputError
        For non-holonomic constraints, or a load that is not a (Point or ReferenceFrame,
        Vector) pair.
    """
    L = method._L[0] if isinstance(method._L, sympy.MatrixBase) else method._L
    coordinates = list(method.q)
    holonomic = list(method._hol_coneqs) if method._hol_coneqs is not None else []
    if len(method.coneqs) > len(holonomic):
        raise InputError(
            f"the LagrangesMethod has {len(method.coneqs) - len(holonomic)} non-holonomic constraint(s) "
            "(nonhol_coneqs): dirac treats holonomic constraints chi(q, t) = 0 only; give them as hol_coneqs"
        )
    return L, coordinates, holonomic, generalized_forces(method)


def generalized_forces(method: Any) -> dict[sympy.Expr, sympy.Expr]:
    """``Q_r = sum_i (d v_i / d q_dot_r) . F_i`` of the loads of a ``LagrangesMethod`` (module docstring)."""
    if not method.forcelist:
        return {}
    from sympy.physics.mechanics import dynamicsymbols
    from sympy.physics.vector import Point, ReferenceFrame, Vector

    frame = method.inertial
    time = dynamicsymbols._t
    forces: dict[sympy.Expr, sympy.Expr] = {}
    for number, load in enumerate(method.forcelist, start=1):
        where, vector = (load[0], load[1]) if len(load) == 2 else (None, None)
        if isinstance(where, Point) and isinstance(vector, Vector):
            velocity = where.vel(frame)
        elif isinstance(where, ReferenceFrame) and isinstance(vector, Vector):
            velocity = where.ang_vel_in(frame)
        else:
            raise InputError(
                f"load {number} of the LagrangesMethod's forcelist is not a (Point, Vector) force or a "
                "(ReferenceFrame, Vector) torque; give each load as such a pair"
            )
        for q in method.q:
            Q = velocity.diff(q.diff(time), frame).dot(vector)
            if Q != 0:
                forces[q] = sympy.simplify(forces.get(q, sympy.S.Zero) + Q)
    return {q: Q for q, Q in forces.items() if Q != 0}
