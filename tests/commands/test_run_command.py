"""``dirac run SCENE.toml [--out FILE.npz] [--no-progress]`` (docs/cli.md, docs/file_formats.md)."""

from __future__ import annotations

import json
import os
import signal
import threading
import tomllib
from pathlib import Path

import numpy as np
import pytest

#: The example scenes of the flows (docs/scenes also holds other commands' scenes).
SCENE_NAMES = ("double_pendulum", "heavy_top", "heavy_top_asymmetric", "pendulum", "rigid_body",
               "rigid_body_splitting", "spherical_pendulum")
SCENES = [Path(__file__).resolve().parents[2] / "docs" / "scenes" / f"{name}.toml" for name in SCENE_NAMES]


def _meta(path: Path) -> dict:
    with np.load(path) as data:
        return json.loads(str(data["meta"]))


@pytest.mark.parametrize("scene", SCENES, ids=[s.stem for s in SCENES])
def test_every_example_scene_runs_and_stores_exactly_its_outputs(scene, tmp_path, run_cli):
    out = tmp_path / f"{scene.stem}.npz"
    status, stdout, stderr = run_cli("run", str(scene), "--out", str(out), "--no-progress")
    assert status == 0, stderr
    assert f"written to {out}" in stdout
    run = tomllib.loads(scene.read_text())["run"]
    with np.load(out) as data:
        assert sorted(data.files) == sorted(["t", "meta", *run["outputs"]])
        assert data["t"].shape == (run["samples"],)
        assert data["t"][0] == 0.0 and data["t"][-1] == run["t_end"]
    meta = _meta(out)
    assert meta["complete"] is True
    assert meta["method"] == run["method"] or run["method"] == "auto"
    for key in ("system", "parameters", "method", "order", "dt", "steps", "cpu_seconds", "complete", "versions"):
        assert key in meta


def _write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


FAILING = """
[system]
name = "pendulum"
[initial]
q = { x = 0.9092974268256817, y = 0.4161468365471424 }
[run]
t_end = 5.0
method = "rattle-2"
dt = 0.3
samples = 6
outputs = ["q"]
max_newton_iterations = 2
"""


def test_failed_run_leaves_an_existing_output_untouched_and_saves_a_partial_file(tmp_path, run_cli):
    scene = _write(tmp_path / "fail.toml", FAILING)
    out = tmp_path / "result.npz"
    out.write_bytes(b"previous results")
    status, _stdout, stderr = run_cli("run", str(scene), "--out", str(out), "--no-progress")
    assert status == 2
    lines = stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: rattle-2: Newton iteration did not converge")
    assert "with method rattle-2" in lines[0] and "at t = " in lines[0] and "(step " in lines[0]
    assert out.read_bytes() == b"previous results"
    partial = tmp_path / "result.partial.npz"
    assert str(partial) in lines[0]
    assert _meta(partial)["complete"] is False


def test_failed_run_without_previous_output_keeps_the_partial_results_there(tmp_path, run_cli):
    scene = _write(tmp_path / "fail.toml", FAILING)
    out = tmp_path / "result.npz"
    status, _stdout, stderr = run_cli("run", str(scene), "--out", str(out), "--no-progress")
    assert status == 2 and "meta complete = false" in stderr
    meta = _meta(out)
    assert meta["complete"] is False and "Newton" in meta["message"]
    with np.load(out) as data:
        assert data["t"][0] == 0.0 and data["q"].shape == (len(data["t"]), 2)


def test_bad_scene_exits_2_with_one_error_line_and_writes_nothing(tmp_path, run_cli):
    scene = _write(tmp_path / "bad.toml", '[system]\nname = "rigid_body"\ninertia = [1, 2, 3]\n[initial]\nM = [1, 0]\n[run]\nt_end = 1.0\n')
    status, stdout, stderr = run_cli("run", str(scene), "--no-progress")
    assert status == 2 and stdout == ""
    assert stderr.count("\n") == 1 and stderr.startswith("error: ") and "[initial] M" in stderr
    assert not (tmp_path / "bad.npz").exists()


def test_an_unknown_key_is_an_error_that_suggests_the_known_key_and_runs_nothing(tmp_path, run_cli):
    """Guards against a typo running silently with a default (``sample = 5`` used to run 101 samples)."""
    from cli_output import one_error_line

    scene = _write(tmp_path / "s.toml", '[system]\nname = "rigid_body"\ninertia = [1, 2, 3]\n[initial]\n'
                   'M = [1, 0, 0]\n[run]\nt_end = 1.0\nmethod = "exact"\nsample = 3\n')
    status, stdout, stderr = run_cli("run", str(scene), "--no-progress")
    line = one_error_line(status, stderr)
    assert line.startswith(f"error: {scene}: [run] has an unknown key 'sample' (did you mean 'samples'?); known keys: ")
    assert stdout == "" and not (tmp_path / "s.npz").exists()


def test_help_lists_every_method(run_cli):
    from dirac.flows.methods.registry import method_names

    status, stdout, _ = run_cli("run", "--help")
    assert status == 0
    listed = stdout.split("methods ([run] method = NAME):")[1]
    names = set()
    for line in listed.splitlines():
        if not line.strip():
            continue
        head = line.split()[0]
        stem, _, variants = head.rpartition("-")
        names |= {f"{stem}-{v}" for v in variants.split("/")} if "/" in variants else {head}
    assert set(method_names()) <= names | {"auto"}


def test_sigterm_saves_what_was_computed_marked_incomplete(tmp_path, run_cli):
    scene = _write(tmp_path / "long.toml", '[system]\nname = "rigid_body"\ninertia = [1, 2, 3]\n[initial]\n'
                   'M = [0.6, 0.8, 0.5]\n[run]\nt_end = 1e6\nmethod = "lie-poisson-2"\ndt = 1e-3\nsamples = 1001\n'
                   'outputs = ["M"]\n')
    out = tmp_path / "long.npz"
    timer = threading.Timer(2.0, os.kill, args=(os.getpid(), signal.SIGTERM))
    timer.start()
    try:
        status, _stdout, stderr = run_cli("run", str(scene), "--out", str(out), "--no-progress")
    finally:
        timer.cancel()
    assert status == 130
    assert "interrupted at t = " in stderr
    meta = _meta(out)
    assert meta["complete"] is False
    with np.load(out) as data:
        assert 1 <= len(data["t"]) < 1001 and data["M"].shape == (len(data["t"]), 3)
