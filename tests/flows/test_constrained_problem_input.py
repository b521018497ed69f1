"""ConstrainedProblem takes a Lagrangian as it comes from the user (README example)."""

from __future__ import annotations

import pytest

import dirac


def test_constrained_problem_accepts_a_lagrangian_directly():
    pendulum = dirac.load_system("pendulum")
    problem = dirac.ConstrainedProblem(pendulum, q0=[0.6, -0.8], p0=[0.0, 0.0])
    assert list(problem.mechanics.coordinate_names) == ["x", "y"]
    with pytest.raises(dirac.InputError, match="off the constraint surface"):
        dirac.ConstrainedProblem(pendulum, q0=[0.6, -0.7], p0=[0.0, 0.0])
