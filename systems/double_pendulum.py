"""Planar double pendulum in Cartesian coordinates: two holonomic constraints."""

from __future__ import annotations

from dirac.model.lagrangian import Lagrangian


def system() -> Lagrangian:
    """Planar double pendulum in Cartesian coordinates (x1, y1, x2, y2), two rod constraints.

    ``L = m1/2 (x1_dot^2 + y1_dot^2) + m2/2 (x2_dot^2 + y2_dot^2) - g (m1 y1 + m2 y2)``
    with ``chi_1 = x1^2 + y1^2 - l1^2`` and ``chi_2 = (x2 - x1)^2 + (y2 - y1)^2 - l2^2``:
    the extended Lagrangian (1) with two multipliers. The chain has four stages of two
    constraints each (Sect. X, (205)-(217)), all second class, on a 12-dimensional phase
    space: two physical degrees of freedom. Parameters ``m1, m2, g, l1, l2`` stay symbolic
    until fixed.
    """
    return Lagrangian.from_strings(
        "double_pendulum",
        ["x1", "y1", "x2", "y2"],
        "m1/2*(x1_dot**2 + y1_dot**2) + m2/2*(x2_dot**2 + y2_dot**2) - g*(m1*y1 + m2*y2)",
        constraints=["x1**2 + y1**2 - l1**2", "(x2 - x1)**2 + (y2 - y1)**2 - l2**2"],
        parameters={"m1": 1.0, "m2": 1.0, "g": 9.81, "l1": 1.0, "l2": 1.0},
        description="planar double pendulum in Cartesian coordinates",
    )
