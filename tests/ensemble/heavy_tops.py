"""The heavy tops of the ensemble tests (shared by the test files of heavy-top ensembles, so that
their scenes and single runs agree): the tilt of an initial attitude, the driven top's scene
``DRIVEN`` and its torque, a single driven run of one member, and a refused scene."""

from __future__ import annotations

import numpy as np
from ensemble_stores import run_ensemble_cli


def tilted(angle: float) -> np.ndarray:
    """The rotation by ``angle`` about the body's first axis (as the scenes' R)."""
    return np.array([[1.0, 0.0, 0.0], [0.0, np.cos(angle), -np.sin(angle)], [0.0, np.sin(angle), np.cos(angle)]])


DRIVEN = """[system]
name = "heavy_top"
inertia = [1.0, "b", 0.6]
mass_gravity = 1.5
center_of_mass = [0.3, 0.0, 1.0]

[forces]
torque = ["-0.2*Omega_1 + 0.1*sin(3*t)", "-0.2*Omega_2", "0.05*R_31 - 0.2*Omega_3"]

[initial]
omega = [0.3, "w", 2.0]
R = [[1.0, 0.0, 0.0], [0.0, "cos(0.4)", "-sin(0.4)"], [0.0, "sin(0.4)", "cos(0.4)"]]

[run]
method = "lie-poisson-4"
dt = 0.007
t_end = 2.0
samples = 5

[ensemble]
grid = { b = [0.8, 1.4, 3], w = [-0.5, 0.5, 2] }
reductions = ["final", "energy_error", "constraint_error"]
"""


TORQUE = ["-0.2*Omega_1 + 0.1*sin(3*t)", "-0.2*Omega_2", "0.05*R_31 - 0.2*Omega_3"]
TORQUE_TEXT = "[" + ", ".join(f'"{component}"' for component in TORQUE) + "]"  # as DRIVEN gives it


def single_driven(method: str, b: float, w: float, torque: list[str] | None, t_end: float = 2.0, samples: int = 5,
                  impulses: list | None = None):
    """dirac.integrate of the driven top of ``DRIVEN`` with ``I_2 = b`` and ``omega_2 = w`` (and the
    given torque and impulses): the single run a member of the scene must equal."""
    from dirac.flows import integrate
    from dirac.flows.problems import HeavyTopProblem

    inertia = np.array([1.0, b, 0.6])
    problem = HeavyTopProblem(inertia, inertia * np.array([0.3, w, 2.0]), tilted(0.4), mass_gravity=1.5,
                              center_of_mass=[0.3, 0.0, 1.0], torque=torque, impulses=impulses or ())
    return integrate(problem, method, t_end=t_end, dt=0.007, samples=samples, outputs=["M", "R", "energy", "work"])


def refused(path, out, message):
    """``dirac ensemble`` refuses the scene ``path`` with one ``error:`` line holding ``message``
    (exit status 2) and writes nothing."""
    result = run_ensemble_cli(path, out)
    assert result.returncode == 2, result.stderr
    assert result.stderr.startswith("error: ") and message in result.stderr and len(result.stderr.splitlines()) == 1
    assert not out.exists()
