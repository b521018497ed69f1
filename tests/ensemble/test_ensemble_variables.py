"""The order of ensemble variables survives meta.json and the fingerprint (variables.py)."""

from __future__ import annotations

import json

import numpy as np

from dirac.ensemble.variables import parse_variables


def _hash(source) -> str:
    return json.dumps(source.describe(), sort_keys=True)  # as meta.json and the fingerprint write it


def test_grid_order_numbers_the_members_and_is_kept():
    """Members are numbered in C order over the grid as listed (the last variable fastest):
    with (b, a) member 1 has the second value of a; sorted JSON alone would read it as (a, b)."""
    ba = parse_variables({"grid": {"b": [0.0, 1.0, 2], "a": [10.0, 20.0, 3]}})
    ab = parse_variables({"grid": {"a": [10.0, 20.0, 3], "b": [0.0, 1.0, 2]}})
    assert np.array_equal(ba.members(0, 2), [[0.0, 10.0], [0.0, 15.0]])
    assert np.array_equal(ab.members(0, 2), [[10.0, 0.0], [10.0, 1.0]])
    assert ba.describe()["order"] == {"grid": ["b", "a"], "random": []}
    assert "order" not in ab.describe()  # alphabetical: described as before
    assert _hash(ab) != _hash(ba)


def test_random_order_picks_the_streams_and_is_kept():
    """The random variables' streams follow their listed position: swapping two uniform
    variables of equal range swaps their draws, so the two scenes differ."""
    xy = parse_variables({"variables": {"x": {"distribution": "uniform", "low": 0, "high": 1},
                                        "y": {"distribution": "uniform", "low": 0, "high": 1}}, "count": 4})
    yx = parse_variables({"variables": {"y": {"distribution": "uniform", "low": 0, "high": 1},
                                        "x": {"distribution": "uniform", "low": 0, "high": 1}}, "count": 4})
    assert np.array_equal(xy.members(0, 4), yx.members(0, 4))  # column k is the k-th stream either way
    assert yx.describe()["order"] == {"grid": [], "random": ["y", "x"]}
    assert _hash(xy) != _hash(yx)
