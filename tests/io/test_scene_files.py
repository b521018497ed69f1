"""Scene parsing and validation (docs/file_formats.md)."""

from __future__ import annotations

import numpy as np
import pytest

from dirac.errors import DiracWarning, InputError
from dirac.io.scene import load_scene, scene_from_dict

RIGID = {"system": {"name": "rigid_body", "inertia": [1.0, 2.0, 3.0]}, "initial": {"M": [0.6, 0.8, 0.5]},
         "run": {"t_end": 1.0}}


def _with(base: dict, **tables) -> dict:
    data = {k: dict(v) for k, v in base.items()}
    for key, value in tables.items():
        data[key] = {**data.get(key, {}), **value}
    return data


def test_contract_example_scene(tmp_path):
    path = tmp_path / "scene.toml"
    path.write_text(
        '[system]\nname = "rigid_body"\ninertia = [2.0, 1.0, 0.6666666666666666]\n'
        "[initial]\nM = [0.4535961214255773, 0.0, 0.8912073600614354]\nR = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]\n"
        '[run]\nt_end = 100.0\nmethod = "auto"\ndt = 0.01\ntolerance = 1e-8\nsamples = 101\n'
        'outputs = ["M", "R", "energy"]\n'
    )
    with pytest.warns(DiracWarning, match="triangle inequality"):
        scene = load_scene(path)
    assert scene.run == {"t_end": 100.0, "method": "auto", "dt": 0.01, "tolerance": 1e-8, "samples": 101,
                         "outputs": ["M", "R", "energy"]}
    assert np.allclose(scene.problem.M0[0], [0.4535961214255773, 0.0, 0.8912073600614354])


def test_angular_velocity_and_lab_momentum_are_accepted():
    omega = scene_from_dict(_with(RIGID) | {"initial": {"omega": [1.0, 1.0, 1.0]}})
    assert np.allclose(omega.problem.M0[0], [1.0, 2.0, 3.0])
    c, s = np.cos(0.3), np.sin(0.3)
    R = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
    lab = scene_from_dict(_with(RIGID) | {"initial": {"m": [1.0, 0.0, 0.0], "R": R}})
    assert np.allclose(np.array(R) @ lab.problem.M0[0], [1.0, 0.0, 0.0])


@pytest.mark.parametrize(
    "data, message",
    [
        (_with(RIGID, run={"sample": 5}),
         "s.toml: [run] has an unknown key 'sample' (did you mean 'samples'?); known keys: drift_limit, dt, "
         "max_newton_iterations, method, newton_tolerance, outputs, samples, t_end, tolerance"),
        (_with(RIGID, system={"inertai": [1.0, 2.0, 3.0]}),
         "s.toml: [system] has an unknown key 'inertai' (did you mean 'inertia'?); known keys: description, inertia, name"),
        (_with(RIGID, initial={"RR": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}),
         "s.toml: [initial] has an unknown key 'RR' (did you mean 'R'?); known keys: M, R, m, omega"),
        (_with(RIGID) | {"intial": {}},
         "s.toml: the scene has an unknown section 'intial' (did you mean 'initial'?); known sections: description, "
         "forces, impulses, initial, run, system"),
        (_with(RIGID, run={"colour": "red"}),  # nothing close: no suggestion
         "s.toml: [run] has an unknown key 'colour'; known keys: drift_limit, dt, max_newton_iterations, method, "
         "newton_tolerance, outputs, samples, t_end, tolerance"),
    ],
)
def test_unknown_keys_and_sections_are_errors_with_the_closest_known_names(data, message):
    with pytest.raises(InputError) as error:
        scene_from_dict(data, source="s.toml")
    assert str(error.value) == message


def test_unknown_methods_outputs_systems_and_parameters_suggest_the_closest_names():
    with pytest.raises(InputError, match=r"^s.toml: \[run\] method: unknown method 'rattle2' \(did you mean "
                                         r"'rattle-2'.*\?\); known methods: .*auto"):
        scene_from_dict(_with(RIGID, run={"method": "rattle2"}), source="s.toml")
    with pytest.raises(InputError, match=r"^s.toml: \[run\] outputs: unknown output 'enrgy' \(did you mean "
                                         r"'energy'\?\); known outputs: M, R, casimir, energy, lab_momentum"):
        scene_from_dict(_with(RIGID, run={"outputs": ["M", "enrgy"]}), source="s.toml")
    with pytest.raises(InputError, match=r"^s.toml: \[system\] name: unknown system 'pendulm' \(did you mean "
                                         r"'pendulum'.*\?\); known systems: .*heavy_top, pendulum, .*rigid_body,"):
        scene_from_dict({"system": {"name": "pendulm"}, "initial": {}, "run": {"t_end": 1.0}}, source="s.toml")
    with pytest.raises(InputError, match=r"^s.toml: \[system\] parameters of 'pendulum': unknown parameter 'll' "
                                         r"\(did you mean 'l'\?\); known parameters: g, l, m$"):
        scene_from_dict({"system": {"name": "pendulum", "parameters": {"ll": 2.0}}, "initial": {},
                         "run": {"t_end": 1.0}},
                        source="s.toml")


