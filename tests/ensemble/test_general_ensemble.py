"""Ensembles of general systems: members equal single runs, reductions against hand
derivations, bit-identical local / dask / resumed runs, and refused bad input."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
import zarr
from ensemble_stores import damped_pendulum
from ensemble_stores import run_ensemble_cli as _cli
from ensemble_stores import scene_file as _scene
from ensemble_stores import stored_arrays as _arrays

from dirac.ensemble.engine import run_ensemble
from dirac.ensemble.scene import load_ensemble_scene

ANGLES = """[system]
name = "double_pendulum_angles"
coordinates = ["th1", "th2"]
parameters = { m1 = 1.0, m2 = 1.0, g = 9.81, l1 = 1.0, l2 = 1.0 }
lagrangian = "(m1 + m2)/2*l1**2*th1_dot**2 + m2/2*l2**2*th2_dot**2 + m2*l1*l2*th1_dot*th2_dot*cos(th1 - th2) + (m1 + m2)*g*l1*cos(th1) + m2*g*l2*cos(th2)"
"""

DAMPED = damped_pendulum(0.0)

CARTESIAN_Q = '{ x1 = "sin(a)", y1 = "-cos(a)", x2 = "sin(a) + sin(b)", y2 = "-cos(a) - cos(b)" }'
FLIP = ('{ kind = "first_crossing", name = "flip_time", expr = ["x1", "x2 - x1"], '
        'when = ["y1 > 0", "y2 - y1 > 0"] }')




def test_members_equal_single_runs(tmp_path):
    """A member's final state is the single run's from the same initial state, to the last bit
    (same kernel, same step times: RATTLE and the implicit midpoint rule); its energy error is
    that run's max |E(t_k) - E(0)|."""
    from dirac.flows import ConstrainedProblem, ForcedProblem, MechanicalSystem, integrate
    from dirac.model.systems import load_system

    cases = [
        ('[system]\nname = "double_pendulum"\n', f"q = {CARTESIAN_Q}", "rattle-2", "double_pendulum",
         lambda a, b: [np.sin(a), -np.cos(a), np.sin(a) + np.sin(b), -np.cos(a) - np.cos(b)], None),
        (ANGLES, 'q = { th1 = "a", th2 = "b" }', "rattle-4", None, lambda a, b: [a, b], ANGLES),
        # the implicit midpoint rule on the Dirac vector field (times t_k + (j + 1/2) dt)
        ('[system]\nname = "double_pendulum"\n', f"q = {CARTESIAN_Q}", "midpoint", "double_pendulum",
         lambda a, b: [np.sin(a), -np.cos(a), np.sin(a) + np.sin(b), -np.cos(a) - np.cos(b)], None),
        (ANGLES, 'q = { th1 = "a", th2 = "b" }', "midpoint", None, lambda a, b: [a, b], ANGLES),
    ]
    systems = {}  # one MechanicalSystem per system, used for both of its methods (as a user would)
    for k, (system, initial, method, builtin, q_of, file_text) in enumerate(cases):
        path = _scene(tmp_path, system, initial, f'method = "{method}"\ndt = 0.01\nt_end = 0.7\nsamples = 8',
                      'grid = { a = [-2.0, 2.5, 3], b = [0.5, 1.0, 2] }\nreductions = ["final", "energy_error"]',
                      name=f"s{k}.toml")
        assert run_ensemble(path, tmp_path / f"out{k}").complete
        stored = _arrays(tmp_path / f"out{k}")
        if (builtin, file_text) not in systems:
            if builtin:
                lagrangian = load_system(builtin)
            else:
                (tmp_path / "sys.toml").write_text(file_text)
                lagrangian = load_system(tmp_path / "sys.toml")
            systems[builtin, file_text] = MechanicalSystem.from_lagrangian(lagrangian)
        mechanics = systems[builtin, file_text]
        for i in range(6):
            q0 = np.array(q_of(stored["a"][i], stored["b"][i]))
            problem = ConstrainedProblem(mechanics, q0, np.zeros_like(q0))
            single = integrate(problem, method, t_end=0.7, dt=0.01, samples=8, outputs=["q", "p", "energy"])
            assert np.array_equal(single.outputs["q"][-1], stored["final_q"][i])
            assert np.array_equal(single.outputs["p"][-1], stored["final_p"][i])
            energy = single.outputs["energy"]
            assert stored["energy_error"][i] == pytest.approx(np.max(np.abs(energy - energy[0])), rel=1e-12, abs=1e-15)
    # a forced, time-dependent system: forced RATTLE's state is the single run's too, under its
    # own name and under the ordinary name rattle-4 (forced-rattle-4 on a forced system, as
    # dirac.integrate of a ConstrainedProblem of the forced system runs it)
    (tmp_path / "damped.toml").write_text(DAMPED)
    for method, single_method, problem_class in (("forced-rattle-2", "forced-rattle-2", ForcedProblem),
                                                  ("rattle-4", "rattle-4", ConstrainedProblem)):
        path = _scene(tmp_path, '[system]\nfile = "damped.toml"\nparameters = { F = 1.2, w = "1 + s" }\n',
                      'q = { th = 0.3 }\nq_dot = { th = "s" }', f'method = "{method}"\ndt = 0.01\nt_end = 1.0',
                      'grid = { s = [0.0, 1.0, 3] }\nreductions = ["final"]', name="forced.toml")
        assert run_ensemble(path, tmp_path / method).complete
        stored = _arrays(tmp_path / method)
        for i, s in enumerate(stored["s"]):
            mechanics = MechanicalSystem.from_lagrangian(load_system(tmp_path / "damped.toml"), {"F": 1.2, "w": 1 + s},
                                                         with_forces=True)
            single = integrate(problem_class(mechanics, np.array([0.3]), np.array([s])), single_method, t_end=1.0,
                               dt=0.01, outputs=["q", "p"])
            assert np.array_equal(single.outputs["q"][-1], stored["final_q"][i])
            assert np.array_equal(single.outputs["p"][-1], stored["final_p"][i])


