"""Planar double pendulum in Cartesian coordinates: two holonomic constraints."""

from __future__ import annotations

from dataclasses import replace

import sympy

from dirac.model.lagrangian import Lagrangian


def system() -> Lagrangian:
    """Planar double pendulum in Cartesian coordinates (x1, y1, x2, y2), two rod constraints.

    ``L = m1/2 (x1_dot^2 + y1_dot^2) + m2/2 (x2_dot^2 + y2_dot^2) - g (m1 y1 + m2 y2)``
    with ``chi_1 = x1^2 + y1^2 - l1^2`` and ``chi_2 = (x2 - x1)^2 + (y2 - y1)^2 - l2^2``:
    the extended Lagrangian (1) with two multipliers. The chain has four stages of two
    constraints each (Sect. X, (205)-(217)), all second class, on a 12-dimensional phase
    space: two physical degrees of freedom. Parameters ``m1, m2, g, l1, l2`` stay symbolic
    until fixed; the masses are declared positive (``positive=True``).
    """
    plain = Lagrangian.from_strings(
        "double_pendulum",
        ["x1", "y1", "x2", "y2"],
        "m1/2*(x1_dot**2 + y1_dot**2) + m2/2*(x2_dot**2 + y2_dot**2) - g*(m1*y1 + m2*y2)",
        constraints=["x1**2 + y1**2 - l1**2", "(x2 - x1)**2 + (y2 - y1)**2 - l2**2"],
        parameters={"m1": 1.0, "m2": 1.0, "g": 9.81, "l1": 1.0, "l2": 1.0},
        description="planar double pendulum in Cartesian coordinates",
    )
    # masses are positive: the Gram determinant of the rods, by which the multiplier solution divides, is then
    # proven nonzero on the surface (a sum of squares with positive weights 1/m1^2, 1/(m1 m2), Cauchy-Binet)
    positive = {p: sympy.Symbol(p.name, positive=True) for p in plain.parameters if p.name in ("m1", "m2")}
    return replace(
        plain,
        expression=plain.expression.xreplace(positive),
        constraints=tuple(c.xreplace(positive) for c in plain.constraints),
        parameters={positive.get(p, p): value for p, value in plain.parameters.items()},
    )
