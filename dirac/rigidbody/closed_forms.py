"""The paper's elementary solutions of the free rigid body (Sect. IX).

- :func:`principal_axis_rotation`: ``m = (0, 0, m3)`` along a principal axis,
  (133)–(165): ``M`` stays ``m`` and ``R`` turns about that axis at ``w = m3 / I3``.
- :func:`symmetric_top`: the free symmetric top ``I1 = I2``, ``m = (0, m2, m3)``, (183):
  ``R(t) = R_m(t) R_OZ(t)``, (197) and (202).

Sign of ``phi`` in (183), (202): with this project's conventions (``dR/dt = R hat(Omega)``,
``R`` body to lab, docs/conventions.md) the rotation about ``z`` is by ``+phi t`` with
``phi = (I2 - I3) m3 / (I2 I3)``, exactly as printed in the paper. Derivation: ``H_0 =
|M|^2/(2 I2) + (1/I3 - 1/I2) M_3^2/2``, two commuting flows; the first turns ``R`` on the
left about ``m`` at rate ``|m|/I2`` (``R_m``), the second on the right about ``e_3`` at
rate ``(1/I3 - 1/I2) m3 = phi``. The tests check it against a tight ``solve_ivp`` run.
"""

from __future__ import annotations

import math

import numpy as np

from dirac.errors import InputError
from dirac.rigidbody.inertia import validate_inertia

__all__ = ["principal_axis_rotation", "symmetric_top", "axis_rotation"]


def axis_rotation(axis: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """Rotations by ``angles`` about the unit vector ``axis`` (Rodrigues; (197) for ``m^``).

    Parameters
    ----------
    axis : array_like, shape (3,)
        Unit vector.
    angles : array_like, shape (N,)

    Returns
    -------
    numpy.ndarray, shape (N, 3, 3)
        ``exp(angle hat(axis))``: ``cos a 1 + sin a hat(n) + (1 - cos a) n n^T``.
    """
    n = np.asarray(axis, dtype=float)
    a = np.atleast_1d(np.asarray(angles, dtype=float))
    K = np.array([[0.0, -n[2], n[1]], [n[2], 0.0, -n[0]], [-n[1], n[0], 0.0]])
    c = np.cos(a)[:, None, None]
    s = np.sin(a)[:, None, None]
    return c * np.eye(3) + s * K + (1.0 - c) * np.outer(n, n)


def principal_axis_rotation(
    inertia: object, m3: float, times: object, axis: int = 2
) -> tuple[np.ndarray, np.ndarray]:
    """Rotation about a principal axis, (133)–(165), with ``R(0) = 1``.

    With ``m = m3 e_axis`` (the paper takes ``axis = 3``, i.e. index 2), ``M(t) = m`` and
    the body turns about that axis at ``w = m3 / I_axis``:
    ``R_1 = (cos wt, sin wt, 0)``, ``R_2 = (-sin wt, cos wt, 0)``, ``R_3 = (0, 0, 1)``
    (the columns of ``R``), (165).

    Parameters
    ----------
    inertia : array_like, shape (3,)
    m3 : float
        Angular momentum along the axis (the paper's (133) has ``m3 < 0``; any sign works).
    times : array_like, shape (N,)
    axis : int
        Principal axis index 0, 1 or 2.

    Returns
    -------
    M : numpy.ndarray, shape (N, 3)
    R : numpy.ndarray, shape (N, 3, 3)
    """
    moments = validate_inertia(inertia)
    if axis not in (0, 1, 2):
        raise InputError(f"axis = {axis!r} is not a principal axis index; use 0, 1 or 2")
    t = np.atleast_1d(np.asarray(times, dtype=float))
    omega = float(m3) / moments[axis]
    e = np.zeros(3)
    e[axis] = 1.0
    M = np.tile(float(m3) * e, (t.shape[0], 1))
    return M, axis_rotation(e, omega * t)


def symmetric_top(
    inertia: object, m2: float, m3: float, times: object
) -> tuple[np.ndarray, np.ndarray]:
    """The free symmetric top ``I1 = I2``, ``m = (0, m2, m3)``, ``R(0) = 1``: (183).

    ``R(t) = R_m(t) R_OZ(t)``: ``R_m`` (197) turns by ``k t`` about ``m / |m|`` with
    ``k = |m| / I2``, ``R_OZ`` (202) by ``phi t`` about ``z`` with
    ``phi = (I2 - I3) m3 / (I2 I3)``; ``M(t) = R(t)^T m``, i.e. (168)
    ``Omega = (m2 sin(phi t)/I2, m2 cos(phi t)/I2, m3/I3)``.

    Parameters
    ----------
    inertia : array_like, shape (3,)
        Must have ``I1 = I2`` (relative difference below ``1e-12``).
    m2, m3 : float
        Components of the conserved lab angular momentum (``|m| > 0``).
    times : array_like, shape (N,)

    Returns
    -------
    M : numpy.ndarray, shape (N, 3)
    R : numpy.ndarray, shape (N, 3, 3)

    Raises
    ------
    InputError
        ``I1 != I2`` or ``m = 0``.
    """
    moments = validate_inertia(inertia)
    i1, i2, i3 = moments
    if abs(i1 - i2) > 1e-12 * max(i1, i2):
        raise InputError(
            f"symmetric_top needs I1 = I2, got inertia = {moments.tolist()}; order the "
            "moments so that the two equal ones come first"
        )
    norm = math.hypot(float(m2), float(m3))
    if norm == 0.0:
        raise InputError("symmetric_top needs a non-zero angular momentum (m2, m3)")
    t = np.atleast_1d(np.asarray(times, dtype=float))
    k = norm / i2
    phi = (i2 - i3) * float(m3) / (i2 * i3)
    R = axis_rotation(np.array([0.0, m2, m3]) / norm, k * t) @ axis_rotation(
        np.array([0.0, 0.0, 1.0]), phi * t
    )
    m = np.array([0.0, float(m2), float(m3)])
    M = np.einsum("nji,j->ni", R, m)
    return M, R