def test_flip_time_and_early_stop(tmp_path):
    """Released at rest with 3 cos a + cos b > 2 (energy below the first flip's), neither arm can
    reach the top (Heyl): no flip. Members that flip stop in the step of their flip:
    (steps - 1) dt < t_flip <= steps dt; the others run every step."""
    path = _scene(tmp_path, '[system]\nname = "double_pendulum"\n', f"q = {CARTESIAN_Q}",
                  "dt = 0.002\nt_end = 3.0", f"grid = {{ a = [-3.0, 3.0, 9], b = [-3.0, 3.0, 9] }}\nreductions = [{FLIP}]")
    assert run_ensemble(path, tmp_path / "out").complete
    stored = _arrays(tmp_path / "out")
    a, b, flip, steps = stored["a"], stored["b"], stored["flip_time"], stored["steps"]
    bound = 3 * np.cos(a) + np.cos(b) > 2
    assert np.all(np.isnan(flip[bound])) and bound.sum() > 5
    flipped = np.isfinite(flip)
    assert flipped.sum() > 10
    dt = 0.002
    assert np.all((steps[flipped] - 1) * dt - 1e-12 <= flip[flipped])
    assert np.all(flip[flipped] <= steps[flipped] * dt + 1e-12)
    assert np.all(steps[~flipped] == 1500)
    assert np.all(stored["failures"] == 0)


def test_flip_map_identical_local_dask_and_resumed(tmp_path):
    """The flip map does not depend on where or in how many pieces it is computed."""
    path = _scene(tmp_path, '[system]\nname = "double_pendulum"\n', f"q = {CARTESIAN_Q}",
                  "dt = 0.002\nt_end = 2.0",
                  f"grid = {{ a = [-3.0, 3.0, 6], b = [-3.0, 3.0, 6] }}\nchunk_size = 9\nreductions = [{FLIP}]")
    assert run_ensemble(path, tmp_path / "local").complete
    reference = _arrays(tmp_path / "local")["flip_time"]
    assert np.isfinite(reference).sum() > 5
    assert run_ensemble(path, tmp_path / "dask", cluster="local", n_workers=2).complete
    assert np.array_equal(_arrays(tmp_path / "dask")["flip_time"], reference, equal_nan=True)
    # an interruption leaves chunks without a marker (their data half written): they are recomputed
    out = tmp_path / "local"
    for index in (1, 3):
        (out / "chunks" / f"chunk-{index:06d}.json").unlink()
        zarr.open_array(str(out / "data.zarr"), path="flip_time", mode="r+")[9 * index : 9 * index + 9] = 123.0
    report = run_ensemble(path, out)
    assert report.complete and report.chunks_computed == 2 and report.chunks_skipped == 2
    assert np.array_equal(_arrays(out)["flip_time"], reference, equal_nan=True)


