"""Impulses (``[[impulses]]``) in ensembles of Lagrangian systems: members equal single runs to
the last bit, a kicked free particle and a blow on a hanging pendulum against their closed
forms, what the reductions see at a kick, the same store locally and on dask, and bad input."""

from __future__ import annotations

import numpy as np
import pytest
from ensemble_stores import damped_pendulum
from ensemble_stores import run_ensemble_cli as _cli
from ensemble_stores import scene_file as _scene
from ensemble_stores import stored_arrays as _arrays

from dirac.ensemble.engine import run_ensemble

CARTESIAN_Q = '{ x1 = "sin(a)", y1 = "-cos(a)", x2 = "sin(a) + sin(b)", y2 = "-cos(a) - cos(b)" }'

#: dt = 0.5/72 (the sample spacing 0.5 cut into 72 steps): inside a step (cut in two), on a step
#: boundary (0.25 = 36 steps), on a sample time (0.5), two inside one step, two at one time
#: inside a step, and at t_end (after the last step)
IMPULSES = [(0.3001, {"x2": 0.5}), (0.25, {"y1": 0.4}), (0.5, {"x1": -0.3}), (0.70001, {"x1": 0.1}),
            (0.70003, {"x2": -0.2}), (0.8101, {"y2": 0.2}), (0.8101, {"x2": 0.3}), (1.0, {"x1": 0.3})]

DAMPED = damped_pendulum(1.2)

PARTICLE = """[system]
name = "particle"
coordinates = ["x"]
parameters = { m = 1.0 }
lagrangian = "m*x_dot**2/2"
"""


def _impulse_tables(impulses) -> str:
    return "".join(f"\n[[impulses]]\nt = {t!r}\nQ = {{ {', '.join(f'{k} = {v!r}' for k, v in J.items())} }}\n"
                   for t, J in impulses)


def test_members_with_impulses_equal_single_runs(tmp_path, monkeypatch):
    """A single run cuts its steps at each impulse (ImpulsesBetweenSteps.step: pieces from the grid
    point to the impulse, between impulses, to the next grid point; a kick between two steps for
    one on a grid point, or at the end of a call), in calls of at most CHUNK_STEPS steps (37
    here, so that calls end inside the sample intervals). A member with the same impulses
    equals dirac.integrate of the ForcedProblem of its initial state to the last bit, on the
    double pendulum with two rods (the kick projected on the constraints) under rattle-2 and
    rattle-4, and on a forced, time-dependent pendulum (the pieces' times enter the force);
    its energy error is the single run's max |E - W - (E - W)(0)|, W counting each impulse's work."""
    import dirac.flows.integration as integration
    from dirac.flows import ForcedProblem, MechanicalSystem, integrate
    from dirac.model.systems import load_system

    monkeypatch.setattr(integration, "CHUNK_STEPS", 37)
    monkeypatch.setattr(integration, "MIN_CHUNK_STEPS", 10)
    dt = 0.5 / 72
    mechanics = MechanicalSystem.from_lagrangian(load_system("double_pendulum"), with_forces=True)
    for method in ("rattle-2", "rattle-4"):
        path = _scene(tmp_path, '[system]\nname = "double_pendulum"\n', f"q = {CARTESIAN_Q}",
                      f'method = "{method}"\ndt = {dt!r}\nt_end = 1.0\nsamples = 3',
                      'grid = { a = [-2.0, 2.5, 3], b = [0.5, 1.0, 2] }\nreductions = ["final", "energy_error"]'
                      + _impulse_tables(IMPULSES), name=f"{method}.toml")
        assert run_ensemble(path, tmp_path / method).complete
        stored = _arrays(tmp_path / method)
        assert np.all(stored["failures"] == 0) and np.all(stored["steps"] == 144)
        for i in range(6):
            a, b = stored["a"][i], stored["b"][i]
            q0 = np.array([np.sin(a), -np.cos(a), np.sin(a) + np.sin(b), -np.cos(a) - np.cos(b)])
            single = integrate(ForcedProblem(mechanics, q0, np.zeros(4), impulses=IMPULSES), method, t_end=1.0, dt=dt,
                               samples=3, outputs=["q", "p", "energy", "work"])
            assert np.array_equal(single.outputs["q"][-1], stored["final_q"][i])
            assert np.array_equal(single.outputs["p"][-1], stored["final_p"][i])
            balance = single.outputs["energy"] - single.outputs["work"]
            assert stored["energy_error"][i] == pytest.approx(np.max(np.abs(balance - balance[0])), rel=1e-9, abs=1e-15)
    (tmp_path / "damped.toml").write_text(DAMPED)
    kicks = [(0.3001, {"th": 0.7}), (0.5, {"th": -0.4}), (0.61, {"th": 0.2})]
    path = _scene(tmp_path, '[system]\nfile = "damped.toml"\nparameters = { w = "1 + s" }\n',
                  'q = { th = 0.3 }\nq_dot = { th = "s" }', f"dt = {dt!r}\nt_end = 1.0\nsamples = 5",
                  'grid = { s = [0.0, 1.0, 3] }\nreductions = ["final"]' + _impulse_tables(kicks), name="damped.toml.scene")
    assert run_ensemble(path, tmp_path / "damped").complete
    stored = _arrays(tmp_path / "damped")
    for i, s in enumerate(stored["s"]):
        forced = MechanicalSystem.from_lagrangian(load_system(tmp_path / "damped.toml"), {"w": 1 + s}, with_forces=True)
        single = integrate(ForcedProblem(forced, np.array([0.3]), np.array([s]), impulses=kicks), "rattle-2", t_end=1.0,
                           dt=dt, samples=5, outputs=["q", "p"])
        assert np.array_equal(single.outputs["q"][-1], stored["final_q"][i])
        assert np.array_equal(single.outputs["p"][-1], stored["final_p"][i])


