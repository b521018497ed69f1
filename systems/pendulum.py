"""Planar pendulum in Cartesian coordinates: one holonomic constraint."""

from __future__ import annotations

from dirac.model.lagrangian import Lagrangian


def system() -> Lagrangian:
    """Planar pendulum in Cartesian coordinates (x, y), constraint x^2 + y^2 = l^2.

    ``L = m/2 (x_dot^2 + y_dot^2) - m g y``, ``chi = x^2 + y^2 - l^2``. With the
    multiplier as a coordinate the Dirac chain has four stages of one constraint each,
    all second class; one physical degree of freedom. Parameters ``m, g, l`` (defaults
    1, 9.81, 1) stay symbolic until fixed.
    """
    return Lagrangian.from_strings(
        "pendulum",
        ["x", "y"],
        "m/2*(x_dot**2 + y_dot**2) - m*g*y",
        constraints=["x**2 + y**2 - l**2"],
        parameters={"m": 1.0, "g": 9.81, "l": 1.0},
        description="planar pendulum in Cartesian coordinates",
    )
