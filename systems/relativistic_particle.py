"""Free relativistic particle in einbein form: reparametrisation invariance, first-class constraints."""

from __future__ import annotations

from dirac.model.lagrangian import Lagrangian


def system() -> Lagrangian:
    """Relativistic particle in einbein form, L = x_dot^2/(2e) - e m^2/2 (first class).

    Coordinates ``t, x, y, z`` (Minkowski, signature (-, +, +, +)) and the einbein ``e``:
    ``L = (-t_dot^2 + x_dot^2 + y_dot^2 + z_dot^2)/(2 e) - e m^2/2``. The Hessian has rank
    4; ``p_e = 0`` is primary, its consistency gives the mass shell
    ``-p_t^2 + p_x^2 + p_y^2 + p_z^2 + m^2 = 0``; both are first class (the canonical
    Hamiltonian ``e/2 (p^2 + m^2)`` is a constraint: reparametrisations are gauge), the
    multiplier of ``p_e`` stays free, and of the 10-dimensional phase space three
    physical degrees of freedom remain. Parameter ``m`` (default 1) stays symbolic.
    """
    return Lagrangian.from_strings(
        "relativistic_particle",
        ["t", "x", "y", "z", "e"],
        "(-t_dot**2 + x_dot**2 + y_dot**2 + z_dot**2)/(2*e) - e*m**2/2",
        parameters={"m": 1.0},
        description="free relativistic particle in einbein form (first-class constraints)",
    )
