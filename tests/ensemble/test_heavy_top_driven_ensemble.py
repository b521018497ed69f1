"""Driven heavy-top ensembles (``[forces] torque``): members equal single driven runs to the last
bit, the balance E - W, members whose torque kick fails, and refused torques. (Free tops are in
test_heavy_top_ensemble.py, impulses and the spin-up in test_heavy_top_impulse_ensemble.py.)"""

from __future__ import annotations

import numpy as np
import pytest
from ensemble_stores import stored_arrays as _arrays
from heavy_tops import DRIVEN, TORQUE, TORQUE_TEXT
from heavy_tops import refused as _refused
from heavy_tops import single_driven as _single
from heavy_tops import tilted as _tilted

from dirac.ensemble.engine import run_ensemble


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

    assert TORQUE_TEXT in failing
    exact_kick = failing.replace(TORQUE_TEXT, '["0.1*sin(3*t)", "0", "0.05*R_31"]')
    path.write_text(exact_kick)
    assert run_ensemble(path, tmp_path / "out2").complete
    assert np.all(_arrays(tmp_path / "out2")["failures"] == 0.0)






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
