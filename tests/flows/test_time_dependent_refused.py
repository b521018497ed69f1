"""Explicit time ``t``: the mechanical flows take it (RATTLE's generated kernels evaluate
chi(q, t), V(q, t) at the sub-step times; see test_time_dependent_flows.py), the Dirac flow
of a full analysis refuses it with a clear error instead of integrating with ``t`` frozen
(which would drop the partial time derivative of the constraints)."""

from __future__ import annotations

import pytest

from dirac.errors import DiracError
from dirac.flows import MechanicalSystem
from dirac.flows.analysed import AnalysedSystem
from dirac.flows.mechanics import TimeDependentSystemError
from dirac.model.lagrangian import Lagrangian

GROWING = Lagrangian.from_strings(
    "growing_pendulum",
    ["x", "y"],
    "(x_dot**2 + y_dot**2)/2 - g*y",
    ["x**2 + y**2 - (1 + a*t)**2"],
    parameters={"g": 9.81, "a": 0.1},
)


def test_mechanical_system_takes_explicit_time():
    system = MechanicalSystem.from_lagrangian(GROWING)
    assert system.time_symbol is not None and system.time_symbol.name == "t"


def test_the_analysed_flow_refusal_names_the_way_that_works():
    with pytest.raises(TimeDependentSystemError, match=r"'growing_pendulum' depends explicitly on the time t.*rattle"):
        AnalysedSystem.from_lagrangian(GROWING)


def test_analysed_system_refuses_explicit_time_before_analysing():
    with pytest.raises(DiracError, match="depends explicitly on the time t"):
        AnalysedSystem.from_lagrangian(GROWING)


def test_t_as_a_coordinate_is_not_time_dependence():
    """A coordinate named t (no explicit time): the free particle L = (t_dot^2 + x_dot^2)/2 compiles."""
    free = Lagrangian.from_strings("free", ["t", "x"], "(t_dot**2 + x_dot**2)/2")
    assert MechanicalSystem.from_lagrangian(free).name == "free"
