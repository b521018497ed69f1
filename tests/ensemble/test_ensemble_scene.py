"""Ensemble scene validation and member files."""

from __future__ import annotations

import numpy as np
import pytest
import zarr

from dirac.ensemble.chunk import compute_chunk
from dirac.ensemble.scene import load_ensemble_scene
from dirac.errors import DiracWarning, InputError

HEAD = """
[system]
name = "rigid_body"
[run]
method = "lie-poisson-2"
dt = 0.1
t_end = 1.0
samples = 3
[ensemble]
reductions = ["initial_state", "final_state"]
"""


def _members(n: int) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(0)
    return {"M": rng.normal(size=(n, 3)), "inertia": rng.uniform(1.0, 1.5, size=(n, 3))}


@pytest.mark.parametrize("kind", ["npz", "zarr"])
def test_member_file_supplies_the_initial_data(tmp_path, kind):
    data = _members(7)
    if kind == "npz":
        np.savez(tmp_path / "members.npz", **data)
        name = "members.npz"
    else:
        group = zarr.open_group(str(tmp_path / "members.zarr"), mode="w")
        for key, value in data.items():
            # shape and dtype, then a write: the form zarr 3.0 accepts (create_array(data=) is 3.1+)
            group.create_array(key, shape=value.shape, dtype=value.dtype)[...] = value
        name = "members.zarr"
    (tmp_path / "s.toml").write_text(HEAD + f'file = "{name}"\n')
    scene = load_ensemble_scene(tmp_path / "s.toml")
    assert scene.count == 7
    result = compute_chunk(scene, 2, 6)
    assert np.array_equal(result["initial_M"], data["M"][2:6])
    assert np.array_equal(result["inertia"], data["inertia"][2:6])
    assert np.array_equal(result["initial_R"], np.broadcast_to(np.eye(3), (4, 3, 3)))  # R not in the file


def test_member_file_errors(tmp_path):
    data = _members(5)
    np.savez(tmp_path / "m.npz", **data)
    (tmp_path / "count.toml").write_text(HEAD + 'file = "m.npz"\ncount = 6\n')
    with pytest.raises(InputError, match="count = 6 but file"):
        load_ensemble_scene(tmp_path / "count.toml")
    np.savez(tmp_path / "bad.npz", M=data["M"], R=np.ones((5, 3, 3)))
    (tmp_path / "bad.toml").write_text(HEAD + 'file = "bad.npz"\n[ensemble.inertia]\nvalue = [1, 1, 1]\n')
    with pytest.raises(InputError, match="not a proper rotation"):
        load_ensemble_scene(tmp_path / "bad.toml")
    (tmp_path / "none.toml").write_text(HEAD + 'file = "nothing.npz"\n')
    with pytest.raises(InputError, match="does not exist"):
        load_ensemble_scene(tmp_path / "none.toml")


def test_scene_errors_and_warnings(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(HEAD + "count = 3\n")
    with pytest.raises(InputError, match=r"give \[initial\] M or an \[ensemble.M\] table"):
        load_ensemble_scene(path)
    path.write_text(HEAD.replace('name = "rigid_body"', 'name = "pendulum"') + "count = 3\n")
    # any system is accepted now; this scene of a pendulum lacks its initial state
    with pytest.raises(InputError, match=r"needs a \[initial\] table"):
        load_ensemble_scene(path)
    path.write_text(HEAD.replace("samples = 3", "samples = 1") + "count = 3\n[ensemble.M]\nvalue = [0, 1, 0]\n"
                    "[ensemble.inertia]\nvalue = [1, 2, 3]\n")
    with pytest.raises(InputError, match="samples = 1 must be an integer >= 2"):
        load_ensemble_scene(path)
    path.write_text(
        HEAD + "count = 3\n[ensemble.M]\ndistribution = \"sphere\"\nnorm = 1.0\n"
        "[ensemble.inertia]\ndistribution = \"uniform\"\nlow = [1, 1, 1]\nhigh = [3, 3, 3]\n"
    )
    with pytest.warns(DiracWarning, match="triangle inequality"):
        scene = load_ensemble_scene(path)
    assert scene.with_R and scene.steps == 10


def test_ensemble_scenes_read_their_sections_numbers_and_vectors_like_single_run_scenes(tmp_path):
    """The shared reader of dirac.io.scene: the same messages for the same mistakes."""
    path = tmp_path / "s.toml"
    members = 'count = 3\n[ensemble.M]\ndistribution = "sphere"\nnorm = 1.0\n[ensemble.inertia]\nvalue = [1, 1, 1]\n'
    cases = [
        (HEAD.replace('name = "rigid_body"', 'name = "rigid_body"\ninertia = [1, true, 2]') + members,
         r"\[system\] inertia = \[1, True, 2\] contains true/false"),
        (HEAD.replace('name = "rigid_body"', 'name = "rigid_body"\ninertia = [1, 2]') + members,
         r"\[system\] inertia has shape \(2,\)"),
        (HEAD.replace("dt = 0.1", "dt = 0") + members, r"\[run\] dt = 0 must be a finite number > 0"),
        (HEAD.replace("samples = 3", "samples = 2.5") + members, r"\[run\] samples = 2.5 must be an integer >= 2"),
        ("[ensemble]\ncount = 3\n[run]\ndt = 0.1\nt_end = 1.0\n", r"missing \[system\] table .*docs/ensembles.md"),
        (HEAD.replace("[run]", "[initial]\nM = [0, 1]\n[run]") + members, r"\[initial\] M has shape \(2,\)"),
    ]
    for text, match in cases:
        path.write_text(text)
        with pytest.raises(InputError, match=match):
            load_ensemble_scene(path)


def test_fingerprint_ignores_the_chunk_size_and_sees_the_physics(tmp_path):
    base = HEAD + 'count = 3\n[ensemble.M]\ndistribution = "sphere"\nnorm = 1.0\n[ensemble.inertia]\nvalue = [1, 2, 3]\n'
    (tmp_path / "a.toml").write_text(base)
    (tmp_path / "b.toml").write_text(base.replace("count = 3", "count = 3\nchunk_size = 2"))
    (tmp_path / "c.toml").write_text(base.replace("norm = 1.0", "norm = 2.0"))
    a, b, c = (load_ensemble_scene(tmp_path / f"{x}.toml").fingerprint() for x in "abc")
    assert a == b and a != c
