"""The free rigid body in the nine elements of its rotation matrix, Lagrangian (78).

    L = 1/2 g_ij R_dot_ki R_dot_kj - 1/2 lambda_ij (R_ki R_kj - delta_ij)

with the mass matrix ``g = diag(g_1, g_2, g_3)`` in the principal axes, written through
the principal moments of inertia (72): ``g_i = (I_j + I_k - I_i)/2`` for ``(i, j, k)`` a
permutation of ``(1, 2, 3)``. ``R`` is first an arbitrary 3x3 matrix; the six constraints
``R^T R = 1`` enter with a symmetric multiplier matrix ``lambda``.

The module also holds the pieces shared with :mod:`dirac_systems.rigid_body_momentum`:
the rotation-matrix symbols, the six constraints, the inertia check (the mass matrix
``g`` must be positive: (72), docs/conventions.md), which the factories pass to
:class:`~dirac.model.lagrangian.Lagrangian` as its ``validator`` so that it runs whenever
:meth:`~dirac.model.lagrangian.Lagrangian.fix` makes the moments numbers.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
import sympy

from dirac.errors import InputError
from dirac.model.lagrangian import Lagrangian

__all__ = [
    "system",
    "check_inertia",
    "mass_matrix_from_inertia",
    "rotation_symbols",
    "orthogonality_constraints",
    "constraint_index_pairs",
    "inertia_symbols",
    "surface_point",
    "phase_point",
    "multipliers_221",
]

#: default principal moments: an admissible (physical) asymmetric body, g = (5/2, 3/2, 1/2)
DEFAULT_INERTIA = (2.0, 3.0, 4.0)

#: (i, j) of the constraint (R^T R - 1)_ij behind each multiplier lambda_1 .. lambda_6
_PAIRS = ((1, 1), (1, 2), (1, 3), (2, 2), (2, 3), (3, 3))


def constraint_index_pairs() -> tuple[tuple[int, int], ...]:
    """The pair ``(i, j)``, ``i <= j``, of the symmetric multiplier ``lambda_ij`` behind
    each engine multiplier ``lambda_1 … lambda_6`` (in this order): 11, 12, 13, 22, 23, 33.
    """
    return _PAIRS


def rotation_symbols() -> tuple[sympy.Matrix, sympy.Matrix]:
    """The matrix ``R`` of coordinates ``R_11 … R_33`` and the matrix of velocities
    ``R_11_dot … R_33_dot`` (real symbols, row-major order)."""
    R = sympy.Matrix(3, 3, lambda i, j: sympy.Symbol(f"R_{i + 1}{j + 1}", real=True))
    R_dot = sympy.Matrix(3, 3, lambda i, j: sympy.Symbol(f"R_{i + 1}{j + 1}_dot", real=True))
    return R, R_dot


def inertia_symbols() -> tuple[sympy.Symbol, sympy.Symbol, sympy.Symbol]:
    """The parameters ``I_1, I_2, I_3`` (principal moments of inertia, positive)."""
    return tuple(sympy.Symbol(f"I_{k}", positive=True) for k in (1, 2, 3))


def mass_matrix_from_inertia(I_1, I_2, I_3):
    """Principal values of the mass matrix from the principal moments, inverse of (72).

    ``I_1 = g_2 + g_3`` etc. (72) give ``g_i = (I_j + I_k - I_i)/2``.

    Returns
    -------
    tuple
        ``(g_1, g_2, g_3)``, of the same kind as the input (sympy or numbers).
    """
    return ((I_2 + I_3 - I_1) / 2, (I_1 + I_3 - I_2) / 2, (I_1 + I_2 - I_3) / 2)


def orthogonality_constraints(R: sympy.Matrix) -> tuple[sympy.Expr, ...]:
    """The six constraints ``R^T R = 1`` scaled so that the engine's multipliers are the
    paper's symmetric ``lambda_ij``.

    The engine adds ``- sum_a lambda_a chi_a`` (extended Lagrangian (1)); the paper's (78)
    has ``- 1/2 sum_ij lambda_ij (R^T R - 1)_ij`` with symmetric ``lambda``, i.e.
    ``- sum_{i<=j} c_ij lambda_ij (R^T R - 1)_ij`` with ``c_ii = 1/2`` and ``c_ij = 1``
    for ``i < j``. Hence ``chi = 1/2 (R^T R - 1)_ii`` on the diagonal and
    ``chi = (R^T R)_ij`` off it, in the order of :func:`constraint_index_pairs`.
    """
    G = R.T * R - sympy.eye(3)
    result = []
    for i, j in _PAIRS:
        entry = sympy.expand(G[i - 1, j - 1])
        result.append(entry / 2 if i == j else entry)
    return tuple(result)


def check_inertia(I_1: float, I_2: float, I_3: float) -> tuple[float, float, float]:
    """Refuse principal moments whose mass matrix ``g`` is not positive definite.

    The Lagrangians (19) and (78) need ``g_i = (I_j + I_k - I_i)/2 > 0`` (72): the
    triangle inequality ``I_j + I_k > I_i`` (docs/conventions.md). Equality is a planar body,
    whose ``g`` is singular (no inverse, so the chain (217) does not exist).

    Parameters
    ----------
    I_1, I_2, I_3
        Principal moments of inertia (finite numbers).

    Returns
    -------
    tuple of float
        The principal values ``(g_1, g_2, g_3)`` of the mass matrix.

    Raises
    ------
    InputError
        If a moment is not a finite positive number, or some ``g_i <= 0``.
    """
    moments = (I_1, I_2, I_3)
    for k, value in enumerate(moments, start=1):
        if isinstance(value, bool) or not isinstance(value, (int, float, sympy.Rational)):
            raise InputError(f"I_{k} = {value!r} is not a number: give a positive principal moment")
        if not math.isfinite(float(value)) or float(value) <= 0:
            raise InputError(f"I_{k} = {value!r} must be a finite positive principal moment of inertia")
    g = mass_matrix_from_inertia(*(float(v) for v in moments))
    for k, g_k in enumerate(g, start=1):
        if g_k <= 0:
            i, j = [m for m in (1, 2, 3) if m != k]
            raise InputError(
                f"inertia (I_1, I_2, I_3) = ({float(I_1)!r}, {float(I_2)!r}, {float(I_3)!r}) "
                f"gives the mass matrix value g_{k} = (I_{i} + I_{j} - I_{k})/2 = {g_k!r} <= 0: "
                f"the Lagrangian needs a positive mass matrix; choose moments with "
                f"I_{i} + I_{j} > I_{k} (triangle inequality)"
            )
    return g


def _validate_fixed_inertia(values: Mapping[str, float]) -> None:
    """Validator of (78): positivity of each fixed moment, the triangle inequality once
    all three are numbers."""
    for k in (1, 2, 3):
        value = values.get(f"I_{k}")
        if value is not None and not float(value) > 0:
            raise InputError(f"I_{k} = {value!r} must be a positive principal moment of inertia")
    if all(f"I_{k}" in values for k in (1, 2, 3)):
        check_inertia(values["I_1"], values["I_2"], values["I_3"])


def system() -> Lagrangian:
    """Free rigid body, rotation-matrix Lagrangian (78) in R_11..R_33; parameters I_1, I_2, I_3.

    ``L = 1/2 g_ij R_dot_ki R_dot_kj - 1/2 lambda_ij (R_ki R_kj - delta_ij)`` (78), with
    ``g = diag(g_1, g_2, g_3)``, ``g_i = (I_j + I_k - I_i)/2`` (72). The six constraints
    are ``(R^T R - 1)_ij`` for ``ij`` = 11, 12, 13, 22, 23, 33, the diagonal ones halved,
    so that the engine's multipliers ``lambda_1 … lambda_6`` are the paper's symmetric
    ``lambda_11, lambda_12, lambda_13, lambda_22, lambda_23, lambda_33``.

    The Dirac–Bergmann chain is (217): 6 + 6 + 6 + 6 second-class constraints in a
    30-dimensional phase space, 3 physical degrees of freedom, and the multipliers on
    the surface are (221). Parameters ``I_1, I_2, I_3`` (defaults 2, 3, 4) stay symbolic
    until fixed; fixing them to moments that violate the triangle inequality (so that
    some ``g_i <= 0``) raises :class:`~dirac.errors.InputError`.
    """
    R, R_dot = rotation_symbols()
    I = inertia_symbols()
    g = mass_matrix_from_inertia(*I)
    kinetic = sum(
        g[i] / 2 * sum((R_dot[k, i] ** 2 for k in range(3)), sympy.Integer(0)) for i in range(3)
    )
    return Lagrangian(
        "rigid_body_matrix",
        tuple(R),
        tuple(R_dot),
        kinetic,
        orthogonality_constraints(R),
        {I[k]: DEFAULT_INERTIA[k] for k in range(3)},
        "free rigid body, rotation-matrix Lagrangian (78)",
        validator=_validate_fixed_inertia,
    )


def _hat(w: np.ndarray) -> np.ndarray:
    """``hat(w) v = w x v`` (the transpose of the paper's hat (8); docs/conventions.md)."""
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def multipliers_221(angular_velocity: np.ndarray, inertia: np.ndarray) -> np.ndarray:
    """The multipliers on the constraint surface, (221):
    ``lambda_ij = 2 g_i g_j/(g_i + g_j) [|Omega|^2 delta_ij - Omega_i Omega_j]``.

    Returns the symmetric 3x3 matrix ``lambda``.
    """
    omega = np.asarray(angular_velocity, dtype=float)
    g = np.array(check_inertia(*(float(v) for v in inertia)))
    weight = 2 * np.outer(g, g) / np.add.outer(g, g)
    return weight * (omega @ omega * np.eye(3) - np.outer(omega, omega))


def surface_point(rotation: np.ndarray, angular_velocity: np.ndarray, inertia: np.ndarray) -> dict[str, float]:
    """The point of the constraint surface (217) of (78) with attitude ``R`` and body
    angular velocity ``Omega``, written by hand from the paper.

    ``p = R_dot g`` (205) with ``R_dot = R hat(Omega)`` (225), the multipliers from
    (221), ``pi = 0`` (206); the moments ``I_1, I_2, I_3`` are included.

    Parameters
    ----------
    rotation
        A rotation matrix (``R^T R = 1``).
    angular_velocity
        ``Omega`` in the body.
    inertia
        ``(I_1, I_2, I_3)`` satisfying the triangle inequality strictly.
    """
    R = np.asarray(rotation, dtype=float)
    omega = np.asarray(angular_velocity, dtype=float)
    g = np.array(check_inertia(*(float(v) for v in inertia)))
    p = R @ _hat(omega) @ np.diag(g)
    return phase_point(R, p, multipliers_221(omega, inertia), inertia)


def phase_point(R: np.ndarray, p: np.ndarray, lam: np.ndarray, inertia) -> dict[str, float]:
    """Name -> value of a phase-space point of the rigid-body Lagrangians (78) and (228).

    ``R``, its momentum ``p`` and the symmetric multipliers ``lam`` (3x3, stored as
    ``lambda_1 … lambda_6`` in the order of ``_PAIRS``); ``pi = 0``; the moments
    ``I_1, I_2, I_3`` are included.
    """
    point = {f"R_{i + 1}{j + 1}": R[i, j] for i in range(3) for j in range(3)}
    point.update({f"p_R_{i + 1}{j + 1}": p[i, j] for i in range(3) for j in range(3)})
    for k, (i, j) in enumerate(_PAIRS, start=1):
        point[f"lambda_{k}"] = lam[i - 1, j - 1]
        point[f"p_lambda_{k}"] = 0.0
    point.update({f"I_{k + 1}": float(inertia[k]) for k in range(3)})
    return {name: float(value) for name, value in point.items()}
