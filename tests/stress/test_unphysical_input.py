"""Unphysical but legal input is warned about, not refused.

``I_i + I_j < I_k`` belongs to no real body (docs/conventions.md: ``I_1 = g_2 + g_3`` etc. (72)
with ``g_i >= 0``), yet the Euler–Poisson flow (250)–(251) is defined for any positive
inertia and the standard body ``I = (2, 1, 2/3)`` of the standard test case is such a case: one
``warning:`` line, and the run goes on. The Lagrangians (19) and (78) need a positive
mass matrix ``g`` and refuse such moments with an ``error:``.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from cli_output import one_error_line

import dirac
from dirac.errors import DiracWarning, InputError

STANDARD_SCENE = """
[system]
name = "rigid_body"
inertia = [2.0, 1.0, 0.6666666666666666]
[initial]
M = [0.4535961214255773, 0.0, 0.8912073600614354]
[run]
t_end = 10.0
method = "lie-poisson-4"
dt = 0.01
samples = 3
"""


def test_standard_body_warns_once_and_integrates():
    from dirac.flows.integration import integrate
    from dirac.flows.problems import RigidBodyProblem

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        problem = RigidBodyProblem([2.0, 1.0, 2.0 / 3.0], [np.cos(1.1), 0.0, np.sin(1.1)])
        solution = integrate(problem, "exact", t_end=10.0, samples=2, outputs=["M"])
    dirac_warnings = [w for w in caught if issubclass(w.category, DiracWarning)]
    assert len(dirac_warnings) == 1 and "triangle" in str(dirac_warnings[0].message)
    # M(10) of the standard test case (docs/conventions.md)
    assert np.allclose(solution["M"][-1], [0.40706613658804081, 0.28300742681284408, 0.86844916766156164],
                       rtol=0, atol=1e-13)


def test_standard_scene_prints_one_warning_line_and_exits_0(tmp_path, run_cli):
    path = tmp_path / "standard.toml"
    path.write_text(STANDARD_SCENE)
    status, _, err = run_cli("run", str(path), "--out", str(tmp_path / "out.npz"), "--no-progress")
    lines = [line for line in err.splitlines() if line.strip()]
    assert status == 0, err
    assert len(lines) == 1 and lines[0].startswith("warning:") and "triangle" in lines[0], err


@pytest.mark.parametrize("inertia", [(1.0, 2.0, 3.0), (2.0, 2.0, 2.0), (1.0, 1.0, 1.9)])
def test_physical_and_plane_bodies_are_not_warned_about(inertia):
    from dirac.flows.problems import RigidBodyProblem

    with warnings.catch_warnings():
        warnings.simplefilter("error", DiracWarning)
        RigidBodyProblem(inertia, [0.3, 0.4, 0.5])


@pytest.mark.parametrize("inertia", [(2.0, 1.0, 2.0 / 3.0), (1.0, 2.0, 3.5), (5.0, 1.0, 1.0)])
def test_matrix_lagrangian_78_refuses_a_mass_matrix_that_is_not_positive(inertia):
    with pytest.raises(InputError, match="triangle inequality"):
        dirac.load_system("rigid_body_matrix", I_1=inertia[0], I_2=inertia[1], I_3=inertia[2])


def test_matrix_lagrangian_78_refuses_the_plane_body_whose_g_is_singular():
    with pytest.raises(InputError):
        dirac.load_system("rigid_body_matrix", I_1=1.0, I_2=2.0, I_3=3.0)


def test_particle_lagrangian_19_refuses_a_negative_mass():
    with pytest.raises(InputError):
        dirac.load_system("rigid_body_particles", masses=[1.0, 2.0, 3.0, -4.0])


def test_analyze_of_78_with_the_standard_inertia_is_one_error_line(run_cli):
    status, _, err = run_cli("analyze", "rigid_body_matrix", "--param", "I_1=2", "--param", "I_2=1",
                             "--param", "I_3=0.6666666666666666")
    assert "g_1" in one_error_line(status, err), err
