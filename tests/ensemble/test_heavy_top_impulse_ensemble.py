"""Heavy-top ensembles with impulses and torques of closed form: a spin-up against its closed
form, members with angular impulses equal single runs to the last bit, a driven free body as a
heavy top without weight, reductions across an impulse's jump. (Free tops are in
test_heavy_top_ensemble.py, driven members in test_heavy_top_driven_ensemble.py.)"""

from __future__ import annotations

import numpy as np
import pytest
from ensemble_stores import stored_arrays as _arrays
from heavy_tops import DRIVEN, TORQUE, TORQUE_TEXT
from heavy_tops import refused as _refused
from heavy_tops import single_driven as _single

from dirac.ensemble.engine import run_ensemble


def test_a_constant_spin_torque_spins_up_a_symmetric_top_at_its_rate(tmp_path):
    """A symmetric top (I_1 = I_2) with its centre of mass on its axis (chi = (0, 0, l)) under a
    body torque N = (0, 0, k): the third Euler-Poisson equation is
    dM_3/dt = (M x Omega)_3 + m g (gamma x chi)_3 + N_3 = M_1 M_2 (1/I_2 - 1/I_1) + m g (gamma_1 chi_2 - gamma_2 chi_1) + k = k,
    so M_3(t) = M_3(0) + k t, whatever the nutation. The exact free flow keeps M_3 of a
    symmetric body and the exact kick adds tau k: the largest M_3 over the run and the final
    M_3 are M_3(0) + k T to rounding."""
    path = tmp_path / "spin.toml"
    path.write_text("""[system]
name = "heavy_top"
inertia = [1.0, 1.0, 2.0]
mass_gravity = 1.0
center_of_mass = [0.0, 0.0, 0.5]

[forces]
torque = ["0", "0", "0.25"]

[initial]
M = [0.1, 0.0, "m3"]
R = [[1.0, 0.0, 0.0], [0.0, "cos(0.1)", "-sin(0.1)"], [0.0, "sin(0.1)", "cos(0.1)"]]

[run]
method = "exact-kick-4"
dt = 0.01
t_end = 4.0
samples = 5

[ensemble]
grid = { m3 = [1.0, 3.0, 5] }
reductions = [{ kind = "max", name = "top_spin", expr = "M3" }, "final"]
""")
    assert run_ensemble(path, tmp_path / "out").complete
    stored = _arrays(tmp_path / "out")
    expected = stored["m3"] + 0.25 * 4.0
    assert np.allclose(stored["top_spin"], expected, rtol=0.0, atol=1e-12)
    assert np.allclose(stored["final_M"][:, 2], expected, rtol=0.0, atol=1e-12)
    assert np.all(np.abs(stored["final_M"][:, :2]) > 1e-3)  # the top nutates: M_1, M_2 are not trivially zero


#: impulses at t = 0, inside a step (cut in two), on a step boundary (0.5 = 72 steps of 0.5/72),
#: two inside one step, and at t_end (after the last step of the last call)
IMPULSES = [(0.0, [0.0, 0.0, 0.3]), (0.3001, [0.2, -0.1, 0.0]), (0.5, [0.0, 0.4, 0.0]),
            (1.20001, [0.1, 0.0, 0.0]), (1.20003, [0.0, 0.0, -0.2]), (2.0, [0.5, 0.5, 0.5])]


@pytest.mark.parametrize("method, torque", [("lie-poisson-4", True), ("exact-kick-4", False)])
def test_members_with_impulses_equal_single_runs(tmp_path, method, torque, monkeypatch):
    """Angular impulses cut a single run's steps at their times (TorquedStepper.step): a member
    with the same impulses equals dirac.integrate of the driven HeavyTopProblem to the last bit,
    with a torque and with impulses alone (a zero torque, as a single run), in calls of 37 steps;
    its energy error is the single run's max |E - W - (E - W)(0)|, W counting each impulse's jump
    of the kinetic energy. An impulse at t = 0 acts on the initial state."""
    import dirac.flows.integration as integration

    monkeypatch.setattr(integration, "CHUNK_STEPS", 37)
    monkeypatch.setattr(integration, "MIN_CHUNK_STEPS", 10)
    scene = DRIVEN.replace('"lie-poisson-4"', f'"{method}"').replace("reductions = [", "reductions = [{ kind = \"max\", name = \"spin\", expr = \"M_3\" }, ")
    if not torque:
        scene = scene.replace(f"[forces]\ntorque = {TORQUE_TEXT}\n", "")
    scene += "".join(f"\n[[impulses]]\nt = {t}\nangular_impulse = {vector}\n" for t, vector in IMPULSES)
    path = tmp_path / "kicked.toml"
    path.write_text(scene)
    assert run_ensemble(path, tmp_path / "out").complete
    stored = _arrays(tmp_path / "out")
    assert np.all(stored["failures"] == 0)
    for i in range(6):
        single = _single(method, float(stored["b"][i]), float(stored["w"][i]), TORQUE if torque else None,
                         impulses=IMPULSES)
        assert np.array_equal(single.outputs["M"][-1], stored["final_M"][i])
        assert np.array_equal(single.outputs["R"][-1], stored["final_R"][i])
        balance = single.outputs["energy"] - single.outputs["work"]
        assert stored["energy_error"][i] == pytest.approx(np.max(np.abs(balance - balance[0])), rel=1e-9, abs=1e-15)
        assert single.outputs["M"][0][2] == pytest.approx(0.6 * 2.0 + 0.3)  # M_3 = I_3 omega_3, then the jump at t = 0
        assert stored["spin"][i] >= single.outputs["M"][0][2]


