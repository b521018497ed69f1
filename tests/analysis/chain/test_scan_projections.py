"""The scans of two rank decisions on one surface project onto it once (special_values._Projections)."""

from __future__ import annotations

import numpy as np
import pytest
import sympy

from dirac.analysis.chain.special_values import _Projections
from dirac.analysis.core.numeric import Numerics
from dirac.analysis.core.phase_space import PhaseSpace
from dirac.errors import AnalysisError

x, y, px, py = sympy.symbols("x y p_x p_y", real=True)
a = sympy.Symbol("a", positive=True)
SPACE = PhaseSpace((x, y), (px, py), (a,))
SURFACE = [x**2 + y**2 - a, x * px + y * py]


def _scan(numerics: Numerics, project) -> list:
    """What a scan asks: projections from given starts, then random ones, at two parameter values."""
    out = []
    for value in (0.5, 2.0):
        numerics.parameter_vector = np.array([value])
        for start in (np.array([1.0, 0.2, 0.3, -0.4]), np.array([-0.7, 0.9, 0.1, 0.5])):
            out += project(numerics, SURFACE, 1, attempts=1, start=start)
        out += project(numerics, SURFACE, 2, attempts=20)
    return out


def test_a_replay_gives_the_same_points_and_leaves_the_generator_as_a_projection_does(monkeypatch):
    direct = Numerics(SPACE, {a: 1.3}, seed=3)
    expected = _scan(direct, lambda n, c, k, **o: n.surface_points(c, k, **o))
    projections = _Projections()
    first = _scan(Numerics(SPACE, {a: 1.3}, seed=3), projections.surface_points)
    calls = []
    original = Numerics.surface_points
    monkeypatch.setattr(Numerics, "surface_points", lambda self, *args, **kw: calls.append(1) or original(self, *args, **kw))
    second_numerics = Numerics(SPACE, {a: 1.3}, seed=3)
    second = _scan(second_numerics, projections.surface_points)
    assert calls == []  # every projection of the second scan was a replay
    for points in (first, second):
        assert len(points) == len(expected) == 8
        assert all(np.array_equal(p, q) for p, q in zip(points, expected))  # bit for bit
    assert second_numerics.rng.bit_generator.state == direct.rng.bit_generator.state
    # another state of the generator is another projection
    second_numerics.rng.random()
    second_numerics.parameter_vector = np.array([2.0])
    projections.surface_points(second_numerics, SURFACE, 2, attempts=20)
    assert calls == [1]


def test_a_refusal_is_replayed():
    projections = _Projections()
    empty = [x**2 + y**2 + a]  # no real point for a > 0
    for _ in range(2):
        numerics = Numerics(SPACE, {a: 1.3}, seed=5)
        with pytest.raises(AnalysisError):
            projections.surface_points(numerics, empty, 1, attempts=3)
    assert len(projections._found) == 1