#: kicks of a free particle: inside a step, two inside another, one on a grid point
PARTICLE_KICKS = [(0.5001, {"x": 1.0}), (0.73, {"x": -0.5}), (0.7342, {"x": 0.25}), (1.2, {"x": 0.125})]


def _particle_run(tmp_path, name: str) -> dict:
    (tmp_path / "particle.toml").write_text(PARTICLE)
    path = _scene(tmp_path, '[system]\nfile = "particle.toml"\nparameters = { m = "mass" }\n',
                  'q = { x = -1.0 }\nq_dot = { x = "v" }', "dt = 0.01\nt_end = 1.5\nsamples = 4",
                  'grid = { v = [0.5, 1.0, 3], mass = [1.0, 2.0, 2] }\nreductions = ["final", "energy_error"]'
                  + _impulse_tables(PARTICLE_KICKS), name=f"scene-{name}.toml")
    assert run_ensemble(path, tmp_path / name).complete
    return _arrays(tmp_path / name)


def _particle_closed_form(stored: dict) -> tuple[np.ndarray, np.ndarray]:
    """x(T) = x0 + v0 T + sum_i J_i (T - t_i) / m and p(T) = m v0 + sum_i J_i, by hand (free motion
    between the blows, each changing the velocity by J_i / m)."""
    T, v, m = 1.5, stored["v"], stored["mass"]
    x = -1.0 + v * T + sum(J["x"] * (T - t) for t, J in PARTICLE_KICKS) / m
    return x, m * v + sum(J["x"] for _, J in PARTICLE_KICKS)


def test_a_kicked_free_particle_lands_where_the_hand_says(tmp_path):
    """The steps are exact for free motion, so the kicks at their own times give the closed form
    to rounding; E - W stays E(0) (each kick's work is its jump of m v^2 / 2)."""
    stored = _particle_run(tmp_path, "particle")
    x, p = _particle_closed_form(stored)
    assert np.allclose(stored["final_q"][:, 0], x, rtol=0, atol=1e-13)
    assert np.allclose(stored["final_p"][:, 0], p, rtol=0, atol=1e-13)
    assert np.all(stored["energy_error"] < 1e-13)


def test_a_kick_applied_at_the_start_of_its_step_is_caught(tmp_path, monkeypatch):
    """The check above can fail: a member loop that kicks an in-step impulse at the start of its
    step (the cut step run whole after the kick) lands J (t_i - t_step) / m away from the
    closed form, which the particle's x(T) shows."""
    import dirac.ensemble.general_kernel as general_kernel
    import dirac.ensemble.impulse_plan as impulse_plan
    from dirac.flows.methods.forced import Advance, Kick

    original = impulse_plan.plan_call

    def kick_at_step_start(start, n_steps, dt, times):
        plan, used = original(start, n_steps, dt, times)
        moved: list = []
        for piece in plan:
            if isinstance(piece, Kick) and moved and isinstance(moved[-1], Advance) and moved[-1].size < dt:
                cut = moved.pop()
                moved += [Kick(piece.impulse, cut.base), cut]
            else:
                moved.append(piece)
        return moved, used

    monkeypatch.setattr(impulse_plan, "plan_call", kick_at_step_start)
    monkeypatch.setattr(general_kernel, "_CACHE", {})  # not the loop of the same scene built by another test
    stored = _particle_run(tmp_path, "mutated")
    x, _ = _particle_closed_form(stored)
    assert np.max(np.abs(stored["final_q"][:, 0] - x)) > 1e-6


