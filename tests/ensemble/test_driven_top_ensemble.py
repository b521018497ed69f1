"""Ensembles of heavy tops driven by a torque (``[forces] torque``): members equal single
driven runs to the last bit, a spin-up against its closed form, the energy balance
``E - W``, members whose torque kick fails, and refused bad input."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
import zarr

from dirac.ensemble.engine import run_ensemble

DRIVEN = """[system]
name = "heavy_top"
inertia = [1.0, "b", 0.6]
mass_gravity = 1.5
center_of_mass = [0.3, 0.0, 1.0]

[forces]
torque = ["-0.2*Omega_1 + 0.1*sin(3*t)", "-0.2*Omega_2", "0.05*R_31 - 0.2*Omega_3"]

[initial]
omega = [0.3, "w", 2.0]
R = [[1.0, 0.0, 0.0], [0.0, "cos(0.4)", "-sin(0.4)"], [0.0, "sin(0.4)", "cos(0.4)"]]

[run]
method = "lie-poisson-4"
dt = 0.007
t_end = 2.0
samples = 5

[ensemble]
grid = { b = [0.8, 1.4, 3], w = [-0.5, 0.5, 2] }
reductions = ["final", "energy_error", "constraint_error"]
"""


def _arrays(out) -> dict[str, np.ndarray]:
    group = zarr.open_group(str(out / "data.zarr"), mode="r")
    return {name: np.asarray(group[name][:]) for name in group.array_keys()}


def _tilted(angle: float) -> np.ndarray:
    return np.array([[1.0, 0.0, 0.0], [0.0, np.cos(angle), -np.sin(angle)], [0.0, np.sin(angle), np.cos(angle)]])


def _single(method: str, b: float, w: float, torque: list[str], t_end: float = 2.0, samples: int = 5):
    from dirac.flows import integrate
    from dirac.flows.problems import HeavyTopProblem

    inertia = np.array([1.0, b, 0.6])
    problem = HeavyTopProblem(inertia, inertia * np.array([0.3, w, 2.0]), _tilted(0.4), mass_gravity=1.5,
                              center_of_mass=[0.3, 0.0, 1.0], torque=torque)
    return integrate(problem, method, t_end=t_end, dt=0.007, samples=samples, outputs=["M", "R", "energy", "work"])


TORQUE = ["-0.2*Omega_1 + 0.1*sin(3*t)", "-0.2*Omega_2", "0.05*R_31 - 0.2*Omega_3"]


@pytest.mark.parametrize("method", ["lie-poisson-4", "exact-kick-4"])
def test_driven_members_equal_single_runs(tmp_path, method, monkeypatch):
    """A member's final state is dirac.integrate's on a driven HeavyTopProblem of the same
    initial state to the last bit: the same torque kick (implicit midpoint here: the torque
    depends on Omega; and on t and R), not merged, with the time of a call's steps counted
    from the end of the call before, in calls of 37 steps (72 steps of 0.5/72 per sample
    interval: 37 + 35) in both runs. The energy error
    is the single run's max |E - W - E(0)| over the samples (W the torque's work)."""
    import dirac.flows.integration as integration

    monkeypatch.setattr(integration, "CHUNK_STEPS", 37)
    monkeypatch.setattr(integration, "MIN_CHUNK_STEPS", 10)
    path = tmp_path / "driven.toml"
    path.write_text(DRIVEN.replace('"lie-poisson-4"', f'"{method}"'))
    assert run_ensemble(path, tmp_path / "out").complete
    stored = _arrays(tmp_path / "out")
    assert np.all(stored["failures"] == 0) and np.all(stored["steps"] == 288)
    for i in range(6):
        single = _single(method, float(stored["b"][i]), float(stored["w"][i]), TORQUE)
        assert np.array_equal(single.outputs["M"][-1], stored["final_M"][i])
        assert np.array_equal(single.outputs["R"][-1], stored["final_R"][i])
        balance = single.outputs["energy"] - single.outputs["work"]
        assert stored["energy_error"][i] == pytest.approx(np.max(np.abs(balance - balance[0])), rel=1e-9, abs=1e-15)
        # the damping does work: E alone is not conserved, E - W is to the method's error
        assert abs(single.outputs["work"][-1]) > 1e-2 and stored["energy_error"][i] < 1e-6
    assert np.max(stored["constraint_error"]) < 1e-12


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


def test_a_member_whose_kick_fails_is_marked_and_the_rest_complete(tmp_path):
    """With one Newton iteration allowed, the midpoint kick of a torque that depends on Omega
    cannot confirm convergence (its first correction is the whole step's): every member of
    that scene fails with code 1 (Newton), as a single run raises. A torque free of M and
    Omega is an exact kick (no Newton iteration), so the same limit fails nobody."""
    from dirac.errors import IntegrationError

    failing = DRIVEN.replace('samples = 5', 'samples = 5\nmax_newton_iterations = 1')
    path = tmp_path / "fail.toml"
    path.write_text(failing)
    assert run_ensemble(path, tmp_path / "out").complete
    stored = _arrays(tmp_path / "out")
    assert np.all(stored["failures"] == 1.0)
    assert np.all(np.isnan(stored["energy_error"])) and np.all(np.isnan(stored["final_M"]))
    from dirac.flows import integrate
    from dirac.flows.problems import HeavyTopProblem

    problem = HeavyTopProblem([1.0, 0.8, 0.6], [0.3, -0.4, 1.2], _tilted(0.4), mass_gravity=1.5,
                              center_of_mass=[0.3, 0.0, 1.0], torque=TORQUE)
    with pytest.raises(IntegrationError, match="did not converge in 1 Newton"):
        integrate(problem, "lie-poisson-4", t_end=2.0, dt=0.007, samples=5, max_newton_iterations=1)

    exact_kick = failing.replace(TORQUE_TEXT, '["0.1*sin(3*t)", "0", "0.05*R_31"]')
    path.write_text(exact_kick)
    assert run_ensemble(path, tmp_path / "out2").complete
    assert np.all(_arrays(tmp_path / "out2")["failures"] == 0.0)


TORQUE_TEXT = '["-0.2*Omega_1 + 0.1*sin(3*t)", "-0.2*Omega_2", "0.05*R_31 - 0.2*Omega_3"]'


def _cli(scene, out):
    return subprocess.run([sys.executable, "-m", "dirac", "ensemble", str(scene), "--out", str(out), "--no-progress"],
                          capture_output=True, text=True, timeout=300)


@pytest.mark.parametrize("change, message", [
    (('"-0.2*Omega_2"', '"-0.2*Omega2 + b"'), "unknown name 'b'"),  # an ensemble variable in a torque
    (('"-0.2*Omega_2"', '"-0.2*Omga_2"'), "did you mean 'Omega_2'"),  # a misspelt torque variable
    (("torque = [", "torqe = ["), "did you mean 'torque'"),
    (('"0.05*R_31 - 0.2*Omega_3"]', '"0.05*R_31 - 0.2*Omega_3", "0"]'), "must be three expressions"),
])
def test_bad_torques_are_refused_before_anything_is_written(tmp_path, change, message):
    path = tmp_path / "bad.toml"
    assert change[0] in DRIVEN
    path.write_text(DRIVEN.replace(*change))
    _refused(path, tmp_path / "out", message)


def test_impulses_are_still_refused_with_the_way_out(tmp_path):
    path = tmp_path / "kicked.toml"
    path.write_text(DRIVEN + '\n[[impulses]]\nt = 1.0\nM = [0.0, 0.0, 1.0]\n')
    _refused(path, tmp_path / "out", "[[impulses]] are not available in heavy-top ensembles")


def _refused(path, out, message):
    result = _cli(path, out)
    assert result.returncode == 2, result.stderr
    assert result.stderr.startswith("error: ") and message in result.stderr and len(result.stderr.splitlines()) == 1
    assert not out.exists()
