"""Members of a general ensemble that step across a pole of their equations of motion fail with code 4.

``L = x_dot^2/2 - log(x)`` from ``x0`` at rest reaches the pole ``x = 0`` of the force ``-1/x`` at
``t* = x0 sqrt(pi/2)`` (by hand: ``v^2/2 = log(x0/x)``, ``t* = integral_0^{x0} dx / sqrt(2 log(x0/x))``,
and ``x = x0 e^{-u}`` turns it into ``x0 Gamma(1/2)/sqrt(2)``; tests/flows/test_pole_guard.py checks it by
quadrature): ``0.627`` for ``x0 = 0.5``, ``1.57`` for ``x0 = 1.25`` and ``2.51`` for ``x0 = 2``. Up to ``t = 1``
only the first member meets the pole; its fixed steps used to jump over it and the member completed
with an energy jump larger than its energy.
"""

from __future__ import annotations

import json

import numpy as np
from ensemble_stores import scene_file, stored_arrays

from dirac.ensemble.engine import run_ensemble
from dirac.ensemble.general_kernel import FAILURES


def test_a_member_over_the_pole_fails_with_its_reason(tmp_path):
    """The member ``x0 = 0.5`` fails with code 4 (its reductions NaN, its steps stopping in the step
    that crossed, near ``t* / dt = 62.7``); ``x0 = 1.25`` and ``x0 = 2`` complete with ``x > 0`` and an
    energy error below 1e-2 (RATTLE's error away from the pole), where the crossing member's jump was above 1."""
    (tmp_path / "well.toml").write_text(
        '[system]\nname = "log_well"\ncoordinates = ["x"]\nlagrangian = "x_dot**2/2 - log(x)"\n')
    path = scene_file(tmp_path, '[system]\nfile = "well.toml"\n', 'q = { x = "x0" }\nq_dot = { x = 0.0 }',
                      'method = "rattle-2"\ndt = 0.01\nt_end = 1.0\nsamples = 11',
                      'grid = { x0 = [0.5, 2.0, 3] }\nreductions = ["final", "energy_error"]')
    assert run_ensemble(path, tmp_path / "out").complete
    stored = stored_arrays(tmp_path / "out")
    assert np.array_equal(stored["x0"], [0.5, 1.25, 2.0])
    assert np.array_equal(stored["failures"], [4.0, 0.0, 0.0])
    assert np.isnan(stored["final_q"][0]).all() and np.isnan(stored["energy_error"][0])
    assert 60 <= stored["steps"][0] <= 64
    assert np.all(stored["final_q"][1:, 0] > 0.0)
    assert np.all(stored["energy_error"][1:] < 1e-2)
    meta = json.loads((tmp_path / "out" / "meta.json").read_text())
    assert meta["failure_codes"]["4"] == FAILURES[4] and "pole" in FAILURES[4]
