"""The field-theory table of dirac bench: one fresh-process analysis, its counts in the table."""

from __future__ import annotations

from dirac.bench.field_theories import field_theory_table


def test_table_rows_and_the_slowest_median():
    runs = [("maxwell", [{"cpu": 0.5, "wall": 1.0, "dof": 2, "stages": [1, 1], "first": 2, "second": 0, "gauge": 1},
                         {"cpu": 0.7, "wall": 1.2, "dof": 2, "stages": [1, 1], "first": 2, "second": 0, "gauge": 1},
                         {"cpu": 0.6, "wall": 1.1, "dof": 2, "stages": [1, 1], "first": 2, "second": 0, "gauge": 1}])]
    table, worst = field_theory_table(runs)
    assert worst == 0.6  # the median of 0.5, 0.7, 0.6
    assert "maxwell" in table and "[1, 1]" in table and "0.60" in table
