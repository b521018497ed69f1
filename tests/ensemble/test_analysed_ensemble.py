"""Ensembles of systems that run on the Dirac flow of their analysis (velocity-linear and gauge
Lagrangians): members equal single runs, reductions against the closed form of the implicit
midpoint rule on a linear flow, refused bad input."""

from __future__ import annotations

import numpy as np
import pytest
import zarr
from ensemble_stores import run_ensemble_cli as _cli
from ensemble_stores import scene_file as _scene
from ensemble_stores import stored_arrays as _arrays

from dirac.ensemble.engine import run_ensemble

#: L = x y_dot - (x^2 + y^2)/2 + z_dot^2/2 - z^2/2 (velocity-linear in x, y).
VELOCITY_LINEAR = """[system]
name = "velocity_linear"
coordinates = ["x", "y", "z"]
lagrangian = "x*y_dot - (x**2 + y**2)/2 + z_dot**2/2 - z**2/2"
"""




def test_members_equal_single_runs(tmp_path):
    """A member's final state is that of a single midpoint run of the same initial state on the
    same analysed system (AnalysedSystem.from_lagrangian, z0 completed by initial_state), to the
    last bit; its energy error is that run's max |H_c(t_k) - H_c(0)|. Both a velocity-linear
    Lagrangian and the Christ-Lee gauge system (free multiplier u_1 = 0, as a single run; initial
    velocities radial, x p_y - y p_x = 0 on the Gauss-law surface)."""
    from dirac.flows import AnalysedProblem, AnalysedSystem, integrate
    from dirac.model.systems import load_system

    (tmp_path / "vl.toml").write_text(VELOCITY_LINEAR)
    cases = [
        ('[system]\nfile = "vl.toml"\n', 'q = { x = "a", y = "b", z = "a*b" }\nq_dot = { z = "b" }', tmp_path / "vl.toml",
         lambda a, b: ({"x": a, "y": b, "z": a * b}, {"x": 0.0, "y": 0.0, "z": b})),
        ('[system]\nname = "gauge_system"\n', 'q = { x = "a", y = "0.5*a", z = 0.0 }\nq_dot = { x = "a*b", y = "0.5*a*b" }',
         "gauge_system", lambda a, b: ({"x": a, "y": 0.5 * a, "z": 0.0}, {"x": a * b, "y": 0.5 * a * b, "z": 0.0})),
    ]
    for k, (system, initial, source, given) in enumerate(cases):
        path = _scene(tmp_path, system, initial, "dt = 0.01\nt_end = 0.7\nsamples = 8",
                      'grid = { a = [-1.0, 1.5, 3], b = [0.5, 1.0, 2] }\nreductions = ["final", "energy_error"]',
                      name=f"s{k}.toml")
        assert run_ensemble(path, tmp_path / f"out{k}").complete
        stored = _arrays(tmp_path / f"out{k}")
        analysed = AnalysedSystem.from_lagrangian(load_system(source))
        half = analysed.dimension // 2
        assert stored["final_q"].shape == (6, 3) and half == 3
        for i in range(6):
            q, q_dot = given(stored["a"][i], stored["b"][i])
            z0 = analysed.initial_state(q, q_dot=q_dot)
            single = integrate(AnalysedProblem(analysed, z0), "midpoint", t_end=0.7, dt=0.01, samples=8,
                               outputs=["z", "energy"])
            assert np.array_equal(single.outputs["z"][-1][:half], stored["final_q"][i])
            assert np.array_equal(single.outputs["z"][-1][half:], stored["final_p"][i])
            energy = single.outputs["energy"]
            assert stored["energy_error"][i] == pytest.approx(np.max(np.abs(energy - energy[0])), rel=1e-12, abs=1e-15)
        assert np.all(stored["failures"] == 0)


