"""Lagrangians linear in the velocities: Hessian of rank 0 (first-order systems).

For ``L = a(q) . q_dot - V(q)`` (Faddeev–Jackiw first-order systems; the Chern–Simons
oscillator and the massless Landau problem of Dunne, Jackiw and Trugenberger) the
Hessian ``W = d^2 L / dq_dot dq_dot`` vanishes, every momentum is fixed by the
coordinates and the Legendre transform gives ``n`` primary constraints

    phi_j = p_j - a_j(q) = 0                                   (Dirac; Henneaux–Teitelboim (1.9)),

with canonical Hamiltonian ``H_c = p . q_dot - L = V`` on the primary surface (plus
``lambda_a chi_a`` for holonomic constraints, the paper's (207)). Their brackets

    {phi_i, phi_j} = d_i a_j - d_j a_i = F_ij

are the symplectic two-form of the first-order Lagrangian: where ``F`` is invertible
all ``phi`` are second class and the Dirac bracket of the coordinates is
``{q_i, q_j}_D = -(F^{-1})_ij``, the Faddeev–Jackiw bracket (Henneaux–Teitelboim Sect. 1.6).
The constraint chain, classification and Dirac bracket then run unchanged.
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy

from dirac.analysis.core.algebra import tidy

__all__ = ["FIRST_ORDER_METHOD", "first_order_primary"]

#: how the Legendre transform of a rank-0 Lagrangian is described in the analysis notes
FIRST_ORDER_METHOD = (
    "Hessian of rank 0 (L linear in the velocities, L = a(q).q_dot - V): every momentum is a primary "
    "constraint p - a(q) = 0, and H_c = V"
)


def first_order_primary(shifted: sympy.Matrix, variables: Sequence[sympy.Symbol]) -> list[sympy.Expr]:
    """The primary constraints ``phi_j = p_j - a_j(q)`` of a Lagrangian linear in the velocities.

    Parameters
    ----------
    shifted
        The column ``p - a(q)`` (``a_j = dL/dq_dot_j`` at zero velocity).
    variables
        The phase-space variables (for the readable normal form of each constraint).

    Returns
    -------
    list of sympy.Expr
        One constraint per coordinate, in the order of the coordinates.
    """
    return [tidy(phi, variables, sign=True) for phi in shifted]
