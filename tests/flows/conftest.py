"""Shared fixtures of the flow tests: compiled systems are built once per session."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from dirac.errors import DiracWarning

#: The standard test case and its reference values (docs/conventions.md).
STANDARD_INERTIA = np.array([2.0, 1.0, 2.0 / 3.0])
STANDARD_M0 = np.array([np.cos(1.1), 0.0, np.sin(1.1)])
STANDARD_M10 = np.array([0.40706613658804081, 0.28300742681284408, 0.86844916766156164])
STANDARD_ENERGY = 0.64712527931383642713


@pytest.fixture(scope="session")
def pendulum_system():
    from dirac.flows.mechanics import MechanicalSystem
    from dirac.model.systems import load_system

    return MechanicalSystem.from_lagrangian(load_system("pendulum"))


@pytest.fixture(scope="session")
def double_pendulum_system():
    from dirac.flows.mechanics import MechanicalSystem
    from dirac.model.systems import load_system

    return MechanicalSystem.from_lagrangian(load_system("double_pendulum"))


@pytest.fixture
def standard_problem():
    from dirac.flows.problems import RigidBodyProblem

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DiracWarning)  # I = (2, 1, 2/3) is not physical: it warns
        return RigidBodyProblem(STANDARD_INERTIA, STANDARD_M0)


@pytest.fixture
def stress() -> float:
    """:func:`stress_scaling.stress_scale` as a fixture."""
    from stress_scaling import stress_scale

    return stress_scale()
