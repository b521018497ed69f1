"""Result files (docs/file_formats.md): exactly ``t``, the requested outputs and ``meta``; written
atomically, so a failed write never leaves a partial file nor destroys an existing one."""

from __future__ import annotations

import json

import numpy as np
import pytest

from dirac.flows import RigidBodyProblem, integrate
from dirac.io.results import read_results, write_results


def _solution(outputs=("M", "energy")):
    return integrate(RigidBodyProblem([1.0, 2.0, 3.0], [0.6, 0.8, 0.5]), "lie-poisson-4", t_end=1.0, dt=0.01,
                     samples=5, outputs=list(outputs))


def test_file_holds_exactly_t_the_outputs_and_meta(tmp_path):
    path = write_results(_solution(), tmp_path / "run.npz", extra_meta={"scene": "x.toml"})
    with np.load(path) as data:
        assert sorted(data.files) == ["M", "energy", "meta", "t"]
        assert data["M"].shape == (5, 3) and data["t"].shape == (5,)
        meta = json.loads(str(data["meta"]))
    for key in ("system", "parameters", "method", "order", "dt", "steps", "cpu_seconds", "complete", "versions"):
        assert key in meta
    assert meta["system"] == "rigid_body" and meta["method"] == "lie-poisson-4" and meta["order"] == 4
    assert meta["complete"] is True and meta["scene"] == "x.toml"
    assert meta["parameters"] == {"inertia": [1.0, 2.0, 3.0]}
    arrays, meta2 = read_results(path)
    assert meta2 == meta and set(arrays) == {"t", "M", "energy"}


def test_failed_write_leaves_the_existing_file_untouched_and_no_debris(tmp_path, monkeypatch):
    path = tmp_path / "run.npz"
    write_results(_solution(("M",)), path)
    before = path.read_bytes()

    def broken_savez(stream, **arrays):
        stream.write(b"PK\x03\x04 half a file")
        raise OSError("disk full")

    monkeypatch.setattr(np, "savez", broken_savez)
    with pytest.raises(OSError, match="disk full"):
        write_results(_solution(("M", "energy")), path)
    assert path.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.npz"]


def test_interrupted_write_leaves_no_debris(tmp_path, monkeypatch):
    def interrupted(stream, **arrays):
        raise KeyboardInterrupt

    monkeypatch.setattr(np, "savez", interrupted)
    with pytest.raises(KeyboardInterrupt):
        write_results(_solution(), tmp_path / "run.npz")
    assert list(tmp_path.iterdir()) == []
