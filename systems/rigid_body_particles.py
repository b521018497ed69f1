"""The free rigid body as ``n >= 4`` point masses held by distance constraints, (17)–(19).

    L = 1/2 sum_N m_N |y_N_dot|^2 + 1/2 sum_{A=2..4} sum_{N=2..n} lambda_AN
        [(y_A - y_1, y_N - y_1) - a_AN]                                           (19)

with the independent constraints (17) ``(y_A - y_1, y_B - y_1) = a_AB`` for
``A <= B`` in ``2, 3, 4`` (six) and (18) ``(y_A - y_1, y_alpha - y_1) = a_A alpha`` for
``alpha = 5 … n`` (``3(n - 4)``): ``3n - 6`` constraints on ``3n`` coordinates, so six
degrees of freedom (three of the centre of mass, three of the rotation).

The masses and the initial positions are structural options of the factory (they fix
the number of particles and the constants ``a_AN``); :func:`body_data` gives the centre
of mass (24), the mass matrix ``g`` (66) and the inertia tensor ``I`` (67) they define.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import sympy

from dirac.errors import InputError
from dirac.model.lagrangian import Lagrangian

__all__ = ["system", "body_data", "RigidBodyData", "DEFAULT_MASSES", "DEFAULT_POSITIONS"]

#: default body: four particles at the vertices of a non-planar (irregular) tetrahedron
DEFAULT_MASSES = (1.0, 2.0, 3.0, 4.0)
DEFAULT_POSITIONS = (
    (0.0, 0.0, 0.0),
    (1.0, 0.0, 0.0),
    (0.0, 2.0, 0.0),
    (0.5, 0.5, 1.5),
)

#: relative size below which a principal value of g counts as zero (planar body)
_PLANAR_TOLERANCE = 1e-12


@dataclass(frozen=True)
class RigidBodyData:
    """What a set of particles defines as a rigid body (Sect. II, IV).

    Attributes
    ----------
    masses : numpy.ndarray, shape (n,)
    positions : numpy.ndarray, shape (n, 3)
        Initial lab positions ``y_N(0)``.
    centre_of_mass : numpy.ndarray, shape (3,)
        ``y_0(0) = sum m_N y_N(0) / sum m_N`` (24).
    relative_positions : numpy.ndarray, shape (n, 3)
        ``x_N(0) = y_N(0) - y_0(0)`` (26).
    mass_matrix : numpy.ndarray, shape (3, 3)
        ``g_ij = sum_N m_N x_N^i(0) x_N^j(0)`` (66).
    inertia_tensor : numpy.ndarray, shape (3, 3)
        ``I = tr(g) 1 - g`` (67).
    principal_moments : numpy.ndarray, shape (3,)
        Eigenvalues of ``I`` in increasing order (``I_1 = g_2 + g_3`` etc., (72)).
    """

    masses: np.ndarray
    positions: np.ndarray
    centre_of_mass: np.ndarray
    relative_positions: np.ndarray
    mass_matrix: np.ndarray
    inertia_tensor: np.ndarray
    principal_moments: np.ndarray


def _clean_masses(masses: object) -> np.ndarray:
    try:
        values = np.array(masses, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"masses = {masses!r} must be a list of positive numbers") from None
    if values.ndim != 1 or values.size < 4:
        raise InputError(
            f"masses = {masses!r}: a rigid body of point masses needs a list of n >= 4 masses"
        )
    if not np.all(np.isfinite(values)) or np.any(values <= 0):
        raise InputError(f"masses = {values.tolist()} must all be finite and positive")
    return values


def _clean_positions(positions: object, n: int) -> np.ndarray:
    try:
        values = np.array(positions, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"positions = {positions!r} must be a list of n points [x, y, z]") from None
    if values.shape != (n, 3):
        raise InputError(
            f"positions have shape {values.shape}; give one point [x, y, z] per mass, shape ({n}, 3)"
        )
    if not np.all(np.isfinite(values)):
        raise InputError(f"positions = {values.tolist()} have non-finite entries")
    return values


def body_data(
    masses: Sequence[float] = DEFAULT_MASSES,
    positions: Sequence[Sequence[float]] = DEFAULT_POSITIONS,
) -> RigidBodyData:
    """Centre of mass (24), mass matrix ``g`` (66) and inertia tensor ``I`` (67) of a body.

    Parameters
    ----------
    masses
        ``n >= 4`` positive masses ``m_N``.
    positions
        The ``n`` initial lab positions ``y_N(0)``.

    Returns
    -------
    RigidBodyData

    Raises
    ------
    InputError
        For fewer than four particles, non-positive masses, a wrong shape, or a planar
        or collinear body: its ``g`` has a zero principal value, so the triangle
        inequality ``I_i + I_j >= I_k`` (docs/conventions.md) holds with equality and the
        rotation-matrix description (78) does not exist.
    """
    m = _clean_masses(masses)
    y = _clean_positions(positions, m.size)
    centre = (m[:, None] * y).sum(axis=0) / m.sum()
    x = y - centre
    g = np.einsum("n,ni,nj->ij", m, x, x)
    inertia = np.trace(g) * np.eye(3) - g
    g_values = np.linalg.eigvalsh(g)
    scale = max(g_values[-1], np.finfo(float).tiny)
    rank = int(np.sum(g_values > _PLANAR_TOLERANCE * scale)) if g_values[-1] > 0 else 0
    if rank < 3:
        shape = {2: "planar", 1: "collinear", 0: "a single point"}[rank]
        moments = np.linalg.eigvalsh(inertia)
        raise InputError(
            f"the particles form a {shape} body (mass matrix g has principal values "
            f"{g_values.tolist()}, inertia {moments.tolist()} meets the triangle inequality "
            "with equality): give positions that do not all lie in one plane"
        )
    return RigidBodyData(m, y, centre, x, g, inertia, np.linalg.eigvalsh(inertia))


def _exact(value: float) -> sympy.Rational:
    """The number as written, as an exact rational (``0.1`` -> ``1/10``)."""
    if float(value).is_integer():
        return sympy.Integer(int(value))
    return sympy.Rational(repr(float(value)))


def system(
    masses: Sequence[float] = DEFAULT_MASSES,
    positions: Sequence[Sequence[float]] = DEFAULT_POSITIONS,
) -> Lagrangian:
    """Free rigid body of n >= 4 point masses, constraints (17)-(18), Lagrangian (19); 6 degrees of freedom.

    Coordinates ``x_N, y_N, z_N`` (lab position of particle ``N = 1 … n``). The
    constraints are, in this order, ``(y_A - y_1, y_B - y_1) - a_AB`` for ``AB`` = 22,
    23, 24, 33, 34, 44 (17) and ``(y_A - y_1, y_alpha - y_1) - a_A alpha`` for
    ``alpha = 5 … n``, ``A = 2, 3, 4`` (18); the constants ``a_AN`` are computed
    exactly from ``positions`` (the initial configuration). The engine's multipliers are
    ``lambda_AN`` of (19) up to the factor ``-1/2`` (``-lambda_a chi_a`` in (1)).

    Parameters
    ----------
    masses
        ``n >= 4`` positive masses (default ``1, 2, 3, 4``).
    positions
        Their ``n`` initial positions (default: an irregular tetrahedron). Particles
        1–4 must not lie in one plane, so that ``y_A - y_1`` (``A = 2, 3, 4``) span space
        (``det a != 0`` in (13)).

    Raises
    ------
    InputError
        See :func:`body_data`; also when particles 1–4 are coplanar.
    """
    data = body_data(masses, positions)
    n = data.masses.size
    frame = data.positions[1:4] - data.positions[0]
    volume = abs(np.linalg.det(frame))
    size = max(np.linalg.norm(frame, axis=1).prod(), np.finfo(float).tiny)
    if volume <= 1e-12 * size:
        raise InputError(
            "particles 1-4 lie in one plane, so the constraints (17)-(18) built on them are "
            "not independent: list four particles that do not lie in one plane first"
        )
    exact = [[_exact(c) for c in point] for point in data.positions]
    mass = [_exact(value) for value in data.masses]
    coords = [
        [sympy.Symbol(f"{axis}_{N}", real=True) for axis in ("x", "y", "z")] for N in range(1, n + 1)
    ]
    velocities = [[sympy.Symbol(f"{s.name}_dot", real=True) for s in point] for point in coords]

    def dot(a: Sequence, b: Sequence) -> sympy.Expr:
        return sum((a[i] * b[i] for i in range(3)), sympy.Integer(0))

    def rel(points: Sequence, N: int) -> list:  # y_N - y_1 (0-based N)
        return [points[N][i] - points[0][i] for i in range(3)]

    pairs = [(A, B) for A in (1, 2, 3) for B in (1, 2, 3) if A <= B]
    pairs += [(A, alpha) for alpha in range(4, n) for A in (1, 2, 3)]
    constraints = tuple(
        sympy.expand(dot(rel(coords, A), rel(coords, N)) - dot(rel(exact, A), rel(exact, N)))
        for A, N in pairs
    )
    kinetic = sympy.Rational(1, 2) * sum(
        mass[N] * dot(velocities[N], velocities[N]) for N in range(n)
    )
    description = f"free rigid body of {n} point masses, Lagrangian (19)"
    return Lagrangian(
        "rigid_body_particles",
        tuple(s for point in coords for s in point),
        tuple(s for point in velocities for s in point),
        kinetic,
        constraints,
        {},
        description,
    )