def test_velocity_linear_sweep_against_the_closed_form(tmp_path):
    """By hand: p_x = dL/dx_dot = 0, p_y = x (second-class constraints p_x = 0, p_y - x = 0);
    Euler-Lagrange for x: 0 = y_dot - x, for y: x_dot = -y, for z: z_ddot = -z. So (x, y)
    rotates, x = A cos t, y = A sin t from (A, 0), and (z, p_z) too, with the conserved
    H_c = (x^2 + y^2)/2 + (p_z^2 + z^2)/2. The implicit midpoint rule on this linear flow
    (whose linear constraints it keeps) is the rotation by theta = 2 atan(h/2) per step
    (Cayley transform of h J; Hairer, Lubich & Wanner IV.2): x_k = A cos(k theta), y_k = A sin(k theta).

    Checked: max of y over the steps (A max_k sin(k theta)); max of y_dot (= x on the flow:
    A, at t = 0); max and min of x^2 + y^2 (= A^2, a quadratic invariant); the first zero of x
    (the straight-line zero between the steps bracketing k theta = pi/2, near T/4 = pi/2);
    the Poincaré point of y crossing 0 upward (y = 0 to 1e-12, near t = 2 pi); the final state;
    energy and constraint errors at the Newton tolerance."""
    path = _scene(tmp_path, VELOCITY_LINEAR, 'q = { x = "A", y = 0.0, z = "A/2" }',
                  "dt = 0.01\nt_end = 7.0\nsamples = 8",
                  'grid = { A = [0.5, 2.0, 4] }\nreductions = [\n'
                  '  { kind = "max", name = "ymax", expr = "y" },\n'
                  '  { kind = "max", name = "vmax", expr = "y_dot" },\n'
                  '  { kind = "max", name = "r2max", expr = "x**2 + y**2" },\n'
                  '  { kind = "min", name = "r2min", expr = "x**2 + y**2" },\n'
                  '  { kind = "first_crossing", name = "quarter", expr = "x" },\n'
                  '  { kind = "poincare", name = "section", expr = "y", count = 2 },\n'
                  '  "final", "energy_error", "constraint_error",\n]')
    assert run_ensemble(path, tmp_path / "out").complete
    stored = _arrays(tmp_path / "out")
    h, steps = 0.01, 700
    theta = 2.0 * np.arctan(h / 2.0)
    k = np.arange(steps + 1)
    A = stored["A"]
    assert np.allclose(A, [0.5, 1.0, 1.5, 2.0], rtol=0, atol=1e-15)
    assert np.allclose(stored["ymax"], A * np.max(np.sin(k * theta)), rtol=1e-11, atol=0)
    assert np.allclose(stored["vmax"], A, rtol=1e-12, atol=0)
    assert np.allclose(stored["r2max"], A**2, rtol=1e-11, atol=0)
    assert np.allclose(stored["r2min"], A**2, rtol=1e-11, atol=0)
    # the first zero of x_k = A cos(k theta), on the straight line between the bracketing steps
    j = int(np.argmax(np.cos((k + 1) * theta) <= 0.0))
    s = np.cos(j * theta) / (np.cos(j * theta) - np.cos((j + 1) * theta))
    assert np.allclose(stored["quarter"], (j + s) * h, rtol=0, atol=1e-9)
    assert np.all(np.abs(stored["quarter"] - np.pi / 2) < 2e-5)  # the scheme's phase error, O(h^2)
    # y_k = A sin(k theta) crosses 0 upward between steps i and i + 1 (i theta just below 2 pi)
    i = int(np.argmax((np.sin(k[1:] * theta) < 0.0) & (np.sin((k[1:] + 1) * theta) >= 0.0))) + 1
    s = -np.sin(i * theta) / (np.sin((i + 1) * theta) - np.sin(i * theta))
    assert np.allclose(stored["section_t"][:, 0], (i + s) * h, rtol=0, atol=1e-9)
    assert np.all(np.isnan(stored["section_t"][:, 1]))  # the next one is after t_end (4 pi > 7)
    assert np.max(np.abs(stored["section_q"][:, 0, 1])) <= 1e-12
    # the final state: (x, y, z) and (p_x, p_y, p_z) = (0, x, z_dot)
    c, sn = np.cos(steps * theta), np.sin(steps * theta)
    expected_q = np.column_stack([A * c, A * sn, A / 2 * c])
    expected_p = np.column_stack([0 * A, A * c, -A / 2 * sn])
    assert np.allclose(stored["final_q"], expected_q, rtol=0, atol=1e-10)
    assert np.allclose(stored["final_p"], expected_p, rtol=0, atol=1e-10)
    assert np.all(stored["energy_error"] <= 1e-12 * A**2)
    assert np.all(stored["constraint_error"] <= 1e-13)
    assert np.all(stored["failures"] == 0) and np.all(stored["steps"] == steps)


