"""Unknown names on the command line and in scenes: one ``error:`` line, exit status 2,
"did you mean" with the closest known names (none when nothing is close), the file named
where there is one, and the known names sorted."""

from __future__ import annotations

from pathlib import Path

import pytest
from cli_output import one_error_line

RIGID = '[system]\nname = "rigid_body"\ninertia = [1, 2, 3]\n[initial]\nM = [1, 0.1, 0.1]\n[run]\nt_end = 1.0\n'


def _scene(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "s.toml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize(
    "text, expected",
    [
        (RIGID + "sample = 5\n", "[run] has an unknown key 'sample' (did you mean 'samples'?); known keys: drift_limit, dt, "),
        (RIGID.replace("[initial]", "[intial]"),
         "the scene has an unknown section 'intial' (did you mean 'initial'?); known sections: description, forces, impulses, initial, run, system"),
        (RIGID + 'method = "rattle2"\n', "[run] method: unknown method 'rattle2' (did you mean 'rattle-2'"),
        (RIGID + 'outputs = ["M", "enrgy"]\n',
         "[run] outputs: unknown output 'enrgy' (did you mean 'energy'?); known outputs: M, R, casimir, energy, lab_momentum"),
        (RIGID.replace('"rigid_body"', '"rigid_bdy"'), "[system] name: unknown system 'rigid_bdy' (did you mean 'rigid_body'"),
        ('[system]\nname = "pendulum"\nparameters = { ll = 2.0 }\n[initial]\nq = { x = 1.0, y = 0.0 }\n[run]\nt_end = 1.0\n',
         "[system] parameters of 'pendulum': unknown parameter 'll' (did you mean 'l'?); known parameters: g, l, m"),
    ],
)
def test_scene_typos_name_the_file_and_suggest_the_known_name(tmp_path, run_cli, text, expected):
    scene = _scene(tmp_path, text)
    status, stdout, stderr = run_cli("run", str(scene), "--no-progress")
    line = one_error_line(status, stderr)
    assert line.startswith(f"error: {scene}: {expected}"), line
    assert stdout == "" and not (tmp_path / "s.npz").exists()


def test_a_name_with_nothing_close_gets_no_suggestion(tmp_path, run_cli):
    scene = _scene(tmp_path, RIGID + 'method = "zzz"\n')
    line = one_error_line(*run_cli("run", str(scene), "--no-progress")[::2])
    assert line.startswith(f"error: {scene}: [run] method: unknown method 'zzz'; known methods: ")
    assert "did you mean" not in line


def test_method_lists_in_errors_are_sorted(tmp_path, run_cli):
    scene = _scene(tmp_path, RIGID + 'method = "zzz"\n')
    line = one_error_line(*run_cli("run", str(scene), "--no-progress")[::2])
    listed = line.split("known methods: ")[1].split(", ")
    assert listed == sorted(listed) and "auto" in listed


@pytest.mark.parametrize(
    "argv, expected",
    [
        (("analyze", "pendulm"),
         "error: unknown system 'pendulm' (did you mean 'pendulum' or 'double_pendulum'?); known systems: double_pendulum, "),
        (("analyze", "pendulum", "--param", "ll=2"),
         "error: system 'pendulum': unknown parameter 'll' (did you mean 'l'?); known parameters: g, l, m"),
        (("demo", "--method", "lie-poison-4"), "error: --method: unknown method 'lie-poison-4' (did you mean 'lie-poisson-4'"),
        (("analyze", "pendulum", "--param", "L=2"),
         "error: system 'pendulum': unknown parameter 'L' (did you mean 'l'?); known parameters: g, l, m"),
    ],
)
def test_command_line_typos_suggest_the_known_name(run_cli, argv, expected):
    status, _stdout, stderr = run_cli(*argv)
    assert one_error_line(status, stderr).startswith(expected)


SYSTEM = """[system]
name = "pendulum"
coordinates = ["x", "y"]
parameters = {{ m = 1.0, g = 9.81{extra} }}
lagrangian = "{lagrangian}"
constraints = ["{constraint}"]
"""


def _system(tmp_path: Path, lagrangian: str = "m/2*(x_dot**2 + y_dot**2) - m*g*y",
            constraint: str = "x**2 + y**2 - l**2", extra: str = ", l = 1.0") -> Path:
    path = tmp_path / "system.toml"
    path.write_text(SYSTEM.format(lagrangian=lagrangian, constraint=constraint, extra=extra), encoding="utf-8")
    return path


def test_a_typo_inside_an_expression_gets_did_you_mean(tmp_path, run_cli):
    system = _system(tmp_path, lagrangian="m/2*(x_dot**2 + yy_dot**2) - m*g*y")
    line = one_error_line(*run_cli("analyze", str(system))[::2])
    assert "unknown name 'yy_dot' (did you mean 'y_dot'" in line
    assert "add it to parameters" not in line  # a typo, not a missing parameter


def test_a_parameter_missing_from_parameters_is_named_with_the_fix(tmp_path, run_cli):
    system = _system(tmp_path, extra="")
    line = one_error_line(*run_cli("analyze", str(system))[::2])
    assert "unknown name 'l'; if it is a parameter, add it to parameters" in line


def test_a_constraint_lists_only_the_names_allowed_in_it(tmp_path, run_cli):
    line = one_error_line(*run_cli("analyze", str(_system(tmp_path, constraint="x**2 + y**2 - ll**2")))[::2])
    assert "unknown name 'll' (did you mean 'l'?); the names allowed here are: g, l, m, x, y" in line
    assert "x_dot" not in line.split("allowed here are:")[1]  # constraints refuse velocities: not offered
    line = one_error_line(*run_cli("analyze", str(_system(tmp_path, constraint="x**2 + y**2 - l**2 + x_dot")))[::2])
    assert "'x_dot' is not allowed here: it is a velocity, and only holonomic constraints chi(q, t) = 0" in line
