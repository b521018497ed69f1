"""The everyday systems of ``dirac bench`` timed with their text report (``REPORT_CASES``)."""

from __future__ import annotations

import dirac
from dirac.bench.analysis_times import REPORT_CASES, analysis_time
from dirac_systems.report_models import MODELS


def test_every_model_is_a_case_with_a_target_of_a_few_seconds() -> None:
    assert [case.report for case in REPORT_CASES] == [True] * len(MODELS)
    assert {case.target for case in REPORT_CASES} == {5.0}
    assert len(REPORT_CASES) == len(MODELS)
    for name, build in MODELS.items():
        assert isinstance(build(), dirac.Lagrangian) and build().name == name


def test_the_slider_crank_and_its_report_in_a_fresh_process() -> None:
    """Its report waited on a ``trigsimp`` that did not end in five minutes; now it is analysed and reported."""
    case = next(c for c in REPORT_CASES if "slider" in c.name)
    row = analysis_time(case)
    assert row["outcome"] == "analysed"
    assert 0.0 < row["cpu"] and 0.0 < row["wall"]
