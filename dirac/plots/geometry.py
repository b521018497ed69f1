"""Geometry behind the rigid-body pictures: spheres, ellipsoids and polhodes.

Pure numpy (plus :mod:`contourpy`, which ships with matplotlib); nothing here draws.

The polhodes of the free rigid body (paper Sect. VII) are the curves on which the body
angular momentum ``M`` moves: the intersections of the sphere ``|M| = G`` (the Casimir of
the bracket (248)) with the energy ellipsoid ``sum_i M_i^2 / I_i = 2E`` (247). On the
sphere they are the level sets of ``e(n) = sum_i n_i^2 / I_i`` with ``n = M / G``; the
level ``e = 1 / I_mid`` of the middle moment is the separatrix through the unstable axis.
"""

from __future__ import annotations

from typing import cast

import numpy as np
from numpy.typing import ArrayLike

__all__ = [
    "sphere_mesh",
    "ellipsoid_mesh",
    "energy_on_sphere",
    "polhode_levels",
    "level_curves_on_sphere",
    "view_direction",
    "split_front_back",
]


def sphere_mesh(radius: float = 1.0, n: int = 41) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Grid ``(x, y, z)`` of a sphere of the given radius, each of shape ``(n, n)``."""
    theta = np.linspace(0.0, np.pi, n)
    phi = np.linspace(-np.pi, np.pi, n)
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    return radius * np.sin(th) * np.cos(ph), radius * np.sin(th) * np.sin(ph), radius * np.cos(th)


def ellipsoid_mesh(semi_axes: np.ndarray, n: int = 41) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Grid ``(x, y, z)`` of the ellipsoid ``sum_i x_i^2 / a_i^2 = 1``, each of shape ``(n, n)``.

    For the energy ellipsoid of (247), ``sum_i M_i^2 / I_i = 2E``, the semi-axes are
    ``a_i = sqrt(2 E I_i)``.
    """
    x, y, z = sphere_mesh(1.0, n)
    a = np.asarray(semi_axes, dtype=float)
    return a[0] * x, a[1] * y, a[2] * z


def energy_on_sphere(points: np.ndarray, inertia: np.ndarray) -> np.ndarray:
    """``e(n) = sum_i n_i^2 / I_i`` for unit vectors ``n`` (shape ``(..., 3)``).

    ``e = 2E / G^2``: a polhode is a level set of ``e`` on the unit sphere.
    """
    n = np.asarray(points, dtype=float)
    return np.sum(n * n / np.asarray(inertia, dtype=float), axis=-1)


def polhode_levels(inertia: np.ndarray, count: int = 9) -> tuple[np.ndarray, float]:
    """Levels of ``e`` for a family of polhodes, and the separatrix level ``1 / I_mid``.

    The ``count`` levels are spread evenly in ``e`` on each side of the separatrix (so both
    families, around the axis of largest and of smallest moment, get curves); the
    extremes ``1 / I_max`` and ``1 / I_min`` (the stable axes, single points) are left out.
    """
    a = np.sort(1.0 / np.asarray(inertia, dtype=float))
    lo, mid, hi = float(a[0]), float(a[1]), float(a[2])
    per_side = max(1, count // 2)
    below = lo + (mid - lo) * (np.arange(1, per_side + 1) / (per_side + 1))
    above = mid + (hi - mid) * (np.arange(1, per_side + 1) / (per_side + 1))
    levels = np.concatenate([below, above])
    levels = levels[(levels > lo) & (levels < hi) & (np.abs(levels - mid) > 1e-12 * hi)]
    return levels, mid


def level_curves_on_sphere(
    inertia: np.ndarray, levels: ArrayLike, radius: float = 1.0, resolution: int = 181
) -> list[list[np.ndarray]]:
    """Level curves of ``e(n) = sum_i n_i^2 / I_i`` on a sphere, one list of polylines per level.

    Parameters
    ----------
    inertia : array_like, shape (3,)
        Principal moments ``I_i``.
    levels : array_like
        Values of ``e`` (``2E / G^2``); levels outside ``[1/I_max, 1/I_min]`` give no curve.
    radius : float
        Radius ``G = |M|`` of the sphere the curves are drawn on.
    resolution : int
        Grid points per angle of the ``(theta, phi)`` grid the contours are traced on.

    Returns
    -------
    list of list of numpy.ndarray
        For each level, the polylines (arrays of shape ``(k, 3)``) that make up its curve.
    """
    import contourpy

    theta = np.linspace(0.0, np.pi, resolution)
    phi = np.linspace(-np.pi, np.pi, 2 * resolution - 1)
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    n = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], axis=-1)
    field = energy_on_sphere(n, inertia)
    generator = contourpy.contour_generator(x=ph, y=th, z=field, line_type="Separate")
    curves: list[list[np.ndarray]] = []
    for level in np.atleast_1d(np.asarray(levels, dtype=float)):
        polylines = []
        # line_type="Separate": the lines are a list of (k, 2) point arrays, one per polyline
        for line in cast("list[np.ndarray]", generator.lines(float(level))):
            p, t = line[:, 0], line[:, 1]
            xyz = radius * np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1)
            polylines.append(xyz)
        curves.append(polylines)
    return curves


def view_direction(elev: float, azim: float) -> np.ndarray:
    """Unit vector from the origin towards the viewer of a matplotlib 3-D axes (degrees)."""
    e, a = np.radians(elev), np.radians(azim)
    return np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])


def split_front_back(points: np.ndarray, view: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Split a polyline on a centred sphere into its visible and hidden parts.

    Returns two copies of ``points`` (shape ``(k, 3)``) with the hidden, respectively the
    visible, points replaced by NaN, so that each draws as a broken line. Segments that
    cross the horizon keep one shared point on each side, so the two parts join.
    """
    pts = np.asarray(points, dtype=float)
    front = pts @ np.asarray(view, dtype=float) >= 0.0
    # a point adjacent to the other side stays in both parts so that they meet
    grow_front = front.copy()
    grow_front[1:] |= front[:-1]
    grow_front[:-1] |= front[1:]
    back = ~front
    grow_back = back.copy()
    grow_back[1:] |= back[:-1]
    grow_back[:-1] |= back[1:]
    visible = pts.copy()
    visible[~grow_front] = np.nan
    hidden = pts.copy()
    hidden[~grow_back] = np.nan
    return visible, hidden