def test_early_stop_on_the_dirac_flow(tmp_path):
    """A member that asks only for the first zero of x stops in the step of it (x_k = A cos(k theta):
    the step j + 1 with k theta crossing pi/2, above)."""
    path = _scene(tmp_path, VELOCITY_LINEAR, 'q = { x = "A", y = 0.0, z = 0.0 }', "dt = 0.01\nt_end = 3.0",
                  'grid = { A = [1.0, 2.0, 2] }\nreductions = [{ kind = "first_crossing", name = "quarter", expr = "x" }]')
    assert run_ensemble(path, tmp_path / "out").complete
    stored = _arrays(tmp_path / "out")
    theta = 2.0 * np.arctan(0.005)
    k = np.arange(301)
    j = int(np.argmax(np.cos((k + 1) * theta) <= 0.0))
    assert np.all(stored["steps"] == j + 1)



@pytest.mark.parametrize("initial, run, ensemble, message", [
    ('q = { x = "A", y = 0.0, z = "B" }', "", "", "unknown name 'B'"),
    ('q = { x = "A", y = "sinn(A)", z = 0.0 }', "", "", "call of 'sinn' is not allowed"),
    ('q = { x = "A", y = 0.0, z = 0.0 }', "", 'reductions = [{ kind = "max", expr = "x + w" }]', "unknown name 'w'"),
    # p_y = x is a constraint of the flow: p_y = 2 A leaves the surface
    ('q = { x = "A", y = 0.0, z = 0.0 }\np = { y = "2*A" }', "", "", "no point of the constraint surface"),
    ('q = { x = "A", y = 0.0, z = 0.0 }\nproject = true', "", "", "project = true"),
    ('q = { x = "A", y = 0.0, z = 0.0 }', 'method = "rattle-2"\n', "", "method = 'rattle-2' is not available"),
])
def test_bad_input_is_refused_before_anything_is_written(tmp_path, initial, run, ensemble, message):
    path = _scene(tmp_path, VELOCITY_LINEAR, initial, run + "dt = 0.01\nt_end = 0.1",
                  "grid = { A = [0.5, 1.0, 2] }\n" + (ensemble or 'reductions = ["final"]'))
    result = _cli(path, tmp_path / "out")
    assert result.returncode == 2, result.stderr
    assert result.stderr.startswith("error: ") and message in result.stderr and len(result.stderr.splitlines()) == 1
    assert not (tmp_path / "out").exists()


def test_parameters_varying_over_an_analysed_ensemble_are_refused(tmp_path):
    """The analysis is made with the parameters fixed, as in a single run: a parameter that varies
    over the members is refused by name (the Christ-Lee system's k)."""
    path = _scene(tmp_path, '[system]\nname = "gauge_system"\nparameters = { k = "K" }\n',
                  'q = { x = 1.0, y = 0.0, z = 0.0 }', "dt = 0.01\nt_end = 0.1",
                  'grid = { K = [0.5, 1.0, 2] }\nreductions = ["final"]')
    result = _cli(path, tmp_path / "out")
    assert result.returncode == 2 and "parameters k of 'gauge_system' vary over the ensemble" in result.stderr
    assert not (tmp_path / "out").exists()


