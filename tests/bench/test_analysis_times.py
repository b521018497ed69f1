"""The symbolic-analysis cases of ``dirac bench`` run in a fresh process and report their outcome."""

from __future__ import annotations

from dirac.bench.analysis_times import ANALYSIS_CASES, analysis_time


def test_conic_case_is_refused_in_a_fresh_process() -> None:
    # the square-root particle on an ellipse is refused at stage 2 (tests/analysis/test_relativistic_conic.py)
    case = next(c for c in ANALYSIS_CASES if "ellipse" in c.name)
    row = analysis_time(case)
    # refused as two parts that meet (SeparableParts, an AnalysisError naming both branches)
    assert row["outcome"] in {"AnalysisError", "SeparableParts"}
    assert 0.0 < row["cpu"] and 0.0 < row["wall"]


def test_every_case_has_a_target() -> None:
    assert [c.target for c in ANALYSIS_CASES] == [2.0, 1.5, 1.0, 5.0]
