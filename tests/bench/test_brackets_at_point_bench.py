"""The brackets-at-a-point table of ``dirac bench`` (dirac/bench/brackets_at_point.py)."""

from __future__ import annotations

from dirac.bench.brackets_at_point import _chain_row, format_brackets_at_point


def test_a_row_agrees_with_the_closed_form_and_is_printed() -> None:
    """One size in its fresh process: {x_(N-1), p_x_N}_D against the closed form
    delta - G^T (G G^T)^{-1} G computed by hand in the child (numpy), and the counts of
    the 8-link chain (48 variables, 32 second-class constraints: tests/systems)."""
    row = _chain_row(8, 1)
    assert (row["variables"], row["second_class"]) == (48, 32)
    assert row["error"] < 1e-12
    for key in ("bracket_same_point_ms", "bracket_new_point_ms", "motion_new_point_ms", "closed_form_ms"):
        assert row[key] > 0.0
    table = format_brackets_at_point([row])
    assert table.splitlines()[2].split()[:3] == ["8", "48", "32"]