def test_needs_analysis_agrees_with_the_mechanical_form():
    """The scene's test is the one that makes MechanicalSystem refuse a Lagrangian."""
    from dirac.ensemble.general_scene import needs_analysis
    from dirac.flows.mechanics import MechanicalSystem, NotMechanicalError
    from dirac.model.system_file import lagrangian_from_table
    from dirac.model.systems import load_system

    velocity_linear = lagrangian_from_table({"name": "vl", "coordinates": ["x", "y", "z"],
                                             "lagrangian": "x*y_dot - (x**2 + y**2)/2 + z_dot**2/2 - z**2/2"},
                                            source="test")
    quartic = lagrangian_from_table({"name": "quartic", "coordinates": ["x"], "lagrangian": "x_dot**4/4 - x**2/2"},
                                    source="test")
    for lagrangian in (velocity_linear, quartic, load_system("gauge_system"), load_system("double_pendulum"),
                       load_system("pendulum")):
        try:
            MechanicalSystem.from_lagrangian(lagrangian)
            refused = False
        except NotMechanicalError:
            refused = True
        assert needs_analysis(lagrangian) == refused, lagrangian.name
    assert needs_analysis(velocity_linear) and needs_analysis(load_system("gauge_system"))


def test_a_system_a_single_run_refuses_is_refused_with_its_message(tmp_path):
    """The einbein form of the relativistic particle, L = x_dot^2/(2e) - e m^2/2, is quadratic in
    the velocities without e_dot: its mass matrix diag(-1/e, 1/e, 1/e, 1/e, 0) is singular, and a
    single run refuses it (the mass matrix is singular or not positive); so does the ensemble,
    before anything is written, instead of failing every member."""
    path = _scene(tmp_path, '[system]\nname = "relativistic_particle"\n',
                  'q = { t = 0.0, x = 0.0, y = 0.0, z = 0.0, e = 1.0 }\nq_dot = { t = 1.2, x = "a" }',
                  "dt = 0.01\nt_end = 0.1", 'grid = { a = [0.1, 0.5, 2] }\nreductions = ["final"]')
    result = _cli(path, tmp_path / "out")
    assert result.returncode == 2 and len(result.stderr.splitlines()) == 1
    assert "the mass matrix of 'relativistic_particle' is singular or not positive" in result.stderr
    assert not (tmp_path / "out").exists()


#: A velocity-linear pair (x, y) and a particle on the unit circle z^2 + w^2 = 1 in the potential
#: z^2/2: the analysis adds the multiplier lambda_1 (and p_lambda_1) to the phase space.
RING = """[system]
name = "ring"
coordinates = ["x", "y", "z", "w"]
lagrangian = "x*y_dot - (x**2 + y**2)/2 + z_dot**2/2 + w_dot**2/2 - z**2/2"
constraints = ["z**2 + w**2 - 1"]
"""


def test_multipliers_are_completed_the_same_everywhere_and_members_equal_single_runs(tmp_path):
    """The multiplier lambda_1 is solved from a random start by surface_point: without a fixed
    start its last bits differ from call to call (and so between a local and a dask run). The
    ensemble completes every member from the same start (seed 0): two completions are equal to
    the bit, a member equals the single run from that state, and the stored final state holds
    the Lagrangian's coordinates x, y, z, w and their momenta only."""
    from dirac.ensemble.analysed_members import analysed_initial_states, analysed_system
    from dirac.ensemble.scene import load_ensemble_scene
    from dirac.flows import AnalysedProblem, integrate
    from dirac.model.systems import load_system

    (tmp_path / "ring.toml").write_text(RING)
    path = _scene(tmp_path, '[system]\nfile = "ring.toml"\n',
                  'q = { x = 1.0, y = 0.0, z = "cos(a)", w = "sin(a)" }\nq_dot = { z = "-sin(a)", w = "cos(a)" }',
                  "dt = 0.01\nt_end = 0.5\nsamples = 6",
                  'grid = { a = [0.3, 1.2, 3] }\nreductions = ["final", "constraint_error"]')
    scene = load_ensemble_scene(path)
    analysed = analysed_system(scene)
    assert analysed.variable_names[4] == "lambda_1" and analysed.dimension == 10
    values = scene.source.members(0, 3)
    first, second = analysed_initial_states(scene, analysed, values), analysed_initial_states(scene, analysed, values)
    assert all(np.array_equal(u, v) for u, v in zip(first, second))
    assert run_ensemble(path, tmp_path / "out").complete
    stored = _arrays(tmp_path / "out")
    assert stored["final_q"].shape == (3, 4) and stored["final_p"].shape == (3, 4)
    assert np.all(stored["constraint_error"] <= 1e-10) and np.all(stored["failures"] == 0)
    single_system = type(analysed).from_lagrangian(load_system(tmp_path / "ring.toml"))
    for i, a in enumerate(stored["a"]):
        z0 = single_system.initial_state({"x": 1.0, "y": 0.0, "z": np.cos(a), "w": np.sin(a)},
                                         q_dot={"x": 0.0, "y": 0.0, "z": -np.sin(a), "w": np.cos(a)}, seed=0)
        single = integrate(AnalysedProblem(single_system, z0), "midpoint", t_end=0.5, dt=0.01, samples=6, outputs=["z"])
        assert np.array_equal(single.outputs["z"][-1][:4], stored["final_q"][i])
        assert np.array_equal(single.outputs["z"][-1][5:9], stored["final_p"][i])


