"""Validation of the rigid-body inputs: principal moments, attitude, angular momentum.

Each ``validate_*`` helper returns the cleaned value (a float64 numpy array) or raises
:class:`dirac.errors.InputError` naming the offending value and the fix.
"""

from __future__ import annotations

import numpy as np

from dirac.errors import InputError, warn
from dirac.validate import validate_array

__all__ = ["validate_inertia", "validate_rotation", "validate_momentum"]


def validate_inertia(inertia: object) -> np.ndarray:
    """Check the principal moments of inertia ``(I_1, I_2, I_3)``.

    The moments are ``I_1 = g_2 + g_3`` etc. (72) with ``g_i >= 0`` the principal values
    of the mass matrix (66); hence ``I_i > 0`` and the triangle inequality
    ``I_i + I_j >= I_k`` (docs/conventions.md, "Principal moments and the triangle
    inequality"). A violation of the triangle inequality is legal for the Euler–Poisson
    equations (250)–(251) (e.g. the standard test case ``I = (2, 1, 2/3)``), so it only
    warns, once per call, and goes on.

    Parameters
    ----------
    inertia : array_like, shape (3,)
        Principal moments of inertia, finite and strictly positive.

    Returns
    -------
    numpy.ndarray, shape (3,)
        The moments as float64.

    Raises
    ------
    InputError
        Wrong shape, non-finite or non-positive entries.
    """
    moments = validate_array(inertia, "inertia", (3,))
    if np.any(moments <= 0.0):
        raise InputError(
            f"inertia = {moments.tolist()} has a non-positive moment; every principal "
            "moment I_i must be > 0"
        )
    with np.errstate(divide="ignore", over="ignore"):
        reciprocal = 1.0 / moments
    if not np.all(np.isfinite(reciprocal)):
        raise InputError(
            f"inertia = {moments.tolist()} has a moment so small that 1/I_i overflows; "
            "rescale the units (e.g. measure lengths in smaller units)"
        )
    for k in range(3):
        i, j = (k + 1) % 3, (k + 2) % 3
        if moments[i] + moments[j] < moments[k]:
            warn(
                f"inertia = {moments.tolist()} violates the triangle inequality "
                f"I_{i + 1} + I_{j + 1} >= I_{k + 1}: no physical body has this inertia "
                "(its mass matrix would have a negative principal value); the "
                "Euler-Poisson flow is still well defined, continuing"
            )
            break
    return moments


def validate_rotation(rotation: object, tol: float = 1e-10) -> np.ndarray:
    """Check an attitude matrix ``R`` (body to lab, ``R^T R = 1``, ``det R = +1``).

    Parameters
    ----------
    rotation : array_like, shape (3, 3)
        Rotation matrix; its columns are the body axes in the lab frame (41), (43).
    tol : float
        Largest accepted ``max |R^T R - 1|`` and ``|det R - 1|``.

    Returns
    -------
    numpy.ndarray, shape (3, 3)

    Raises
    ------
    InputError
        Wrong shape, non-finite entries, not orthogonal, or left-handed (``det R = -1``).
    """
    matrix = validate_array(rotation, "R", (3, 3))
    defect = float(np.max(np.abs(matrix.T @ matrix - np.eye(3))))
    if defect > tol:
        raise InputError(
            f"R is not orthogonal: max |R^T R - 1| = {defect:.3g} > {tol:.1g}; give a "
            "rotation matrix (orthonormal columns), e.g. re-orthonormalise it"
        )
    det = float(np.linalg.det(matrix))
    if det < 0.0:
        raise InputError(
            f"R is left-handed: det R = {det:.6g}; give a proper rotation (det R = +1), "
            "e.g. flip the sign of one column"
        )
    if abs(det - 1.0) > tol:
        raise InputError(
            f"R has det R = {det:.15g}, off by {abs(det - 1.0):.3g} from +1; give a "
            "proper rotation matrix"
        )
    return matrix


def validate_momentum(momentum: object) -> np.ndarray:
    """Check a body angular momentum ``M`` (shape (3,), finite).

    Parameters
    ----------
    momentum : array_like, shape (3,)
        Body angular momentum ``M = I Omega`` (docs/conventions.md).

    Returns
    -------
    numpy.ndarray, shape (3,)

    Raises
    ------
    InputError
        Wrong shape, non-finite entries, or so large that ``|M|^2`` overflows (then no
        invariant of (247)-(249) can be evaluated).
    """
    array = validate_array(momentum, "M", (3,))
    with np.errstate(over="ignore"):
        square = float(array @ array)
    if not np.isfinite(square):
        raise InputError(
            f"M = {array.tolist()} is so large that |M|^2 overflows; rescale the units "
            "(e.g. measure angular momentum in larger units)"
        )
    return array