def test_a_driven_free_body_runs_as_a_heavy_top_without_weight(tmp_path):
    """A rigid-body ensemble scene with [forces] is refused with the way out: a heavy top with
    mass_gravity = 0. That scene's members equal single driven RigidBodyProblem runs in M to
    the last bit (the same torque kick with a zero weight vector, around the same free step)."""
    from dirac.flows import integrate
    from dirac.flows.problems import RigidBodyProblem

    rigid = tmp_path / "rigid.toml"
    rigid.write_text('[system]\nname = "rigid_body"\ninertia = [1.0, 2.0, 3.0]\n\n[forces]\n'
                     'torque = ["0", "0", "-0.1*Omega_3"]\n\n[initial]\nM = [0.1, 1.0, 0.1]\n\n[run]\n'
                     'method = "lie-poisson-4"\ndt = 0.01\nt_end = 1.0\n\n[ensemble]\ncount = 4\nreductions = ["flip_time"]\n')
    _refused(rigid, tmp_path / "out", 'write [system] name = "heavy_top" with mass_gravity = 0')
    top = tmp_path / "top.toml"
    top.write_text('[system]\nname = "heavy_top"\ninertia = [1.0, 2.0, 3.0]\nmass_gravity = 0.0\n\n[forces]\n'
                   'torque = ["0", "0", "-0.1*Omega_3"]\n\n[initial]\nM = [0.1, "m2", 0.1]\n\n[run]\n'
                   'method = "lie-poisson-4"\ndt = 0.01\nt_end = 1.0\nsamples = 3\n\n[ensemble]\n'
                   'grid = { m2 = [0.5, 1.5, 3] }\nreductions = ["final"]\n')
    assert run_ensemble(top, tmp_path / "top").complete
    stored = _arrays(tmp_path / "top")
    for i, m2 in enumerate(stored["m2"]):
        problem = RigidBodyProblem([1.0, 2.0, 3.0], [0.1, float(m2), 0.1], torque=["0", "0", "-0.1*Omega_3"])
        single = integrate(problem, "lie-poisson-4", t_end=1.0, dt=0.01, samples=3, outputs=["M"])
        assert np.array_equal(single.outputs["M"][-1], stored["final_M"][i])


def test_reductions_see_an_impulse_as_a_jump(tmp_path):
    """A sphere (I = 1, no weight) keeps M between impulses (dM/dt = M x Omega = 0): M_3 = 1,
    then -1 after the blow (0, 0, -2) at t = 0.2537 (inside a step of 0.01), then 1 after
    (0, 0, 2) at t = 0.6 (on a step boundary). By hand: M_3 first changes sign at the first
    blow, so its first crossing is at t = 0.2537 exactly (a line across the jump would put it
    at 0.25 + 0.5 * 0.01 for the middle of the step); its `when` M_1 > 0 holds after the blow
    (M_1 = 0.3 throughout); no state of the flow lies on the section M_3 = 0 (both crossings are
    jumps), so the Poincare section is empty; max M_3 = 1 and min M_3 = -1 (the states before and
    after each blow)."""
    scene = ('[system]\nname = "heavy_top"\ninertia = [1.0, 1.0, 1.0]\nmass_gravity = 0.0\n\n[initial]\n'
             'M = [0.3, "m2", 1.0]\n\n[run]\nmethod = "lie-poisson-4"\ndt = 0.01\nt_end = 1.0\nsamples = 3\n\n'
             '[[impulses]]\nt = 0.2537\nangular_impulse = [0.0, 0.0, -2.0]\n\n'
             '[[impulses]]\nt = 0.6\nangular_impulse = [0.0, 0.0, 2.0]\n\n'
             '[ensemble]\ngrid = { m2 = [0.0, 0.0, 1] }\nreductions = [\n'
             '  { kind = "first_crossing", name = "flip", expr = "M_3", when = "M_1 > 0" },\n'
             '  { kind = "poincare", name = "section", expr = "M_3", count = 2 },\n'
             '  { kind = "max", name = "high", expr = "M_3" },\n  { kind = "min", name = "low", expr = "M_3" },\n'
             '  "final",\n]\n')
    path = tmp_path / "jumps.toml"
    path.write_text(scene)
    assert run_ensemble(path, tmp_path / "out").complete
    stored = _arrays(tmp_path / "out")
    assert stored["flip"][0] == 0.2537
    assert np.all(np.isnan(stored["section_t"][0]))
    assert stored["high"][0] == pytest.approx(1.0, abs=1e-12) and stored["low"][0] == pytest.approx(-1.0, abs=1e-12)
    # the splitting of a sphere is exact up to its O(dt^4) error (each sub-flow turns M about one axis)
    assert stored["final_M"][0] == pytest.approx([0.3, 0.0, 1.0], abs=1e-8)
