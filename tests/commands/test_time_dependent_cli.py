"""`dirac analyze` and `dirac run` on a system file that uses the time t.

Pendulum of changing length ``chi = x^2 + y^2 - (l0 + a t)^2`` (hand derivation in
tests/analysis/chain/test_rheonomic_chain.py): four stages of one constraint each, the third
``2 (x p_x + y p_y)/m - 2 a (l0 + a t)`` carrying the partial time derivative, 4 second-class
constraints, one degree of freedom. `dirac run` integrates it with RATTLE, whose kernel
takes the time (the rod length at every sample is l0 + a t).
"""

from __future__ import annotations

import json
import textwrap

import numpy as np

SYSTEM = textwrap.dedent(
    """
    [system]
    name = "growing_pendulum"
    coordinates = ["x", "y"]
    parameters = { m = 1.0, g = 9.81, l0 = 1.0, a = 0.1 }
    lagrangian = "m/2*(x_dot**2 + y_dot**2) - m*g*y"
    constraints = ["x**2 + y**2 - (l0 + a*t)**2"]
    """
)

SCENE = textwrap.dedent(
    """
    [system]
    file = "growing.toml"

    [initial]
    q = { x = 1.0, y = 0.0 }

    [run]
    t_end = 1.0
    method = "rattle-2"
    dt = 0.01
    samples = 3
    outputs = ["q"]
    """
)


def test_analyze_json_of_a_time_dependent_system_file(run_cli, tmp_path):
    path = tmp_path / "growing.toml"
    path.write_text(SYSTEM, encoding="utf-8")
    status, out, err = run_cli("analyze", str(path), "--json")
    assert status == 0, err
    data = json.loads(out)
    assert data["time_dependent"] is True
    assert [len(stage["constraints"]) for stage in data["stages"]] == [1, 1, 1, 1]
    assert "t" in data["stages"][2]["constraints"][0] and "a" in data["stages"][2]["constraints"][0]
    assert len(data["second_class"]) == 4 and data["physical_degrees_of_freedom"] == 1


def test_analyze_text_says_time_dependent(run_cli, tmp_path):
    path = tmp_path / "growing.toml"
    path.write_text(SYSTEM, encoding="utf-8")
    status, out, err = run_cli("analyze", str(path), "--param", "a=0.2")
    assert status == 0, err
    assert "time-dependent: t occurs explicitly" in out
    assert "parameters (symbolic): m, g, l0" in out
    assert "constraint 1: x**2 + y**2 - (l0 + t/5)**2 = 0" in out


def test_t_as_a_parameter_in_a_system_file_is_one_error_line(run_cli, tmp_path):
    path = tmp_path / "frozen.toml"
    path.write_text(SYSTEM.replace("a = 0.1 }", "a = 0.1, t = 0.0 }"), encoding="utf-8")
    status, out, err = run_cli("analyze", str(path))
    assert status == 2 and out == ""
    assert err.startswith("error: ") and err.count("\n") == 1
    assert "'t' is time" in err and "cannot be a parameter" in err


def test_run_integrates_a_time_dependent_system(run_cli, tmp_path):
    """The bead starts at (1, 0) moving outwards with the rod (x_dot = a = 0.1, on the moving
    surface at t = 0); RATTLE keeps x^2 + y^2 = (l0 + a t)^2 at every sample."""
    from dirac.io.results import read_results

    (tmp_path / "growing.toml").write_text(SYSTEM, encoding="utf-8")
    scene = tmp_path / "scene.toml"
    scene.write_text(SCENE.replace("q = { x = 1.0, y = 0.0 }", "q = { x = 1.0, y = 0.0 }\nq_dot = { x = 0.1, y = 0.0 }"),
                     encoding="utf-8")
    status, out, err = run_cli("run", str(scene), "--out", str(tmp_path / "out.npz"), "--no-progress")
    assert status == 0, err
    arrays, _meta = read_results(tmp_path / "out.npz")
    length = np.hypot(arrays["q"][:, 0], arrays["q"][:, 1])
    assert np.max(np.abs(length - (1.0 + 0.1 * arrays["t"]))) <= 1e-12