def test_poincare_points_lie_on_the_section(tmp_path):
    """Upward crossings of th1 = 0 are located on the section to 1e-12, in time order, with th1
    increasing through it; between two steps (dt)."""
    (tmp_path / "angles.toml").write_text(ANGLES)
    path = _scene(tmp_path, '[system]\nfile = "angles.toml"\n', 'q = { th1 = "a", th2 = "b" }',
                  "dt = 0.005\nt_end = 8.0",
                  'grid = { a = [0.3, 1.2, 3], b = [-1.0, 1.5, 3] }\n'
                  'reductions = [{ kind = "poincare", name = "section", expr = "th1", count = 4 }]')
    assert run_ensemble(path, tmp_path / "out").complete
    stored = _arrays(tmp_path / "out")
    t, q = stored["section_t"], stored["section_q"]
    assert t.shape == (9, 4) and q.shape == (9, 4, 2)
    found = np.isfinite(t)
    assert found.sum() >= 20
    assert np.max(np.abs(q[found][:, 0])) <= 1e-12
    assert np.all(np.diff(t[found.all(axis=1)], axis=1) > 0.005)


def test_damped_pendulum_basins_from_energy(tmp_path):
    """A damped pendulum (th'' = -g sin th - c th') whose energy E = th'^2/2 + g (1 - cos th)
    starts below the separatrix value 2 g cannot pass over the top: it ends at the equilibrium
    of its own well, th = 0 (energy decreases along the motion). Above it, members that go over
    end at th = 2 pi k with k != 0."""
    (tmp_path / "damped.toml").write_text(DAMPED)
    path = _scene(tmp_path, '[system]\nfile = "damped.toml"\n', 'q = { th = "th0" }\nq_dot = { th = "w0" }',
                  'method = "forced-rattle-2"\ndt = 0.01\nt_end = 40.0',
                  'grid = { th0 = [-3.0, 3.0, 7], w0 = [-9.0, 9.0, 7] }\nreductions = ["final", "energy_error"]')
    assert run_ensemble(path, tmp_path / "out").complete
    stored = _arrays(tmp_path / "out")
    energy = stored["w0"] ** 2 / 2 + 9.81 * (1 - np.cos(stored["th0"]))
    final = stored["final_q"][:, 0]
    below = energy < 2 * 9.81
    assert below.sum() >= 10 and np.all(np.abs(final[below]) < 1e-3)
    well = np.round(final / (2 * np.pi))
    assert np.all(np.abs(final - 2 * np.pi * well) < 1e-3)  # every member ends at an equilibrium
    assert np.any(well[~below] != 0)
    # energy - work is conserved up to the method's O(dt^2): halving dt divides the error by about 4
    half = _scene(tmp_path, '[system]\nfile = "damped.toml"\n', 'q = { th = "th0" }\nq_dot = { th = "w0" }',
                  'method = "forced-rattle-2"\ndt = 0.005\nt_end = 10.0',
                  'grid = { th0 = [-3.0, 3.0, 7], w0 = [-9.0, 9.0, 7] }\nreductions = ["energy_error"]', name="half.toml")
    full = _scene(tmp_path, '[system]\nfile = "damped.toml"\n', 'q = { th = "th0" }\nq_dot = { th = "w0" }',
                  'method = "forced-rattle-2"\ndt = 0.01\nt_end = 10.0',
                  'grid = { th0 = [-3.0, 3.0, 7], w0 = [-9.0, 9.0, 7] }\nreductions = ["energy_error"]', name="full.toml")
    assert run_ensemble(half, tmp_path / "half").complete and run_ensemble(full, tmp_path / "full").complete
    coarse, fine = _arrays(tmp_path / "full")["energy_error"], _arrays(tmp_path / "half")["energy_error"]
    ratio = coarse[fine > 0] / fine[fine > 0]
    assert 3.9 < np.median(ratio) < 4.1  # (the member at rest at th = 0 has no error at all)



