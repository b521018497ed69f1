"""A planar particle with a rotational gauge symmetry: first-class constraints."""

from __future__ import annotations

from dirac.model.lagrangian import Lagrangian


def system() -> Lagrangian:
    """Gauge-invariant planar oscillator (Christ-Lee type): two first-class constraints.

    ``L = 1/2 [(x_dot - z y)^2 + (y_dot + z x)^2] - k/2 (x^2 + y^2)``. The coordinate
    ``z`` has no velocity: it acts as a gauge field for rotations of the plane,
    ``(x, y) -> R(alpha(t)) (x, y)``, ``z -> z - alpha_dot``. The Hessian has rank 2, so
    ``p_z = 0`` is primary; its consistency gives the Gauss law
    ``x p_y - y p_x = 0`` (second stage), whose consistency holds identically. Both
    constraints are first class, the multiplier of ``p_z`` stays free (gauge freedom),
    and of the 6-dimensional phase space one physical degree of freedom remains (the
    radial oscillation). Parameter ``k`` (default 1) stays symbolic until fixed.
    """
    return Lagrangian.from_strings(
        "gauge_system",
        ["x", "y", "z"],
        "((x_dot - z*y)**2 + (y_dot + z*x)**2)/2 - k/2*(x**2 + y**2)",
        parameters={"k": 1.0},
        description="planar oscillator with a rotational gauge field (first-class constraints)",
    )
