"""Kill a running 'dirac ensemble' midway, rerun the same command: identical results,
finished chunks not recomputed (their markers untouched, meta counts the work)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import zarr

from dirac.ensemble.engine import run_ensemble

CHUNKS = 20


def _command(scene, out) -> list[str]:
    return [sys.executable, "-m", "dirac", "ensemble", str(scene), "--out", str(out), "--no-progress"]


def test_killed_run_resumes_with_identical_results(write_scene, tmp_path):
    # 20 chunks of 50 members x 2000 steps: each chunk takes a visible fraction of a second
    scene = write_scene(
        count=50 * CHUNKS, t_end=4.0, dt=0.002, samples=11, outputs='["energy"]',
        reductions='["flip_time", "final_state"]', extra="chunk_size = 50",
    )
    out = tmp_path / "killed"
    process = subprocess.Popen(_command(scene, out), stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 120
    try:
        while len(list((out / "chunks").glob("chunk-*.json"))) < 2:
            assert process.poll() is None, process.communicate()
            assert time.monotonic() < deadline, "fewer than two chunks finished within 120 s"
            time.sleep(0.005)
    finally:
        os.kill(process.pid, signal.SIGKILL)
        process.wait()
    before = {p.name: p.read_text() for p in (out / "chunks").glob("chunk-*.json")}
    assert 2 <= len(before) < CHUNKS, "the run was not interrupted midway"
    assert json.loads((out / "meta.json").read_text())["complete"] is False

    resumed = subprocess.run(_command(scene, out), capture_output=True, text=True, timeout=120)
    assert resumed.returncode == 0, resumed.stderr
    assert f"computed {CHUNKS - len(before)} chunks, {len(before)} already complete" in resumed.stdout
    for name, text in before.items():  # finished chunks untouched
        assert (out / "chunks" / name).read_text() == text
    meta = json.loads((out / "meta.json").read_text())
    assert meta["complete"] and meta["chunks_complete"] == CHUNKS
    assert meta["runs"][-1]["chunks_computed"] == CHUNKS - len(before)
    markers = [json.loads(p.read_text()) for p in (out / "chunks").glob("chunk-*.json")]
    runs = {m["run_id"] for m in markers}
    assert len(runs) == 2  # chunks of the killed run and of the resumed one

    reference = run_ensemble(scene, tmp_path / "uninterrupted")
    assert reference.complete
    a = zarr.open_group(str(out / "data.zarr"), mode="r")
    b = zarr.open_group(str(tmp_path / "uninterrupted" / "data.zarr"), mode="r")
    assert sorted(a.array_keys()) == sorted(b.array_keys())
    for name in a.array_keys():
        assert a[name][:].tobytes() == b[name][:].tobytes(), name
    assert not np.isnan(a["final_M"][:]).any()