@pytest.mark.parametrize("initial, ensemble, project, message", [
    (f"q = {CARTESIAN_Q.replace('sin(b)', 'sin(c)')}", "grid = { a = [0.0, 1.0, 2], b = [0.0, 1.0, 2] }", False,
     "unknown name 'c'"),
    (f"q = {CARTESIAN_Q}", "grid = { a = [0.0, 1.0, 0], b = [0.0, 1.0, 2] }", False, "grid a: n = 0 must be an integer >= 1"),
    (f"q = {CARTESIAN_Q}", "grid = { a = [0.0, 1.0, 2], b = [0.0, 1.0, 2] }\n"
     'reductions = [{ kind = "max", expr = "x1 + zz" }]', False, "unknown name 'zz'"),
    (f"q = {CARTESIAN_Q.replace('-cos(a) - cos(b)', '-cos(a) - 1.5*cos(b)')}",
     "grid = { a = [0.0, 1.0, 2], b = [0.0, 1.0, 2] }", False, "off the constraint surface"),
])
def test_bad_input_is_refused_before_anything_is_written(tmp_path, initial, ensemble, project, message):
    if "reductions" not in ensemble:
        ensemble += '\nreductions = ["final"]'
    path = _scene(tmp_path, '[system]\nname = "double_pendulum"\n', initial + f"\nproject = {str(project).lower()}",
                  "dt = 0.01\nt_end = 0.1", ensemble)
    result = _cli(path, tmp_path / "out")
    assert result.returncode == 2, result.stderr
    assert result.stderr.startswith("error: ") and message in result.stderr and len(result.stderr.splitlines()) == 1
    assert not (tmp_path / "out").exists()


def test_a_forced_system_refuses_a_method_without_forces_naming_those_with(tmp_path):
    """rattle-6 has no forced version: the refusal names the ordinary names that take forces
    (rattle-2, rattle-4) besides the forced methods."""
    (tmp_path / "damped.toml").write_text(DAMPED)
    path = _scene(tmp_path, '[system]\nfile = "damped.toml"\n', 'q = { th = 0.3 }', 'method = "rattle-6"\ndt = 0.01\nt_end = 0.1',
                  'grid = { s = [0.0, 1.0, 2] }\nreductions = ["final"]')
    result = _cli(path, tmp_path / "out")
    assert result.returncode == 2 and len(result.stderr.splitlines()) == 1, result.stderr
    assert result.stderr.startswith("error: [run] method = 'rattle-6' is not available for a forced system")
    assert "'rattle-2', 'rattle-4', 'forced-rattle-2'" in result.stderr
    assert not (tmp_path / "out").exists()


def test_projection_puts_members_on_the_surface(tmp_path):
    """The same off-surface initial q with project = true runs, and every member starts on the
    surface: its constraint error (max over the samples) is at the Newton tolerance."""
    path = _scene(tmp_path, '[system]\nname = "double_pendulum"\n',
                  f"q = {CARTESIAN_Q.replace('-cos(a) - cos(b)', '-cos(a) - 1.5*cos(b)')}\nproject = true",
                  "dt = 0.01\nt_end = 0.2", 'grid = { a = [0.0, 1.0, 2], b = [0.0, 1.0, 2] }\nreductions = ["constraint_error"]')
    assert run_ensemble(path, tmp_path / "out").complete
    assert np.all(_arrays(tmp_path / "out")["constraint_error"] < 1e-9)


def test_map_and_section_pictures(tmp_path):
    """``dirac ensemble-plot`` draws a 2-D grid as a map and a Poincaré section as a scatter."""
    path = _scene(tmp_path, '[system]\nname = "double_pendulum"\n', f"q = {CARTESIAN_Q}",
                  "dt = 0.004\nt_end = 2.0",
                  f'grid = {{ a = [-3.0, 3.0, 5], b = [-3.0, 3.0, 4] }}\nreductions = [{FLIP}, '
                  '{ kind = "poincare", name = "section", expr = "x1", count = 3 }]')
    assert run_ensemble(path, tmp_path / "out").complete
    for args, expected in ([[], "map of flip_time: 5 x 4 members"], [["--array", "section", "--x", "x2", "--y", "p_x2"],
                                                                      "Poincaré section 'section'"]):
        image = tmp_path / "picture.png"
        result = subprocess.run([sys.executable, "-m", "dirac", "ensemble-plot", str(tmp_path / "out"), "--out",
                                 str(image), *args], capture_output=True, text=True, timeout=120)
        assert result.returncode == 0, result.stderr
        assert expected in result.stdout and image.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        image.unlink()
    meta = json.loads((tmp_path / "out" / "meta.json").read_text())
    assert meta["failure_codes"]["1"].startswith("Newton") and meta["system"] == "double_pendulum"
    assert load_ensemble_scene(path).early_stop  # crossings only: a member stops once all are found


