"""The scale table of ``dirac bench --scale``: exponent fit, table, targets, the command's flags."""

from __future__ import annotations

import math

import pytest

from dirac.bench.scale import ScaleRow, format_scale_rows, growth_exponent, phase_space_size, scale_targets


def _rows() -> list[ScaleRow]:
    # t = c N^2 for the ring, t = c N for the chain (exponents known by construction)
    rows = [ScaleRow("maxwell_ring", n, phase_space_size("maxwell_ring", n), 1e-4 * (4 * n) ** 2, peak_mb=100.0)
            for n in (16, 32, 64)]
    rows += [ScaleRow("chain", n, phase_space_size("chain", n), 0.01 * 6 * n, peak_mb=150.0) for n in (4, 8)]
    rows.append(ScaleRow("chain", 16, phase_space_size("chain", 16), None, failed="over the 60 s budget"))
    return rows


def test_growth_exponent_of_power_laws_and_of_too_few_sizes():
    rows = _rows()
    assert math.isclose(growth_exponent(rows, "maxwell_ring"), 2.0)
    assert math.isclose(growth_exponent(rows, "chain"), 1.0)  # the failed size is not fitted
    assert growth_exponent(rows, "maxwell_torus") is None


def test_phase_space_sizes_are_the_hand_counts():
    assert phase_space_size("chain", 128) == 768  # x, y, lambda and momenta per link
    assert phase_space_size("maxwell_ring", 1024) == 4096
    assert phase_space_size("maxwell_torus", 16) == 1536


def test_targets_judge_the_exponent_and_the_memory():
    targets = {t.name: t for t in scale_targets(_rows(), quick=True)}
    assert targets["scale: growth exponent of maxwell_ring"].met is False
    assert targets["scale: growth exponent of chain"].met is True
    assert targets["scale: growth exponent of maxwell_torus"].met is None  # not measured
    assert targets["scale: peak memory of one analysis process"].value == 150.0
    full = {t.name for t in scale_targets(_rows(), quick=False)}
    assert "scale: analyze chain at size 128" in full


def test_table_shows_every_row_and_the_failure():
    text = format_scale_rows(_rows())
    assert text.count("\nmaxwell_ring") == 3 and "over the 60 s budget" in text
    assert "growth exponent (two largest finished sizes): 2.00" in text


def test_measure_one_reports_the_hand_counts_of_a_small_ring():
    from dirac.commands.bench_scale import measure_one

    result = measure_one("maxwell_ring", 4)
    assert result["counts"] == "stages 4+3, 7 first, 0 second class, 1 reducible, 1 dof"
    assert result["analyze_s"] > 0 and result["bracket_ms"] > 0


@pytest.mark.parametrize("flags", [("--scale", "--stress"), ("--scale", "--ensemble")])
def test_scale_is_exclusive_with_the_other_benchmarks(run_cli, flags):
    status, _, err = run_cli("bench", *flags)
    assert status == 2 and err.startswith("error:") and "--scale" in err
