"""The vector-field table of ``dirac bench``: structure and agreement (no timing assertions)."""

from __future__ import annotations

import math

import numpy as np

from dirac.bench.vector_field import format_vector_field_table, measure_vector_field, pendulum_lean_rhs


def test_the_lean_baseline_is_the_pendulum_field_by_hand():
    """At theta = pi/2 at rest (x = l = 1, y = 0, p = 0): lambda = (|p|^2/m - m g y)/(2 l^2) = 0,
    so the field is (0, 0, 0, 0, -g, 0): free fall of the bob, by hand."""
    assert pendulum_lean_rhs(0.0, np.array([1.0, 0.0, 0.0, 0.0, 0.0, 0.0])) == [0.0, 0.0, 0.0, -0.0, -9.81, 0.0]


def test_the_table_compares_the_compiled_field_with_the_lean_baseline():
    rows, target = measure_vector_field(repeats=1, calls=50, batch=100)
    names = [row["field"] for row in rows]
    assert names[0] == "analysis.vector_field(): f(t, y)" and names[1].startswith("lean Python RHS")
    assert all(row["us_per_call"] > 0 for row in rows if "us_per_call" in row)
    assert rows[1]["ratio_to_lean"] == 1.0
    # the two right-hand sides are the same function on the surface
    assert target.extra["agreement"] <= 1e-12
    assert math.isfinite(target.value) and target.sense == "<=" and target.target == 1.0
    integrated = [row for row in rows if "ms" in row]
    assert len(integrated) == 2 and integrated[0]["circle_drift"] <= 1e-8
    text = format_vector_field_table(rows)
    assert "analysis.vector_field(): f(t, y)" in text and "solve_ivp DOP853" in text
    assert any("before" in name for name in names)
    quick_rows, _ = measure_vector_field(repeats=1, calls=50, batch=100, before=False)
    assert not any("before" in row["field"] for row in quick_rows)
