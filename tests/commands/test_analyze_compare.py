"""``dirac analyze SYSTEM --compare SPEC``: the report of :func:`cli_compare` and the
checks of SPEC."""

from __future__ import annotations

import json

import pytest
from rigid_body_analyses import cached_analysis

import dirac
from dirac.commands.analyze_compare import cli_compare
from dirac.errors import InputError


@pytest.fixture(scope="module")
def analysis(request):
    return cached_analysis(request.config, "rigid_body_matrix")


def test_cli_compare_json_and_text(analysis):
    report = json.loads(cli_compare(analysis, "dirac,chetaev:2", as_json=True))
    assert report["agree"] is True and report["points"] == 2 and report["differ"] == []
    assert report["jacobi"]["dirac"] < 1e-6 and report["jacobi"]["chetaev"] < 1e-12
    assert len(report["casimirs"]["chetaev"]) == 6
    text = cli_compare(analysis, "lie_poisson_so3, dirac:2", as_json=False)
    assert "agree on all 3 pairs" in text and "M_1**2 + M_2**2 + M_3**2" in text


@pytest.mark.parametrize(
    "spec, message",
    [("dirac", "name two brackets"), ("dirac,foo", "unknown bracket"), ("dirac,chetaev:x", "integer"), ("dirac,chetaev:0", "at least 1")],
)
def test_cli_compare_rejects_bad_specs(analysis, spec, message):
    with pytest.raises(InputError, match=message):
        cli_compare(analysis, spec, as_json=False)


def test_chetaev_needs_a_rigid_body():
    pendulum = dirac.analyze(dirac.load_system("pendulum"))
    with pytest.raises(InputError, match="R_11"):
        cli_compare(pendulum, "dirac,chetaev", as_json=False)
    report = json.loads(cli_compare(pendulum, "dirac,canonical:3", as_json=True))
    assert report["variables"] == ["x", "y", "p_x", "p_y"]
    assert not report["agree"]  # {x, p_x} = 1 canonically, less on the circle
