"""The reading helpers every scene reader shares (:mod:`dirac.io.scene`): the file, its
tables, numbers, vectors and unknown-key errors; single-run and ensemble scenes read
a file the same way."""

from __future__ import annotations

import numpy as np
import pytest

from dirac.errors import InputError
from dirac.io.scene import (
    load_scene,
    read_scene_file,
    reject_unknown_keys,
    scene_inertia,
    scene_integer,
    scene_number,
    scene_table,
    scene_vector,
)


def test_read_scene_file_names_the_file_and_what_is_wrong(tmp_path):
    good = tmp_path / "good.toml"
    good.write_text('[run]\nt_end = 1.0\n', encoding="utf-8")
    assert read_scene_file(good) == {"run": {"t_end": 1.0}}
    with pytest.raises(InputError, match=r"cannot read scene file '.*missing.toml': it does not exist; check the path"):
        read_scene_file(tmp_path / "missing.toml")
    with pytest.raises(InputError, match="cannot read scene file"):
        read_scene_file(tmp_path)  # a directory
    broken = tmp_path / "broken.toml"
    broken.write_text("[run\n", encoding="utf-8")
    with pytest.raises(InputError, match=r"scene file '.*broken.toml' is not valid TOML"):
        read_scene_file(broken)
    latin = tmp_path / "latin.toml"
    latin.write_bytes(b'[system]\nname = "\xe9"\n')
    with pytest.raises(InputError, match="is not valid TOML"):
        read_scene_file(latin)


@pytest.mark.parametrize("reader", ["single", "ensemble"])
def test_both_scene_readers_refuse_a_missing_file_alike(tmp_path, reader):
    from dirac.ensemble.scene import load_ensemble_scene

    load = load_scene if reader == "single" else load_ensemble_scene
    with pytest.raises(InputError, match="cannot read scene file .*: it does not exist; check the path"):
        load(tmp_path / "missing.toml")


def test_scene_table_is_a_table_or_missing_with_a_hint():
    data = {"run": {"t_end": 1.0}, "initial": 3}
    assert scene_table(data, "run", "s.toml") == {"t_end": 1.0}
    assert scene_table(data, "system", "s.toml", required=False) == {}
    with pytest.raises(InputError, match=r"^s.toml: missing \[system\] table \(a scene needs \[system\], \[initial\] "
                                         r"and \[run\]; see docs/file_formats.md\)$"):
        scene_table(data, "system", "s.toml")
    with pytest.raises(InputError, match=r"^missing \[ensemble\] table \(see docs/ensembles.md\)$"):
        scene_table(data, "ensemble", hint="see docs/ensembles.md")
    with pytest.raises(InputError, match=r"^s.toml: \[initial\] must be a table$"):
        scene_table(data, "initial", "s.toml")


def test_unknown_keys_are_errors_naming_the_file_each_key_and_the_closest_known_keys():
    with pytest.raises(InputError) as error:
        reject_unknown_keys({"t_end": 1.0, "speed": 3, "sample": 5}, {"t_end", "samples", "dt"}, "[run]", "s.toml")
    assert str(error.value) == (
        "s.toml: [run] has unknown keys 'sample' (did you mean 'samples'?), 'speed'; known keys: dt, samples, t_end"
    )
    with pytest.raises(InputError) as error:
        reject_unknown_keys({"runn": {}}, {"run", "system", "initial"}, "the scene", "s.toml", kind="section")
    assert str(error.value) == (
        "s.toml: the scene has an unknown section 'runn' (did you mean 'run'?); known sections: initial, run, system"
    )
    with pytest.raises(InputError, match=r"^\[ensemble\] has an unknown key 'colour'; known keys: count$"):
        reject_unknown_keys({"count": 3, "colour": 2}, {"count"}, "[ensemble]")  # no close match: no suggestion
    reject_unknown_keys({"t_end": 1.0}, {"t_end", "dt"}, "[run]", "s.toml")  # nothing unknown: nothing raised


def test_numbers_vectors_and_inertia_are_named_with_the_scene_and_key():
    assert scene_number(2, "[run] dt", "s.toml", positive=True) == 2.0
    assert scene_number(-1.5, "[system] mass_gravity", "s.toml") == -1.5
    with pytest.raises(InputError, match=r"^s.toml: \[run\] dt = 0 must be a finite number > 0$"):
        scene_number(0, "[run] dt", "s.toml", positive=True)
    with pytest.raises(InputError, match=r"^\[run\] t_end = True must be a finite number$"):
        scene_number(True, "[run] t_end")
    assert scene_integer(3, "[run] samples", "s.toml") == 3
    with pytest.raises(InputError, match=r"^s.toml: \[run\] samples = 1 must be an integer >= 2$"):
        scene_integer(1, "[run] samples", "s.toml", minimum=2)
    assert np.array_equal(scene_vector([1, 0, 0], "[initial] M", "s.toml", (3,)), [1.0, 0.0, 0.0])
    with pytest.raises(InputError, match=r"^s.toml: \[initial\] M = \[False, 0.2, 0.1\] contains true/false"):
        scene_vector([False, 0.2, 0.1], "[initial] M", "s.toml", (3,))
    assert np.array_equal(scene_inertia({"inertia": [1, 2, 2]}, "s.toml"), [1.0, 2.0, 2.0])
    with pytest.raises(InputError, match=r"^s.toml: \[system\] lacks 'inertia'"):
        scene_inertia({"name": "rigid_body"}, "s.toml")
    with pytest.raises(InputError, match=r"^\[system\] inertia has shape \(2,\)"):
        scene_inertia({"inertia": [1.0, 2.0]})
