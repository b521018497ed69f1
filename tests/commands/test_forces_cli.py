"""Forced systems on the command line: bad input exits 2 with one error: line."""

from __future__ import annotations

from pathlib import Path

import pytest
from cli_output import one_error_line

SYSTEM = """[system]
name = "damped_pendulum"
coordinates = ["x", "y"]
parameters = { m = 1.0, g = 9.81, l = 1.0, c = 0.3 }
lagrangian = "m/2*(x_dot**2 + y_dot**2) - m*g*y"
constraints = ["x**2 + y**2 - l**2"]
forces = FORCES
"""

SCENE = """[system]
file = "system.toml"
[initial]
q = { x = 0.0, y = -1.0 }
q_dot = { x = 1.0 }
IMPULSES
[run]
t_end = 1.0
method = "METHOD"
dt = 0.01
samples = 3
"""


def _files(tmp_path: Path, forces: str = '{ x = "-c*x_dot", y = "-c*y_dot" }', impulses: str = "",
           method: str = "forced-rattle-2") -> Path:
    (tmp_path / "system.toml").write_text(SYSTEM.replace("FORCES", forces), encoding="utf-8")
    scene = tmp_path / "scene.toml"
    scene.write_text(SCENE.replace("IMPULSES", impulses).replace("METHOD", method), encoding="utf-8")
    return scene


@pytest.mark.parametrize("forces, fragment", [
    ('{ z = "-c*x_dot" }', "a force is given on 'z', which is not a coordinate"),
    ('{ x = "-cc*x_dot" }', "unknown name 'cc' (did you mean 'c'?)"),
    ('{ xx = "-c*x_dot" }', "(did you mean 'x'?)"),
])
def test_bad_forces_exit_2_with_one_error_line(tmp_path, run_cli, forces, fragment):
    status, _, err = run_cli("run", str(_files(tmp_path, forces=forces)), "--no-progress")
    assert fragment in one_error_line(status, err)
    status, _, err = run_cli("analyze", str(tmp_path / "system.toml"))
    assert fragment in one_error_line(status, err)


def test_impulse_at_negative_time_exits_2(tmp_path, run_cli):
    scene = _files(tmp_path, impulses="[[impulses]]\nt = -0.5\nQ = { x = 1.0 }\n")
    status, _, err = run_cli("run", str(scene), "--no-progress")
    assert "not after the start" in one_error_line(status, err)


def test_impulse_on_unknown_coordinate_exits_2(tmp_path, run_cli):
    scene = _files(tmp_path, impulses="[[impulses]]\nt = 0.5\nQ = { z = 1.0 }\n")
    status, _, err = run_cli("run", str(scene), "--no-progress")
    assert "names 'z', which is not a coordinate" in one_error_line(status, err)


def test_impulse_after_t_end_warns_and_runs(tmp_path, run_cli):
    scene = _files(tmp_path, impulses="[[impulses]]\nt = 5.0\nQ = { x = 1.0 }\n")
    status, _, err = run_cli("run", str(scene), "--no-progress", "--out", str(tmp_path / "out.npz"))
    assert status == 0, err
    lines = [line for line in err.splitlines() if line.strip()]
    assert lines == ["warning: impulses at t = 5 come after t_end = 1: they are not applied"]


def test_unforced_method_is_refused_naming_the_forced_methods(tmp_path, run_cli):
    status, _, err = run_cli("run", str(_files(tmp_path, method="rattle-6")), "--no-progress")
    line = one_error_line(status, err)
    assert "cannot integrate a system with forces or impulses" in line
    assert "forced-rattle-2, forced-rattle-4" in line
    assert "rattle-2, rattle-4, midpoint" in line


def test_ordinary_method_name_runs_a_forced_scene(tmp_path, run_cli):
    status, _, err = run_cli("run", str(_files(tmp_path, method="rattle-2")), "--no-progress",
                             "--out", str(tmp_path / "out.npz"))
    assert status == 0, err