def test_reductions_across_a_kick(tmp_path):
    """A particle from x = -1 with v = 1 (m = 1), kicked by J = 1 at t = 0.5001 (inside a step):
    x = 0 at t = 0.5001 + 0.4999 / 2 = 0.75005 (free motion, located exactly on the straight
    line). A kick J = -4 at t = 1.2001 reverses the velocity 2 -> -2: x_dot changes sign at the
    kick itself, a first crossing at t = 1.2001 exactly (its when condition x > 0 holds there).
    A kick J = 3 at t = 1.4001 makes x_dot jump upward across 0 (-2 -> 1): no Poincare point
    (no state lies on x_dot = 0). A kick J = 10 at t_end = 1.5 gives x_dot = 11 in the final
    state only: max sees the state after a kick, min the -2 after the reversal."""
    (tmp_path / "particle.toml").write_text(PARTICLE)
    path = _scene(tmp_path, '[system]\nfile = "particle.toml"\n', 'q = { x = -1.0 }\nq_dot = { x = "v" }',
                  "dt = 0.01\nt_end = 1.5\nsamples = 4",
                  'grid = { v = [1.0, 1.0, 1] }\nreductions = [\n'
                  '  { kind = "first_crossing", name = "arrive", expr = "x" },\n'
                  '  { kind = "first_crossing", name = "turn", expr = "x_dot", when = "x > 0" },\n'
                  '  { kind = "poincare", name = "section", expr = "x", count = 2 },\n'
                  '  { kind = "poincare", name = "stall", expr = "x_dot", count = 1 },\n'
                  '  { kind = "max", name = "fastest", expr = "x_dot" }, { kind = "min", name = "slowest", expr = "x_dot" },\n'
                  ']' + _impulse_tables([(0.5001, {"x": 1.0}), (1.2001, {"x": -4.0}), (1.4001, {"x": 3.0}), (1.5, {"x": 10.0})]))
    assert run_ensemble(path, tmp_path / "out").complete
    stored = _arrays(tmp_path / "out")
    assert stored["arrive"][0] == pytest.approx(0.75005, abs=1e-12)
    assert stored["turn"][0] == 1.2001
    assert stored["section_t"][0, 0] == pytest.approx(0.75005, abs=1e-12)
    assert abs(stored["section_q"][0, 0, 0]) < 1e-12 and np.isnan(stored["section_t"][0, 1])
    assert np.isnan(stored["stall_t"][0, 0])
    assert stored["fastest"][0] == pytest.approx(11.0, abs=1e-13)
    assert stored["slowest"][0] == pytest.approx(-2.0, abs=1e-14)


def test_a_blow_on_a_hanging_pendulum_gives_its_kinetic_energy(tmp_path):
    """A pendulum (x, y, x^2 + y^2 = 1) hanging at rest, a horizontal blow J = 0.6 on its bob at
    t = 0.3001 (inside a step): the projected kick is all of J (horizontal, along the circle), so
    right after it the kinetic energy is J^2 / (2 m), its largest value along the swing (Lamb,
    Higher Mechanics, Sect. 27); the bob rises to y = -1 + J^2 / (2 m^2 g) (energy), and E - W
    stays at E(0) = -m g."""
    path = _scene(tmp_path, '[system]\nname = "pendulum"\nparameters = { m = "mass" }\n',
                  'q = { x = 0.0, y = -1.0 }', "dt = 0.001\nt_end = 2.0\nsamples = 5",
                  'grid = { mass = [1.0, 3.0, 3] }\nreductions = [\n'
                  '  { kind = "max", name = "kinetic", expr = "m*(x_dot**2 + y_dot**2)/2" },\n'
                  '  { kind = "max", name = "height", expr = "y" }, "energy_error",\n]'
                  + _impulse_tables([(0.3001, {"x": 0.6})]))
    assert run_ensemble(path, tmp_path / "out").complete
    stored = _arrays(tmp_path / "out")
    mass = stored["mass"]
    assert np.allclose(stored["kinetic"], 0.36 / (2 * mass), rtol=1e-12, atol=0)
    assert np.allclose(stored["height"], -1.0 + 0.36 / (2 * mass**2 * 9.81), rtol=0, atol=1e-5)
    assert np.all(stored["energy_error"] < 1e-5)


def test_kicked_ensemble_identical_local_and_dask(tmp_path, run_cli):
    """The store of a scene with impulses does not depend on where it is computed: the same
    arrays, bit for bit, from dirac ensemble run locally and with --cluster local --workers 2
    (two worker processes)."""
    path = _scene(tmp_path, '[system]\nname = "double_pendulum"\n', f"q = {CARTESIAN_Q}",
                  "dt = 0.01\nt_end = 1.0\nsamples = 3",
                  'grid = { a = [-2.0, 2.0, 4], b = [0.5, 1.0, 2] }\nchunk_size = 3\nreductions = ["final", '
                  '"energy_error", { kind = "first_crossing", name = "swing", expr = "x2_dot" }]'
                  + _impulse_tables(IMPULSES[:4]))
    status, _, stderr = run_cli("ensemble", str(path), "--out", str(tmp_path / "local"), "--no-progress")
    assert status == 0, stderr
    status, stdout, stderr = run_cli("ensemble", str(path), "--out", str(tmp_path / "dask"), "--cluster", "local",
                                     "--workers", "2", "--no-progress")
    assert status == 0 and "computed 3 chunks" in stdout, stderr
    local, dask = _arrays(tmp_path / "local"), _arrays(tmp_path / "dask")
    assert set(local) == set(dask)
    for name in local:
        assert np.array_equal(local[name], dask[name], equal_nan=True), name


