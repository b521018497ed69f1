"""Assumptions ``EXPR != 0`` / ``EXPR = 0`` (:mod:`dirac.analysis.chain.assumptions`).

The hand counts: a pendulum written with the constraint ``x**2 + y**2 - l**2`` has 4
second-class constraints and 1 degree of freedom; assuming ``x = 0`` in addition adds a
holonomic constraint: the bob is fixed at ``(0, +-l)`` (``p_lambda_k``, ``chi_k``, their
velocities and the multiplier equations: 8 second class, ``(8 - 8)/2 = 0`` degrees of freedom).
"""

from __future__ import annotations

import json

import pytest
import sympy
from cli_output import one_error_line

import dirac
from dirac.analysis.chain.assumptions import parse_assumptions
from dirac.errors import InputError

PENDULUM = dict(m=1.0, g=9.81, l=1.0)


def test_parse_both_forms():
    x, y = sympy.symbols("x y")
    parsed = parse_assumptions(["x**2 + y**2 != 0", "x = y"], {"x": x, "y": y})
    assert [(p.expression, p.nonzero) for p in parsed] == [(x**2 + y**2, True), (x - y, False)]


@pytest.mark.parametrize("text, match", [("x > 0", "malformed"), ("xx != 0", "unknown name"), ("1 != 0", "does not depend")])
def test_malformed_assumptions_are_refused(text, match):
    x = sympy.Symbol("x")
    with pytest.raises(InputError, match=match):
        parse_assumptions([text], {"x": x})


def test_nonzero_assumption_keeps_points_away():
    """Assuming ``x != 0`` on the pendulum changes nothing but the sample points: every one has ``x`` away from 0."""
    a = dirac.analyze(dirac.load_system("pendulum", **PENDULUM), assume=["x != 0"])
    assert (len(a.second_class), a.physical_degrees_of_freedom) == (4, 1)
    ix = a.phase_space.index(a.symbols["x"])
    assert all(abs(z[ix]) > 1e-6 for z in a._points)
    assert a.to_json()["assumptions"] == ["x != 0"]


def test_equality_assumption_keeps_the_motions_that_stay_on_it(run_cli):
    """``x = 0`` on the pendulum (m = l = 1) is imposed without a multiplier: the motion stays on
    ``x = 0`` only at rest at the bottom or the top. By hand: x = 0, then x_dot = p_x = 0, then the
    rod y**2 = 1 with y p_y = 0 and lambda = -g y / 2 (from p_x_dot = -2 lambda x = 0 and
    p_y_dot = -2 lambda y - g = 0): 6 second-class constraints in the 6-dimensional phase space,
    0 degrees of freedom, the Lagrangian unchanged (no multiplier for x)."""
    status, out, _ = run_cli("analyze", "pendulum", "--param", "m=1", "--param", "g=9.81", "--param", "l=1",
                             "--assume", "x = 0", "--json")
    data = json.loads(out)
    assert status == 0 and (len(data["first_class"]), len(data["second_class"]), data["physical_degrees_of_freedom"]) == (0, 6, 0)
    assert data["stages"][1]["constraints"] == ["x"]
    a = dirac.analyze(dirac.load_system("pendulum", m=1.0, g=9.81, l=1.0), assume=["x = 0"])
    assert len(a.phase_space) == 6  # no new multiplier
    point = a.surface_point()
    assert abs(point["x"]) < 1e-10 and abs(abs(point["y"]) - 1) < 1e-10
    assert abs(point["p_x"]) < 1e-10 and abs(point["p_y"]) < 1e-10
    assert abs(point["lambda_1"] + 9.81 * point["y"] / 2) < 1e-8


def test_equality_assumption_that_cannot_hold_is_refused():
    with pytest.raises(dirac.errors.InconsistentSystemError, match="cannot hold"):
        dirac.analyze(dirac.load_system("pendulum", m=1.0, g=9.81, l=1.0), assume=["p_lambda_1 - 1 = 0"])


def test_cli_unknown_name_is_one_error_line(run_cli):
    status, _, err = run_cli("analyze", "pendulum", "--assume", "xx != 0")
    line = one_error_line(status, err)
    assert "xx" in line
