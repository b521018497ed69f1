"""The exact multiplier solution is computed on first use; the numeric decisions are not deferred.

The pendulum in Cartesian coordinates (``chain(1)``): ``L = m/2 (x_dot^2 + y_dot^2) - m g y``
with ``chi = x^2 + y^2 - l^2`` (by hand, as in test_multiplier_solution.py with
``lambda = lambda_1``): the chain ``p_lambda``, ``chi``, ``2 (x p_x + y p_y)/m``,
``psi_4 = 2 g y + 4 lambda r^2/m - 2 p^2/m^2``; the last condition
``{psi_4, H_c} + u 4 r^2/m = 0`` with ``{psi_4, H_c} = 6 g p_y/m + 16 lambda (x p_x + y p_y)/m^2``
fixes ``u = (-3 g p_y - 8 lambda (x p_x + y p_y)/m) / (2 r^2)`` alone.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy

import dirac
from dirac.analysis.chain.constraint_chain import ConstraintChain
from dirac.analysis.classes.multiplier_solution import MultiplierSolution
from dirac_systems.scale_models import chain


@pytest.fixture()
def pendulum():
    return dirac.analyze(chain(1))


def _u_by_hand(s: dict) -> sympy.Expr:
    m, g = sympy.symbols("m g", real=True)
    radial = s["x1"] * s["p_x1"] + s["y1"] * s["p_y1"]
    return (-3 * g * s["p_y1"] - 8 * s["lambda_1"] * radial / m) / (2 * (s["x1"] ** 2 + s["y1"] ** 2))


def test_names_are_known_before_the_exact_solve(pendulum):
    solution = pendulum.multiplier_solution
    assert not solution.solved
    assert list(pendulum.multipliers) == ["u_1"] and len(pendulum.multipliers) == 1 and "u_1" in pendulum.multipliers
    assert pendulum.undetermined_multipliers == [] and solution.free == ()
    assert not solution.solved  # names, counts and membership do not run the solve
    assert repr(pendulum.multipliers) == repr({"u_1": solution.particular["u_1"]})  # printing shows the values


def test_first_read_solves_exactly_and_matches_the_hand_value(pendulum):
    s = pendulum.symbols
    u = pendulum.multipliers["u_1"]
    assert pendulum.multiplier_solution.solved
    assert sympy.simplify(u - _u_by_hand(s)) == 0
    assert pendulum.multiplier_solution.particular["u_1"] is u
    assert pendulum.multiplier_solution.null_vectors == []
    assert dict(pendulum.multipliers) == {"u_1": u}


def test_report_shows_the_solution_when_asked(pendulum):
    data = pendulum.to_json()
    assert data["multipliers"]["u_1"] != "undetermined"
    assert data["multiplier_solution"]["null_vectors"] == []
    assert pendulum.multiplier_solution.solved


def test_a_solution_needs_values_or_a_solve():
    x = sympy.Symbol("x", real=True)
    u = sympy.Symbol("u_1", real=True)
    with pytest.raises(ValueError, match="needs its particular solution"):
        MultiplierSolution((u,), [x], x, None, None)
    calls = []

    def solve():
        calls.append(1)
        return {"u_1": x}, []

    lazy = MultiplierSolution((u,), [x], x, None, None, solve=solve)
    assert lazy.particular == {"u_1": x} and lazy.particular == {"u_1": x} and calls == [1]  # solved once


@pytest.mark.parametrize(
    ("rows", "fixed"),
    [
        ([[2.0, 0.0], [0.0, 3.0]], [1, 1]),  # invertible: both fixed alone (one SVD)
        ([[1.0, 1.0]], [0, 0]),  # only u_1 + u_2 fixed: neither alone
        ([[1.0, 0.0, 0.0], [0.0, 1.0, 1.0]], [1, 0, 0]),  # u_1 alone, u_2 + u_3 only
        ([[1.0, 0.0], [0.0, 1e-12]], [1, 0]),  # numerically rank 1: u_2 is not fixed there
    ],
)
def test_fixed_alone_at_a_point_by_hand(rows, fixed):
    """``u_k`` is fixed alone exactly when ``e_k`` lies in the row space of ``A_P`` (hand cases)."""
    assert list(ConstraintChain._fixed_alone_at_point(np.array(rows))) == fixed