def test_random_variables_do_not_depend_on_the_chunking(tmp_path):
    """Random ensemble variables are counter-based draws: the same members whatever the chunk
    size; a grid point repeats with ``count`` draws each (member i = point * count + draw)."""
    body = ('[system]\nname = "pendulum"\nparameters = { g = "g0" }\n', 'q = { x = "sin(a)", y = "-cos(a)" }',
            "dt = 0.01\nt_end = 0.05")
    ensemble = ('grid = { a = [0.1, 0.3, 3] }\ncount = 4\nseed = 11\nreductions = ["final"]\n'
                '[ensemble.variables]\ng0 = { distribution = "uniform", low = 9.0, high = 10.0 }')
    one = _scene(tmp_path, *body, ensemble + "\n", name="one.toml")
    run_ensemble(one, tmp_path / "one", chunk_size=12)
    run_ensemble(one, tmp_path / "five", chunk_size=5)
    a, b = _arrays(tmp_path / "one"), _arrays(tmp_path / "five")
    assert np.array_equal(a["g0"], b["g0"]) and np.array_equal(a["final_q"], b["final_q"])
    assert np.all((a["g0"] >= 9.0) & (a["g0"] < 10.0)) and len(set(a["g0"].tolist())) == 12
    assert np.array_equal(a["a"], np.repeat(0.1 + (0.3 - 0.1) * np.array([0.0, 0.5, 1.0]), 4))  # lo + (hi - lo) j / (n - 1)


def test_killed_flip_map_run_resumes_bit_identically(tmp_path):
    """'dirac ensemble' killed midway (SIGKILL) and rerun gives the uninterrupted run's bits."""
    import os
    import signal
    import time

    path = _scene(tmp_path, '[system]\nname = "double_pendulum"\n', f"q = {CARTESIAN_Q}", "dt = 0.002\nt_end = 60.0",
                  f'grid = {{ a = [-3.0, 3.0, 12], b = [-3.0, 3.0, 12] }}\nchunk_size = 8\n'
                  f'reductions = [{FLIP}, {{ kind = "max", name = "highest", expr = "y2" }}]')
    out = tmp_path / "killed"
    command = [sys.executable, "-m", "dirac", "ensemble", str(path), "--out", str(out), "--no-progress"]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 240
    try:
        while len(list((out / "chunks").glob("chunk-*.json"))) < 2:
            assert process.poll() is None, process.communicate()
            assert time.monotonic() < deadline, "fewer than two chunks finished within 240 s"
            time.sleep(0.005)
    finally:
        os.kill(process.pid, signal.SIGKILL)
        process.wait()
    done = len(list((out / "chunks").glob("chunk-*.json")))
    assert 2 <= done < 18, "the run was not interrupted midway"
    resumed = _cli(path, out)
    assert resumed.returncode == 0, resumed.stderr
    assert f"computed {18 - done} chunks, {done} already complete" in resumed.stdout
    assert run_ensemble(path, tmp_path / "whole").complete
    for name in ("flip_time", "highest"):
        assert np.array_equal(_arrays(out)[name], _arrays(tmp_path / "whole")[name], equal_nan=True)


def test_failed_members_are_nan_with_their_reason(tmp_path):
    """With one Newton iteration per step, RATTLE's implicit stage converges only where the
    first guess already solves it: the pendulum at rest at the bottom (no force, no motion).
    Every other member fails with code 1 (Newton) and NaN reductions; that one completes."""
    (tmp_path / "angles.toml").write_text(ANGLES)
    path = _scene(tmp_path, '[system]\nfile = "angles.toml"\n', 'q = { th1 = "a", th2 = "b" }',
                  "dt = 0.01\nt_end = 0.5\nmax_newton_iterations = 1",
                  'grid = { a = [-0.5, 0.5, 3], b = [-0.5, 0.5, 3] }\n'
                  'reductions = [{ kind = "max", name = "top", expr = "th1" }, "final"]')
    assert run_ensemble(path, tmp_path / "out").complete
    stored = _arrays(tmp_path / "out")
    centre = (stored["a"] == 0.0) & (stored["b"] == 0.0)
    assert np.array_equal(stored["failures"], np.where(centre, 0.0, 1.0))
    assert np.all(np.isnan(stored["top"][~centre])) and np.all(np.isnan(stored["final_q"][~centre]))
    assert stored["top"][centre] == 0.0 and np.array_equal(stored["final_q"][centre], [[0.0, 0.0]])
    meta = json.loads((tmp_path / "out" / "meta.json").read_text())
    assert meta["failure_codes"]["1"].startswith("Newton iteration did not converge")


