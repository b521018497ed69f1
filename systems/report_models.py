"""Everyday systems as users write them, for the time of ``dirac analyze`` with its report.

Each function returns a :class:`dirac.Lagrangian` with symbolic parameters (the top's carry the
values the latency corpus runs it at; the analysis keeps them symbolic), written the way
a new user writes it (``Lagrangian.from_strings``): Cartesian coordinates with rod
constraints, angles with configuration-dependent inertia, a trigonometric holonomic
constraint. They were chosen because their reports, not their analyses, once took long:
a divisor's expansion, a ``trigsimp`` that did not end, the inverse of a trigonometric
mass matrix (docs/performance.md, "Reports of everyday systems").
"""

from __future__ import annotations

import dirac

from .latency_models import asymmetric_top_euler as asymmetric_top_model

__all__ = ["MODELS", "asymmetric_top_euler", "pendulum_on_a_cart", "slider_crank", "spherical_double_pendulum",
           "triple_pendulum_angles", "triple_pendulum_cartesian"]


def pendulum_on_a_cart() -> dirac.Lagrangian:
    """A cart ``X`` of mass ``M`` with a bob ``(x, y)`` of mass ``m`` on a rod of length ``l``."""
    return dirac.Lagrangian.from_strings(
        "pendulum_on_a_cart", ["X", "x", "y"], "M/2*X_dot**2 + m/2*(x_dot**2 + y_dot**2) - m*g*y",
        constraints=["(x - X)**2 + y**2 - l**2"], parameters={"M": None, "m": None, "g": None, "l": None})


def triple_pendulum_cartesian() -> dirac.Lagrangian:
    """Three unit bobs on unit rods in Cartesian coordinates, gravity ``g``."""
    return dirac.Lagrangian.from_strings(
        "triple_pendulum_cartesian", ["x1", "y1", "x2", "y2", "x3", "y3"],
        "(x1_dot**2 + y1_dot**2 + x2_dot**2 + y2_dot**2 + x3_dot**2 + y3_dot**2)/2 - g*(y1 + y2 + y3)",
        constraints=["x1**2 + y1**2 - 1", "(x2 - x1)**2 + (y2 - y1)**2 - 1", "(x3 - x2)**2 + (y3 - y2)**2 - 1"],
        parameters={"g": None})


def slider_crank() -> dirac.Lagrangian:
    """A crank ``th`` (inertia ``I``, radius ``r``) driving a slider ``s`` (mass ``m``) through a rod ``L``."""
    return dirac.Lagrangian.from_strings(
        "slider_crank", ["th", "s"], "I/2*th_dot**2 + m/2*s_dot**2",
        constraints=["(s - r*cos(th))**2 + r**2*sin(th)**2 - L**2"], parameters={"I": None, "m": None, "r": None, "L": None})


def spherical_double_pendulum() -> dirac.Lagrangian:
    """Two spherical pendulums in series (unit rods, masses 2 and 1 in the kinetic energy) in their polar
    and azimuthal angles ``t1, p1, t2, p2``."""
    return dirac.Lagrangian.from_strings(
        "spherical_double_pendulum", ["t1", "p1", "t2", "p2"],
        "t1_dot**2 + sin(t1)**2*p1_dot**2 + (t2_dot**2 + sin(t2)**2*p2_dot**2)/2"
        " + (cos(t1)*cos(t2)*cos(p1 - p2) + sin(t1)*sin(t2))*t1_dot*t2_dot + sin(t1)*sin(t2)*cos(p1 - p2)*p1_dot*p2_dot"
        " + g*(2*cos(t1) + cos(t2))", parameters={"g": None})


def triple_pendulum_angles() -> dirac.Lagrangian:
    """Three bobs of masses ``m1, m2, m3`` on unit rods in their angles from the vertical."""
    return dirac.Lagrangian.from_strings(
        "triple_pendulum_angles", ["a", "b", "c"],
        "(m1 + m2 + m3)/2*a_dot**2 + (m2 + m3)/2*b_dot**2 + m3/2*c_dot**2 + (m2 + m3)*a_dot*b_dot*cos(a - b)"
        " + m3*a_dot*c_dot*cos(a - c) + m3*b_dot*c_dot*cos(b - c) + g*((m1 + m2 + m3)*cos(a) + (m2 + m3)*cos(b) + m3*cos(c))",
        parameters={"m1": None, "m2": None, "m3": None, "g": None})


def asymmetric_top_euler() -> dirac.Lagrangian:
    """The heavy asymmetric top in Euler angles of the latency corpus (``latency_models.asymmetric_top_euler``)."""
    return asymmetric_top_model().system


#: name -> builder, in the order the bench runs them
MODELS = {f.__name__: f for f in (pendulum_on_a_cart, triple_pendulum_cartesian, slider_crank, spherical_double_pendulum,
                                  triple_pendulum_angles, asymmetric_top_euler)}