@pytest.mark.parametrize(
    "data, match",
    [
        ({"system": {"name": "rigid_body", "inertia": [1, 2, 3]}, "initial": {"M": [1, 0, 0]}, "run": {}}, "t_end"),
        ({"initial": {"M": [1, 0, 0]}, "run": {"t_end": 1.0}}, r"missing \[system\]"),
        (_with(RIGID) | {"initial": {"M": [1, 0, 0], "omega": [1, 0, 0]}}, "exactly one of M"),
        (_with(RIGID) | {"initial": {"M": [1, 0]}}, "shape"),
        (_with(RIGID, run={"samples": 0}), "samples"),
        (_with(RIGID, run={"method": 3}), "method must be a name"),
        (_with(RIGID) | {"system": {"name": "rigid_body"}}, "inertia"),
        ({"system": {"name": "no_such_system"}, "initial": {}, "run": {"t_end": 1.0}}, "unknown system"),
    ],
)
def test_bad_scenes_are_refused_with_the_key_named(data, match):
    with pytest.raises(InputError, match=match):
        scene_from_dict(data, source="s.toml")


PENDULUM = {"system": {"name": "pendulum"}, "run": {"t_end": 1.0, "method": "rattle-2", "dt": 0.01}}


def test_general_scene_with_q_dot_and_parameter_override():
    scene = scene_from_dict(PENDULUM | {"initial": {"q": {"x": 0.0, "y": -2.0}, "q_dot": {"x": 1.0}}}
                            | {"system": {"name": "pendulum", "parameters": {"l": 2.0, "m": 3.0}}})
    assert np.allclose(scene.problem.p0[0], [3.0, 0.0])  # p = m q_dot
    assert scene.problem.mechanics.parameter_values["l"] == 2.0


def test_initial_data_off_the_surface_is_rejected_or_projected():
    off = {"initial": {"q": {"x": 0.5, "y": -0.5}, "q_dot": {"x": 1.0, "y": 1.0}}}
    with pytest.raises(InputError, match="off the constraint surface.*project = true"):
        scene_from_dict(PENDULUM | off)
    scene = scene_from_dict(PENDULUM | {"initial": {**off["initial"], "project": True}})
    q, p = scene.problem.q0[0], scene.problem.p0[0]
    assert abs(q @ q - 1.0) < 1e-13  # on the circle
    assert abs(q @ p) < 1e-13  # velocity tangent
    assert np.allclose(q, [np.sqrt(0.5), -np.sqrt(0.5)])  # closest point
    tangent_off = {"initial": {"q": {"x": 0.0, "y": -1.0}, "q_dot": {"y": 1.0}}}
    with pytest.raises(InputError, match="not tangent"):
        scene_from_dict(PENDULUM | tangent_off)


def test_missing_coordinates_and_both_velocity_forms_are_refused():
    with pytest.raises(InputError, match="lacks y"):
        scene_from_dict(PENDULUM | {"initial": {"q": {"x": 1.0}}})
    with pytest.raises(InputError, match="both q_dot and p"):
        scene_from_dict(PENDULUM | {"initial": {"q": {"x": 1.0, "y": 0.0}, "q_dot": {}, "p": {}}})


def test_inline_system_and_heavy_top():
    inline = {"system": {"name": "spring", "coordinates": ["x"], "lagrangian": "x_dot**2/2 - k*x**2/2",
                         "parameters": {"k": 4.0}},
              "initial": {"q": [1.0]}, "run": {"t_end": 1.0}}
    scene = scene_from_dict(inline)
    assert scene.system == "spring" and scene.problem.mechanics.n_constraints == 0
    top = scene_from_dict({"system": {"name": "heavy_top", "inertia": [1, 1, 0.5], "mass_gravity": 2.0,
                                      "center_of_mass": [0, 0, 0.5]},
                           "initial": {"M": [0, 0, 1]}, "run": {"t_end": 1.0}})
    assert np.allclose(top.problem.weight_vector, [0, 0, 1.0])
