"""The bounded symbolic-analysis cases of ``dirac bench`` and its end-to-end ``dirac analyze`` targets."""

from __future__ import annotations

import dirac
from dirac.bench.analysis_times import ANALYZE_COMMAND_TARGETS, BOUNDED_CASES, analysis_time


def test_relativistic_conic_is_analysed_in_a_fresh_process() -> None:
    """The regular relativistic particle on a conic is analysed (not refused): its special-value search is bounded."""
    (case,) = BOUNDED_CASES
    row = analysis_time(case)
    assert row["outcome"] == "analysed"
    assert 0.0 < row["cpu"] and 0.0 < row["wall"]


def test_end_to_end_targets_name_built_in_systems() -> None:
    """The paper's three rigid-body Lagrangians, with the targets 3, 2.5 and 2 s."""
    assert ANALYZE_COMMAND_TARGETS == {"rigid_body_momentum": 3.0, "rigid_body_particles": 2.5, "rigid_body_matrix": 2.0}
    for name in ANALYZE_COMMAND_TARGETS:
        assert dirac.load_system(name).name
