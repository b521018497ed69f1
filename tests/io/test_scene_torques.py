"""Scenes with ``[forces] torque`` and ``[[impulses]] angular_impulse`` (docs/file_formats.md)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from dirac.errors import DiracWarning, InputError
from dirac.io.scene import scene_from_dict

ROOT = Path(__file__).resolve().parents[2]
BODY = {"system": {"name": "rigid_body", "inertia": [3.0, 2.0, 1.0]}, "initial": {"M": [0.2, 3.0, 0.4]},
        "run": {"t_end": 2.0, "method": "exact-kick-4", "dt": 0.1}}


def _scene(**tables):
    return scene_from_dict({**BODY, **tables})


def test_a_torque_and_impulses_are_read():
    scene = _scene(forces={"torque": ["-0.2*M_1", "0.1*R_31", "sin(t)"]},
                   impulses=[{"t": 1.5, "angular_impulse": [0, 0, 1]}, {"t": 0.5, "angular_impulse": [1, 0, 0]}])
    problem = scene.problem
    assert problem.torque.texts == ("-0.2*M_1", "0.1*R_31", "sin(t)")
    assert problem.torque.depends_on_momentum and problem.torque.depends_on_attitude and problem.torque.depends_on_time
    assert [i.t for i in problem.impulses] == [0.5, 1.5]  # sorted by time
    assert np.array_equal(problem.impulses[0].vector, [1.0, 0.0, 0.0])
    assert problem.parameters()["torque"] == ["-0.2*M_1", "0.1*R_31", "sin(t)"]


def test_a_heavy_top_takes_a_torque():
    data = {**BODY, "system": {"name": "heavy_top", "inertia": [3.0, 3.0, 1.0], "mass_gravity": 1.0},
            "forces": {"torque": ["0", "0", "-0.1*Omega_3"]}}
    assert scene_from_dict(data).problem.torque.kick == "midpoint"


@pytest.mark.parametrize("tables, match", [
    ({"forces": {"torque": ["0", "0"]}}, "three expressions"),
    ({"forces": {"torque": "0"}}, "list of three expressions"),
    ({"forces": {"torqe": ["0", "0", "0"]}}, "did you mean 'torque'"),
    ({"forces": {"torque": ["0", "0", "Omega3"]}}, "did you mean 'Omega_3'"),
    ({"impulses": [{"t": -1.0, "angular_impulse": [0, 0, 1]}]}, "before the start"),
    ({"impulses": [{"t": 1.0, "angular_impulse": [0, 1]}]}, "angular_impulse"),
    ({"impulses": [{"t": 1.0}]}, "lacks angular_impulse"),
    ({"impulses": [{"t": 1.0, "Q": {"x": 1.0}}]}, "unknown key 'Q'"),
])
def test_bad_torques_and_impulses_are_refused(tables, match):
    with pytest.raises(InputError, match=match):
        _scene(**tables)


def test_an_impulse_after_t_end_warns():
    with pytest.warns(DiracWarning, match="after \\[run\\] t_end = 2: it never acts"):
        _scene(impulses=[{"t": 3.0, "angular_impulse": [0, 0, 1]}])


def test_a_torque_in_a_lagrangian_scene_is_refused():
    data = {"system": {"name": "pendulum"}, "initial": {"q": {"x": 1.0, "y": 0.0}}, "run": {"t_end": 1.0},
            "forces": {"torque": ["0", "0", "1"]}}
    with pytest.raises(InputError, match="applies to rigid_body and heavy_top scenes"):
        scene_from_dict(data)


@pytest.mark.parametrize("edit, message", [
    (('"-0.2*M_3"]', '"-0.2*M_3", "0"]'), "must be three expressions"),
    (("-0.2*M_3", "-0.2*Omega3"), "unknown name 'Omega3' (did you mean 'Omega_3'"),
    (("t = 5.0", "t = -1.0"), "before the start of the run"),
    (('method = "exact-kick-6"', 'method = "exact"'), "method 'exact' cannot integrate an external torque; use one of: auto,"),
])
def test_the_command_line_exits_2_with_one_error_line(run_cli, tmp_path, edit, message):
    text = (ROOT / "docs" / "scenes" / "satellite_despin.toml").read_text(encoding="utf-8")
    assert edit[0] in text
    scene = tmp_path / "bad.toml"
    scene.write_text(text.replace(edit[0], edit[1], 1), encoding="utf-8")
    status, out, err = run_cli("run", str(scene), "--out", str(tmp_path / "bad.npz"), "--no-progress")
    lines = [line for line in err.splitlines() if line.strip()]
    assert status == 2
    assert len(lines) == 1 and lines[0].startswith("error:") and message in lines[0], err
