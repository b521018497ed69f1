"""The free rigid body through its body angular momentum, Lagrangian (228).

    L = 1/2 I^{-1}_ij M_i M_j - 1/2 lambda_ij (R_ki R_kj - delta_ij),
    M_i(R, R_dot) = -1/2 I_ik eps_knm (R^T R_dot)_nm                    (227)

In the principal axes ``I = diag(I_1, I_2, I_3)``, so ``M_i = I_i Omega_i`` with
``Omega_i = -1/2 eps_inm (R^T R_dot)_nm`` and ``L = 1/2 sum_i I_i Omega_i^2`` plus the
constraint term. ``L`` depends on the nine velocities only through the three
combinations ``Omega_i``: the Hessian has rank 3, so besides ``pi_ij = 0`` the
Lagrangian has six more primary constraints, ``P_ij = [R^T p + (R^T p)^T]_ij = 0``
(230) on the orthogonality surface.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import sympy

from dirac.errors import InputError, warn
from dirac.model.lagrangian import Lagrangian

from .rigid_body_matrix import (
    DEFAULT_INERTIA,
    _hat,
    inertia_symbols,
    mass_matrix_from_inertia,
    orthogonality_constraints,
    phase_point,
    rotation_symbols,
)

__all__ = ["system", "body_angular_momentum", "surface_point", "multipliers_on_surface"]


def body_angular_momentum(R: sympy.Matrix, R_dot: sympy.Matrix, inertia) -> sympy.Matrix:
    """``M_i(R, R_dot) = -1/2 I_ik eps_knm (R^T R_dot)_nm`` (227), ``I`` diagonal.

    Parameters
    ----------
    R, R_dot
        3x3 matrices (symbols or numbers).
    inertia
        The principal moments ``(I_1, I_2, I_3)``.

    Returns
    -------
    sympy.Matrix, shape (3, 1)
    """
    A = R.T * R_dot
    omega = [
        -sympy.Rational(1, 2) * sum(sympy.LeviCivita(k, n, m) * A[n, m] for n in range(3) for m in range(3))
        for k in range(3)
    ]
    return sympy.Matrix([inertia[k] * omega[k] for k in range(3)])


def _validate_fixed_inertia(values: Mapping[str, float]) -> None:
    """Validator of (228): each fixed moment must be positive (``I^{-1}`` appears in L).

    Moments that violate the triangle inequality are legal for (228), whose kinetic term
    is positive for any positive ``I``, but no body of particles has them: warn.
    """
    for k in (1, 2, 3):
        value = values.get(f"I_{k}")
        if value is not None and not float(value) > 0:
            raise InputError(f"I_{k} = {value!r} must be a positive principal moment of inertia")
    if all(f"I_{k}" in values for k in (1, 2, 3)):
        g = mass_matrix_from_inertia(*(float(values[f"I_{k}"]) for k in (1, 2, 3)))
        if min(g) <= 0:
            warn(
                f"inertia ({values['I_1']!r}, {values['I_2']!r}, {values['I_3']!r}) violates the "
                "triangle inequality I_i + I_j > I_k: no physical body has it; Lagrangian (228) "
                "is still well defined, continuing"
            )


def system() -> Lagrangian:
    """Free rigid body, angular-momentum Lagrangian (228) with M(R, R_dot) of (227); parameters I_1, I_2, I_3.

    ``L = 1/2 I^{-1}_ij M_i M_j - 1/2 lambda_ij (R_ki R_kj - delta_ij)`` with
    ``M_i = -1/2 I_ik eps_knm (R^T R_dot)_nm`` (227) and ``I = diag(I_1, I_2, I_3)``.
    The coordinates are ``R_11 … R_33``; the six constraints and the multiplier order
    are those of :mod:`dirac_systems.rigid_body_matrix` (``lambda_1 … lambda_6`` =
    ``lambda_11, lambda_12, lambda_13, lambda_22, lambda_23, lambda_33``).

    The Lagrangian is singular: its Hessian in ``R_dot`` has rank 3, which gives six
    primary constraints ``P_ij = sym(R^T p)`` (230) besides ``pi_ij = 0`` (Sect. XI).
    Parameters ``I_1, I_2, I_3`` (defaults 2, 3, 4) stay symbolic until fixed; a
    non-positive moment raises :class:`~dirac.errors.InputError`.
    """
    R, R_dot = rotation_symbols()
    I = inertia_symbols()
    M = body_angular_momentum(R, R_dot, I)
    # written through Omega_k = M_k / I_k as in (227)-(228), not expanded: the engine sees the
    # three velocity combinations and finds the primary constraints from them
    kinetic = sympy.Rational(1, 2) * sum(M[k] ** 2 / I[k] for k in range(3))
    return Lagrangian(
        "rigid_body_momentum",
        tuple(R),
        tuple(R_dot),
        kinetic,
        orthogonality_constraints(R),
        {I[k]: DEFAULT_INERTIA[k] for k in range(3)},
        "free rigid body, angular-momentum Lagrangian (228)",
        validator=_validate_fixed_inertia,
    )


def multipliers_on_surface(angular_momentum: np.ndarray, inertia: np.ndarray) -> np.ndarray:
    """The multipliers of (228) on its constraint surface (derived by hand, Sect. XI).

    ``dP_ab/dt = {P_ab, H} = 0`` with ``v = 0`` (fixed by ``d(R^T R)/dt = 0``) and the
    brackets (237), ``{P_ab, R_ki R_kj} = -2 (delta_ia delta_jb + delta_ib delta_ja)`` on
    ``R^T R = 1``, give

        lambda_ab = (M . Omega) delta_ab - (Omega_a M_b + Omega_b M_a)/2,  Omega = I^{-1} M.

    (They differ from (221) of the Lagrangian (78); Appendix 2 relates the two.)
    """
    M = np.asarray(angular_momentum, dtype=float)
    omega = M / np.asarray(inertia, dtype=float)
    return (M @ omega) * np.eye(3) - (np.outer(omega, M) + np.outer(M, omega)) / 2


def surface_point(rotation: np.ndarray, angular_velocity: np.ndarray, inertia: np.ndarray) -> dict[str, float]:
    """The point of the constraint surface of (228) with attitude ``R`` and body angular
    velocity ``Omega``, written by hand from the paper.

    ``M = I Omega``, ``p = -1/2 R eps·M = 1/2 R hat(M)`` (229), so ``P = 0`` (230) and
    ``M = -eps (R^T p)`` (233); multipliers from :func:`multipliers_on_surface`;
    ``pi = 0``. The moments ``I_1, I_2, I_3`` are included.
    """
    R = np.asarray(rotation, dtype=float)
    inertia = np.asarray(inertia, dtype=float)
    M = inertia * np.asarray(angular_velocity, dtype=float)
    p = 0.5 * R @ _hat(M)
    return phase_point(R, p, multipliers_on_surface(M, inertia), inertia)