@pytest.mark.parametrize("builtin, forced, kernel", [
    (ANGLES, False, "rattle_general"),
    (DAMPED, True, "forced_rattle_run"),
])
def test_member_loop_pastes_the_step_body(tmp_path, builtin, forced, kernel):
    """Regression: the member loop pastes the step loop's body (its work arrays allocated once
    per member) for every step kernel, whether or not the system's module inlined its closing
    ``report``; calling the loop for one step instead allocated two dozen arrays per step and
    made the angles' flip map 3 x slower per step than a single run. (The constant-mass RATTLE
    of the Cartesian double pendulum is unrolled scalar code that allocates nothing: it is
    called.)"""
    from dirac.ensemble.general_kernel import _paste_step
    from dirac.flows import MechanicalSystem
    from dirac.model.systems import load_system

    if builtin.startswith("["):
        (tmp_path / "sys.toml").write_text(builtin)
        lagrangian = load_system(tmp_path / "sys.toml")
    else:
        lagrangian = load_system(builtin)
    mechanics = MechanicalSystem.from_lagrangian(lagrangian, with_forces=forced)
    pasted = _paste_step(mechanics.module.source, kernel)
    assert pasted is not None
    allocations, _prelude, body = pasted
    assert allocations and all("= np." in line for line in allocations)
    assert "for step in range(n_steps)" not in "\n".join(body)


def test_flip_map_bench_rows_count_the_steps_run():
    """The flip-map rows of ``dirac bench --ensemble`` at 3 x 3 (the bench runs 256 x 256).

    Hand derivation (point masses m = l = 1 at the rod ends, released at rest): the energy is
    E = V(a, b) = -g (2 cos th1 + cos th2). Arm 1 over its pivot (th1 = pi) needs
    E >= min over th2 of V(pi, th2) = g, arm 2 over arm 1 (th2 = pi) needs E >= min over th1 of
    V(th1, pi) = -g; so no flip where 2 cos a + cos b > 1. Of a, b in {-3, 0, 3} that is
    (0, 0), (0, 3) and (0, -3) (2 + cos 3 = 1.010): they run all 5000 steps of t_end = 10 at
    dt = 2e-3; the other six stop at their flip or run to the end."""
    from dirac.ensemble.bench import format_flip_table, measure_flip_maps

    rows = measure_flip_maps(side=3)
    assert [row["system"] for row in rows] == ["double pendulum (x1, y1, x2, y2; 2 rods)", "double pendulum (th1, th2)"]
    for row in rows:
        assert row["flips"] <= 6
        assert 3 * 5000 + (6 - row["flips"]) * 5000 <= row["member_steps"] < 9 * 5000 or row["flips"] == 0
        assert row["seconds"] > 0.0 and row["cpu_seconds"] > 0.0
    table = format_flip_table(rows)
    assert "3 x 3 angles" in table and "target: <= 60 s" in table


def test_projected_members_are_projected_once_with_the_same_bits(tmp_path, monkeypatch):
    """With project = true a local run projects each member once (the check before anything is
    written keeps the projected states for the chunks), and stores the same bits as chunks that
    project again (as a dask worker or a resumed run does): the projection is one function of
    the member (:meth:`MechanicalSystem.project`), whose result is kept, not approximated."""
    from dirac.ensemble.general_chunk import _PROJECTED, compute_general_chunk
    from dirac.flows.mechanics import MechanicalSystem

    calls = []
    project = MechanicalSystem.project

    def counted(self, q, p, *args, **kwargs):
        calls.append(1)
        return project(self, q, p, *args, **kwargs)

    monkeypatch.setattr(MechanicalSystem, "project", counted)
    path = _scene(tmp_path, '[system]\nname = "double_pendulum"\n',
                  f"q = {CARTESIAN_Q.replace('-cos(a) - cos(b)', '-cos(a) - 1.5*cos(b)')}\n"
                  'q_dot = { x1 = "0.3*b" }\nproject = true',
                  "dt = 0.01\nt_end = 0.3", 'grid = { a = [0.0, 1.0, 3], b = [0.0, 1.0, 3] }\nchunk_size = 4\n'
                  'reductions = ["final", "constraint_error"]')
    assert run_ensemble(path, tmp_path / "out").complete
    assert len(calls) == 9 and not _PROJECTED
    stored = _arrays(tmp_path / "out")
    scene = load_ensemble_scene(path)
    for start, stop in ((0, 4), (4, 8), (8, 9)):
        again = compute_general_chunk(scene, start, stop)
        for name in ("final_q", "final_p", "constraint_error"):
            assert np.array_equal(again[name], stored[name][start:stop])
    assert len(calls) == 18
    assert np.all(stored["constraint_error"] < 1e-9)
