"""Geometry of the rigid-body pictures: polhodes are sphere-ellipsoid intersections."""

from __future__ import annotations

import numpy as np
import pytest

from dirac.plots.geometry import (
    ellipsoid_mesh,
    energy_on_sphere,
    level_curves_on_sphere,
    polhode_levels,
    split_front_back,
    view_direction,
)

INERTIA = np.array([2.0, 1.0, 2.0 / 3.0])


def test_polhode_levels_lie_strictly_between_the_stable_axes_and_skip_the_separatrix() -> None:
    levels, separatrix = polhode_levels(INERTIA, 8)
    assert separatrix == pytest.approx(1.0)  # 1 / I_mid with I_mid = 1
    assert len(levels) == 8
    assert np.all(levels > 0.5) and np.all(levels < 1.5)  # 1/I_max = 0.5, 1/I_min = 1.5
    assert np.all(np.abs(levels - 1.0) > 1e-6)
    assert np.sum(levels < 1.0) == np.sum(levels > 1.0) == 4


@pytest.mark.parametrize("radius", [1.0, 2.5])
def test_level_curves_are_on_the_sphere_and_on_the_energy_ellipsoid(radius: float) -> None:
    level = 1.2  # 2E/G^2 between 1/I_mid = 1 and 1/I_min = 1.5: curves around axis 3
    (curve,) = level_curves_on_sphere(INERTIA, [level], radius)
    assert len(curve) >= 2  # the two polhodes around +e3 and -e3 (possibly cut at the seam)
    points = np.concatenate(curve)
    assert np.allclose(np.linalg.norm(points, axis=1), radius, rtol=1e-12)
    # sum_i M_i^2 / I_i = 2E = level * G^2, up to the contour's linear interpolation
    energy_level = np.sum(points**2 / INERTIA, axis=1) / radius**2
    assert np.max(np.abs(energy_level - level)) < 2e-3
    # they encircle axis 3: |M_3| stays away from 0
    assert np.min(np.abs(points[:, 2])) > 0.3 * radius


def test_the_separatrix_passes_through_the_middle_axis() -> None:
    (curve,) = level_curves_on_sphere(INERTIA, [1.0])
    points = np.concatenate(curve)
    for pole in (np.array([0.0, 1.0, 0.0]), np.array([0.0, -1.0, 0.0])):
        assert np.min(np.linalg.norm(points - pole, axis=1)) < 0.03


def test_levels_outside_the_range_give_no_curve() -> None:
    assert level_curves_on_sphere(INERTIA, [0.3, 2.0]) == [[], []]


def test_energy_on_sphere_and_ellipsoid_mesh() -> None:
    assert energy_on_sphere(np.eye(3), INERTIA) == pytest.approx(1.0 / INERTIA)
    x, y, z = ellipsoid_mesh(np.array([3.0, 2.0, 1.0]), 21)
    assert np.allclose((x / 3.0) ** 2 + (y / 2.0) ** 2 + z**2, 1.0)


def test_view_direction_matches_matplotlib_angles() -> None:
    assert view_direction(0.0, 0.0) == pytest.approx([1.0, 0.0, 0.0])
    assert view_direction(90.0, 0.0) == pytest.approx([0.0, 0.0, 1.0], abs=1e-15)
    assert view_direction(0.0, 90.0) == pytest.approx([0.0, 1.0, 0.0], abs=1e-15)


def test_split_front_back_keeps_each_side_and_joins_them() -> None:
    angle = np.linspace(0.0, 2.0 * np.pi, 9)[:-1]
    circle = np.stack([np.cos(angle), np.sin(angle), np.zeros_like(angle)], axis=1)
    visible, hidden = split_front_back(circle, np.array([1.0, 0.0, 0.0]))
    front = circle[:, 0] >= 0
    assert np.array_equal(visible[front], circle[front])
    assert np.array_equal(hidden[~front], circle[~front])
    # every point is drawn at least once, and the parts share the points at the horizon
    drawn = ~np.isnan(visible[:, 0]) | ~np.isnan(hidden[:, 0])
    assert drawn.all()
    assert np.sum(~np.isnan(visible[:, 0]) & ~np.isnan(hidden[:, 0])) >= 2
