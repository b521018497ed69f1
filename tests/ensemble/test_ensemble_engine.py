"""The engine: chunkings, local vs dask, retries, resuming, meta."""

from __future__ import annotations

import json

import numpy as np
import pytest
import zarr

import dirac.ensemble.dask_executor as dask_executor
import dirac.ensemble.local_executor as local_executor
from dirac.ensemble.engine import run_ensemble
from dirac.errors import InputError


def _arrays(out) -> dict[str, np.ndarray]:
    group = zarr.open_group(str(out / "data.zarr"), mode="r")
    return {name: group[name][:] for name in group.array_keys()}


def _assert_identical(a: dict, b: dict) -> None:
    assert sorted(a) == sorted(b)
    for name in a:
        assert a[name].tobytes() == b[name].tobytes(), name  # bit-identical, NaN included


def test_two_chunkings_give_bit_identical_results(write_scene, tmp_path):
    scene = write_scene(count=150)
    first = run_ensemble(scene, tmp_path / "a", chunk_size=150)
    second = run_ensemble(scene, tmp_path / "b", chunk_size=31)
    assert (first.chunks_total, second.chunks_total) == (1, 5)
    assert first.complete and second.complete
    a, b = _arrays(tmp_path / "a"), _arrays(tmp_path / "b")
    _assert_identical(a, b)
    assert not np.isnan(a["final_M"]).any() and a["M"].shape == (150, 21, 3)
    meta = json.loads((tmp_path / "b" / "meta.json").read_text())
    assert meta["complete"] and meta["chunks_complete"] == 5 and meta["chunks_done"] == [[0, 4]]
    assert meta["count"] == 150 and meta["method"] == "lie-poisson-4" and meta["steps"] == 200


def test_dask_local_cluster_gives_the_local_results(write_scene, tmp_path, dask_client):
    scene = write_scene(count=120)
    local = run_ensemble(scene, tmp_path / "local", chunk_size=25)
    remote = run_ensemble(scene, tmp_path / "dask", chunk_size=40, client=dask_client)
    assert local.complete and remote.complete and remote.chunks_computed == 3
    _assert_identical(_arrays(tmp_path / "local"), _arrays(tmp_path / "dask"))
    meta = json.loads((tmp_path / "dask" / "meta.json").read_text())
    assert meta["runs"][-1]["executor"] == "dask"
    markers = [json.loads(p.read_text()) for p in sorted((tmp_path / "dask" / "chunks").glob("*.json"))]
    assert {m["worker"] for m in markers} <= set(dask_client.scheduler_info(n_workers=-1)["workers"])


def test_failed_chunk_is_retried_reported_and_recomputed_on_resume(write_scene, tmp_path, monkeypatch):
    scene = write_scene(count=100)
    run_ensemble(scene, tmp_path / "ref", chunk_size=20)
    calls: dict[int, int] = {}
    real = local_executor.compute_chunk

    def flaky(scene_, start, stop, members=None):
        calls[start] = calls.get(start, 0) + 1
        if start == 20 and calls[start] == 1:
            raise RuntimeError("transient")  # fails once: the retry succeeds
        if start == 60:
            raise RuntimeError("always broken")
        return real(scene_, start, stop, members)

    monkeypatch.setattr(local_executor, "compute_chunk", flaky)
    out = tmp_path / "run"
    report = run_ensemble(scene, out, chunk_size=20, retries=2)
    assert calls[20] == 2 and calls[60] == 3
    assert set(report.failed) == {3} and "always broken" in report.failed[3]
    assert not report.complete and report.chunks_computed == 4
    meta = json.loads((out / "meta.json").read_text())
    assert meta["complete"] is False and list(meta["failed_chunks"]) == ["3"]
    assert meta["chunks_done"] == [[0, 2], [4, 4]]
    markers = {p.name: p.read_text() for p in (out / "chunks").glob("*.json")}

    monkeypatch.setattr(local_executor, "compute_chunk", real)
    again = run_ensemble(scene, out)
    assert again.complete and again.chunks_computed == 1 and again.chunks_skipped == 4
    for name, text in markers.items():  # finished chunks were not recomputed
        assert (out / "chunks" / name).read_text() == text
    meta = json.loads((out / "meta.json").read_text())
    assert meta["complete"] and meta["failed_chunks"] == {}
    assert [run["chunks_computed"] for run in meta["runs"]] == [4, 1]
    _assert_identical(_arrays(tmp_path / "ref"), _arrays(out))


def test_resuming_a_different_scene_or_chunk_size_is_refused(write_scene, tmp_path):
    out = tmp_path / "out"
    run_ensemble(write_scene(count=30), out, chunk_size=10)
    with pytest.raises(InputError, match="different scene") as refused:
        run_ensemble(write_scene("other.toml", count=30, seed=12), out)
    assert str(refused.value).startswith(f"out={str(out)!r} ")  # the keyword argument, not the CLI flag
    with pytest.raises(InputError, match="chunk_size=10"):
        run_ensemble(write_scene(count=30), out, chunk_size=15)
    # a chunk size above the count was stored as the count: resuming with it is fine
    assert run_ensemble(write_scene(count=30), tmp_path / "big", chunk_size=100).chunk_size == 30
    assert run_ensemble(write_scene(count=30), tmp_path / "big", chunk_size=100).chunks_skipped == 1
    (tmp_path / "busy").mkdir()
    (tmp_path / "busy" / "notes.txt").write_text("mine")
    with pytest.raises(InputError, match="not empty"):
        run_ensemble(write_scene(count=30), tmp_path / "busy")


def test_reductions_only_store_no_trajectories(write_scene, tmp_path):
    scene = write_scene(count=40, outputs="[]", reductions='["flip_time", "max_energy_error"]')
    report = run_ensemble(scene, tmp_path / "out")
    assert report.complete
    arrays = _arrays(tmp_path / "out")
    assert sorted(arrays) == ["flip_time", "max_energy_error", "t"]
    assert arrays["max_energy_error"].shape == (40,) and np.all(arrays["max_energy_error"] < 1e-6)


def test_dask_failed_chunk_is_retried_then_reported(write_scene, tmp_path, dask_client, monkeypatch):
    # the cluster's workers are threads of this process, so they see the patched function
    scene = write_scene(count=60, outputs="[]", reductions='["final_state"]')
    calls: dict[int, int] = {}
    real = dask_executor.compute_chunk

    def broken(scene_, start, stop, members=None):
        calls[start] = calls.get(start, 0) + 1
        if start == 20:
            raise RuntimeError("broken chunk")
        return real(scene_, start, stop, members)

    monkeypatch.setattr(dask_executor, "compute_chunk", broken)
    report = run_ensemble(scene, tmp_path / "out", chunk_size=20, client=dask_client, retries=1)
    assert calls[20] == 2 and calls[0] == 1 and calls[40] == 1
    assert list(report.failed) == [1] and "broken chunk" in report.failed[1] and not report.complete
    meta = json.loads((tmp_path / "out" / "meta.json").read_text())
    assert meta["failed_chunks"].keys() == {"1"} and meta["chunks_done"] == [[0, 0], [2, 2]]