@pytest.mark.parametrize("impulse, message", [
    ('t = 0.05\nQ = { x2 = "a" }', "the impulses of an ensemble are numbers, the same for every member"),
    ("t = 0.05\nQ = { xx2 = 1.0 }", "unknown coordinate 'xx2' (did you mean 'x2'?)"),
    ("t = 0.0\nQ = { x2 = 1.0 }", "give t > 0 (a blow at the start is an initial velocity)"),
    ("t = 0.05\nangular_impulse = [1.0, 0.0, 0.0]", "unknown key 'angular_impulse'; known keys: Q, t"),
])
def test_bad_impulses_are_refused_before_anything_is_written(tmp_path, impulse, message):
    path = _scene(tmp_path, '[system]\nname = "double_pendulum"\n', f"q = {CARTESIAN_Q}", "dt = 0.01\nt_end = 0.1",
                  'grid = { a = [0.0, 1.0, 2], b = [0.0, 1.0, 2] }\nreductions = ["final"]\n'
                  f"[[impulses]]\n{impulse}\n")
    result = _cli(path, tmp_path / "out")
    assert result.returncode == 2, result.stderr
    assert result.stderr.startswith("error: ") and message in result.stderr and len(result.stderr.splitlines()) == 1
    assert not (tmp_path / "out").exists()


def test_impulses_on_a_system_run_on_its_analysis_are_refused(tmp_path):
    """A velocity-linear Lagrangian runs on the Dirac flow of its analysis, where a single scene
    refuses impulses (they are integrated for L = 1/2 q_dot^T M q_dot - V only): so does an ensemble."""
    path = _scene(tmp_path, '[system]\nname = "velocity_linear"\ncoordinates = ["x", "y", "z"]\n'
                  'lagrangian = "x*y_dot - (x**2 + y**2)/2 + z_dot**2/2 - z**2/2"\n',
                  'q = { x = "a", y = 0.0, z = 0.0 }', "dt = 0.01\nt_end = 0.1",
                  'grid = { a = [0.0, 1.0, 2] }\nreductions = ["final"]\n[[impulses]]\nt = 0.05\nQ = { z = 1.0 }\n')
    result = _cli(path, tmp_path / "out")
    assert result.returncode == 2, result.stderr
    assert result.stderr.startswith("error: forces and impulses are integrated for L = 1/2 q_dot^T M(q) q_dot - V(q) only")
    assert not (tmp_path / "out").exists()


def test_conformal_members_with_impulses_equal_single_runs(tmp_path):
    """Under linear damping the conformal splitting (exact damping, RATTLE, damping) is cut at the
    impulses as forced RATTLE is: members equal single conformal-2 runs to the last bit."""
    from dirac.flows import ForcedProblem, MechanicalSystem, integrate
    from dirac.model.systems import load_system

    (tmp_path / "damped.toml").write_text(DAMPED.replace(' + F*cos(w*t)"', '"'))
    kicks = [(0.3001, {"th": 0.7}), (0.5, {"th": -0.4}), (0.61, {"th": 0.2}), (0.6133, {"th": 0.1})]
    path = _scene(tmp_path, '[system]\nfile = "damped.toml"\n', 'q = { th = 0.3 }\nq_dot = { th = "s" }',
                  'method = "conformal-2"\ndt = 0.01\nt_end = 1.0\nsamples = 5',
                  'grid = { s = [0.0, 1.0, 3] }\nreductions = ["final"]' + _impulse_tables(kicks), name="conformal.toml")
    assert run_ensemble(path, tmp_path / "out").complete
    stored = _arrays(tmp_path / "out")
    mechanics = MechanicalSystem.from_lagrangian(load_system(tmp_path / "damped.toml"), with_forces=True)
    assert mechanics.conformal_rate == 0.5
    for i, s in enumerate(stored["s"]):
        single = integrate(ForcedProblem(mechanics, np.array([0.3]), np.array([s]), impulses=kicks), "conformal-2",
                           t_end=1.0, dt=0.01, samples=5, outputs=["q", "p"])
        assert np.array_equal(single.outputs["q"][-1], stored["final_q"][i])
        assert np.array_equal(single.outputs["p"][-1], stored["final_p"][i])
