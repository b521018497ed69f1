"""Spherical pendulum (particle on a sphere) in Cartesian coordinates: one holonomic constraint."""

from __future__ import annotations

from dirac.model.lagrangian import Lagrangian


def system() -> Lagrangian:
    """Particle on a sphere (spherical pendulum) in Cartesian coordinates (x, y, z).

    ``L = m/2 (x_dot^2 + y_dot^2 + z_dot^2) - m g z``, ``chi = x^2 + y^2 + z^2 - l^2``:
    the extended Lagrangian (1) with one multiplier. As for the planar pendulum the chain
    has four stages of one constraint each (Sect. X, (205)-(217)), all second class, on
    an 8-dimensional phase space: two physical degrees of freedom. Parameters ``m, g, l``
    (defaults 1, 9.81, 1) stay symbolic until fixed.
    """
    return Lagrangian.from_strings(
        "spherical_pendulum",
        ["x", "y", "z"],
        "m/2*(x_dot**2 + y_dot**2 + z_dot**2) - m*g*z",
        constraints=["x**2 + y**2 + z**2 - l**2"],
        parameters={"m": 1.0, "g": 9.81, "l": 1.0},
        description="particle on a sphere (spherical pendulum) in Cartesian coordinates",
    )
