"""'dirac ensemble' on the command line: success summary, resume, bad input (exit 2)."""

from __future__ import annotations

import importlib.util


def test_cli_runs_and_resumes(write_scene, tmp_path, run_cli):
    scene = write_scene(count=40, outputs='["M"]', reductions='["final_state"]')
    out = tmp_path / "out"
    status, stdout, stderr = run_cli("ensemble", str(scene), "--out", str(out), "--chunk-size", "15", "--no-progress")
    assert status == 0, stderr
    assert "40 members in 3 chunks of 15" in stdout and "computed 3 chunks, 0 already complete" in stdout
    status, stdout, stderr = run_cli("ensemble", str(scene), "--out", str(out), "--no-progress")
    assert status == 0
    assert "computed 0 chunks, 3 already complete" in stdout
    assert "resuming: 3 of 3 chunks already complete" in stderr


def test_cli_bad_input_exits_2_with_one_error_line(write_scene, tmp_path, run_cli):
    cases = [
        (write_scene("a.toml", method="rattle-2"), "method = 'rattle-2' is not available for ensembles"),
        (write_scene("b.toml", outputs="[]", reductions="[]"), "the scene asks for nothing"),
        (write_scene("c.toml", reductions='["flip_count"]'), "reductions: unknown reduction 'flip_count' (did you mean"),
        (write_scene("e.toml", extra="colour = \"red\""), "e.toml: [ensemble] has an unknown key 'colour'; known keys: "),
        (write_scene("f.toml", extra="cont = 3"), "f.toml: [ensemble] has an unknown key 'cont' (did you mean 'count'?)"),
        (write_scene("d.toml", members='[ensemble.M]\ndistribution = "sphere"\n'), "needs 'norm'"),
        (tmp_path / "missing.toml", "cannot read scene file"),
    ]
    for scene, fragment in cases:
        status, _, stderr = run_cli("ensemble", str(scene), "--out", str(tmp_path / "never"), "--no-progress")
        lines = [line for line in stderr.splitlines() if line.startswith("error:")]
        assert status == 2 and len(lines) == 1 and fragment in lines[0], stderr
    status, _, stderr = run_cli("ensemble", str(cases[0][0]), "--out", str(tmp_path / "x"), "--workers", "2")
    assert status == 2 and "--workers N needs --cluster local" in stderr
    assert not (tmp_path / "never").exists()


def test_scene_warnings(write_scene, tmp_path, run_cli):
    scene = write_scene(count=5, dt=0.03, reductions='["final_state"]', outputs="[]")
    status, _, stderr = run_cli("ensemble", str(scene), "--out", str(tmp_path / "out"), "--no-progress")
    assert status == 0
    warnings = [line for line in stderr.splitlines() if line.startswith("warning:")]
    assert any("dt = 0.03 does not divide the sample spacing 0.1; using dt = 0.025" in line for line in warnings)


def test_cli_on_a_local_cluster_of_worker_processes(write_scene, tmp_path, run_cli):
    import json

    import zarr

    scene = write_scene(count=60, outputs='["M"]', reductions='["flip_time", "final_state"]')
    status, stdout, stderr = run_cli(
        "ensemble", str(scene), "--out", str(tmp_path / "dask"), "--cluster", "local", "--workers", "2",
        "--chunk-size", "20", "--no-progress",
    )
    assert status == 0, stderr
    # the dask dashboard needs bokeh: its address is printed exactly when bokeh is installed
    has_bokeh = importlib.util.find_spec("bokeh") is not None
    assert ("dask dashboard: http://127.0.0.1:" in stderr) == has_bokeh, stderr
    assert "dashboard" not in stderr or has_bokeh
    assert "computed 3 chunks" in stdout
    status, _, stderr = run_cli("ensemble", str(scene), "--out", str(tmp_path / "local"), "--chunk-size", "30", "--no-progress")
    assert status == 0, stderr
    a = zarr.open_group(str(tmp_path / "dask" / "data.zarr"), mode="r")
    b = zarr.open_group(str(tmp_path / "local" / "data.zarr"), mode="r")
    for name in ("M", "flip_time", "final_M", "final_R"):
        assert a[name][:].tobytes() == b[name][:].tobytes(), name
    markers = [json.loads(p.read_text()) for p in (tmp_path / "dask" / "chunks").glob("*.json")]
    assert all(m["worker"].startswith("tcp://127.0.0.1:") for m in markers)  # loopback only


def test_cli_progress_bar_counts_members(write_scene, tmp_path, run_cli):
    scene = write_scene(count=30, outputs="[]", reductions='["final_state"]')
    status, _, stderr = run_cli("ensemble", str(scene), "--out", str(tmp_path / "out"), "--chunk-size", "10")
    assert status == 0, stderr
    assert "ensemble: 100%" in stderr and "30.0/30.0" in stderr and "member/s" in stderr


def test_cli_names_its_flags_where_the_library_names_keyword_arguments(write_scene, tmp_path, run_cli):
    scene = write_scene(count=30, outputs="[]", reductions='["final_state"]')
    out = tmp_path / "out"
    status, _, stderr = run_cli("ensemble", str(scene), "--out", str(out), "--chunk-size", "10", "--no-progress")
    assert status == 0, stderr
    status, _, stderr = run_cli("ensemble", str(scene), "--out", str(out), "--chunk-size", "15", "--no-progress")
    lines = [line for line in stderr.splitlines() if line.startswith("error:")]
    assert status == 2 and len(lines) == 1, stderr
    assert f"--out {out} was started with chunk size 10; resume with --chunk-size 10" in lines[0]
    assert "chunk_size=" not in lines[0] and "out=" not in lines[0]
    other = write_scene("other.toml", count=30, seed=12, outputs="[]", reductions='["final_state"]')
    status, _, stderr = run_cli("ensemble", str(other), "--out", str(out), "--no-progress")
    assert status == 2 and f"error: --out {out} holds an ensemble of a different scene" in stderr


def test_cli_quiet_prints_no_bar_and_no_summary_but_writes_the_store(write_scene, tmp_path, run_cli):
    scene = write_scene(count=30, outputs="[]", reductions='["final_state"]')
    status, stdout, stderr = run_cli("ensemble", str(scene), "--out", str(tmp_path / "out"), "--chunk-size", "10", "-q")
    assert (status, stdout, stderr) == (0, "", "")
    assert len(list((tmp_path / "out" / "chunks").glob("chunk-*.json"))) == 3
    status, stdout, stderr = run_cli("ensemble", str(scene), "--out", str(tmp_path / "out"), "-q")
    assert (status, stdout, stderr) == (0, "", "")  # not even the "resuming" line