def test_ring_identical_local_dask_and_resumed(tmp_path):
    """An analysed ensemble with multipliers (the ring above) gives the same bits locally, on two
    dask workers (other processes: the multipliers completed there from the same start) and after
    a chunk is lost and recomputed."""
    (tmp_path / "ring.toml").write_text(RING)
    path = _scene(tmp_path, '[system]\nfile = "ring.toml"\n',
                  'q = { x = "b", y = 0.0, z = "cos(a)", w = "sin(a)" }\nq_dot = { z = "-sin(a)", w = "cos(a)" }',
                  "dt = 0.01\nt_end = 0.3\nsamples = 4",
                  'grid = { a = [0.3, 1.2, 2], b = [0.5, 1.0, 2] }\nchunk_size = 2\nreductions = ["final"]')
    assert run_ensemble(path, tmp_path / "local").complete
    reference = _arrays(tmp_path / "local")
    assert run_ensemble(path, tmp_path / "dask", cluster="local", n_workers=2).complete
    other = _arrays(tmp_path / "dask")
    for name in ("final_q", "final_p"):
        assert np.array_equal(other[name], reference[name])
    out = tmp_path / "local"
    (out / "chunks" / "chunk-000001.json").unlink()
    zarr.open_array(str(out / "data.zarr"), path="final_q", mode="r+")[2:4] = 123.0
    report = run_ensemble(path, out)
    assert report.complete and report.chunks_computed == 1
    assert np.array_equal(_arrays(out)["final_q"], reference["final_q"])


def test_members_are_completed_once_with_the_same_bits(tmp_path, monkeypatch):
    """A local run completes each member's initial state once (the check before anything is
    written keeps the states for the chunks, as projected ones are), and stores the same bits as
    chunks that complete them again (as a dask worker or a resumed run does)."""
    from dirac.ensemble.general_chunk import _PROJECTED, compute_general_chunk
    from dirac.ensemble.scene import load_ensemble_scene
    from dirac.flows.analysed import AnalysedSystem

    calls = []
    complete = AnalysedSystem.initial_state

    def counted(self, *args, **kwargs):
        calls.append(1)
        return complete(self, *args, **kwargs)

    monkeypatch.setattr(AnalysedSystem, "initial_state", counted)
    path = _scene(tmp_path, VELOCITY_LINEAR, 'q = { x = "A", y = 0.0, z = "A/2" }', "dt = 0.01\nt_end = 0.3",
                  'grid = { A = [0.5, 2.0, 5] }\nchunk_size = 2\nreductions = ["final"]')
    assert run_ensemble(path, tmp_path / "out").complete
    assert len(calls) == 5 and not _PROJECTED
    stored = _arrays(tmp_path / "out")
    scene = load_ensemble_scene(path)
    for start, stop in ((0, 2), (2, 4), (4, 5)):
        again = compute_general_chunk(scene, start, stop)
        for name in ("final_q", "final_p"):
            assert np.array_equal(again[name], stored[name][start:stop])
    assert len(calls) == 10
