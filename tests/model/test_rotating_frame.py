"""`uniform_rotation`: constraints that turn uniformly about an axis (a Jacobi integral exists)."""

from __future__ import annotations

import sympy

from dirac.model.lagrangian import Lagrangian
from dirac.model.rotating_frame import uniform_rotation

VALUES = {"m": 1.0, "g": 9.81, "R": 1.0, "w": 2.0, "a": 0.3}
KINETIC = "m/2*(x_dot**2 + y_dot**2 + z_dot**2) - m*g*z"


def system(constraints, lagrangian=KINETIC):
    return Lagrangian.from_strings("s", ["x", "y", "z"], lagrangian, constraints, VALUES)


def test_a_hoop_turning_about_z_has_the_rate_w_in_the_xy_plane():
    found = uniform_rotation(system(["x**2 + y**2 + z**2 - R**2", "-sin(w*t)*x + cos(w*t)*y"]))
    assert (found.first, found.second) == (0, 1)
    assert found.rate == sympy.Symbol("w", real=True)


def test_the_opposite_sense_of_turning_has_the_rate_minus_w():
    found = uniform_rotation(system(["x**2 + y**2 + z**2 - R**2", "sin(w*t)*x + cos(w*t)*y"]))
    assert sympy.simplify(found.rate + sympy.Symbol("w", real=True)) == 0


def test_other_time_dependences_have_no_jacobi_integral():
    # a moving suspension, a constraint not symmetric about the axis, a time-dependent L
    assert uniform_rotation(system(["(x - a*cos(w*t))**2 + y**2 + z**2 - R**2"])) is None
    assert uniform_rotation(system(["z - a*x**2", "-sin(w*t)*x + cos(w*t)*y"])) is None
    assert uniform_rotation(system(["-sin(w*t)*x + cos(w*t)*y"], KINETIC + " + a*t*x")) is None
    assert uniform_rotation(system(["x**2 + y**2 + z**2 - R**2"])) is None  # no time at all
