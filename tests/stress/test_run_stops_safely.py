"""Guard rails of ``dirac run`` end to end: a failing run stops safely and keeps its data.

A non-finite state, a Newton iteration that does not converge (RATTLE, midpoint) and
constraint drift beyond ``drift_limit`` stop the run with exit status 2 and one ``error:``
line naming the time, the step and the method; everything computed up to then is in the
output file, with ``meta["complete"] = false`` and the same message.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
from cli_output import one_error_line

from dirac.io.results import read_results

RUNAWAY = """
[system]
name = "runaway"
coordinates = ["x"]
lagrangian = "x_dot**2/2 + exp(exp(x))"   # V = -exp(exp(x)): x overflows in finite time
[initial]
q = { x = 1.0 }
[run]
t_end = 10.0
method = "rattle-2"
dt = 0.01
samples = 101
"""

PENDULUM_LOOSE_NEWTON = """
[system]
name = "pendulum"
[initial]
q = { x = 1.0, y = 0.0 }
[run]
t_end = 10.0
method = "rattle-2"
dt = 0.01
samples = 11
newton_tolerance = 1e-4    # positions kept only to 1e-4 ...
drift_limit = 1e-6         # ... so the drift guard must fire
"""

RIGID_ONE_NEWTON_STEP = """
[system]
name = "rigid_body"
inertia = [1.0, 2.0, 3.0]
[initial]
M = [1.0, 0.5, 0.2]
[run]
t_end = 10.0
method = "midpoint"
dt = 0.5
samples = 11
max_newton_iterations = 1
"""

PENDULUM_ONE_NEWTON_STEP = """
[system]
name = "pendulum"
[initial]
q = { x = 0.6, y = -0.8 }
q_dot = { x = 0.8, y = 0.6 }
[run]
t_end = 1.0
method = "rattle-2"
dt = 0.01
samples = 11
max_newton_iterations = 1
"""


@pytest.mark.parametrize(("scene", "method", "cause"), [
    (RUNAWAY, "rattle-2", "non-finite"),
    (PENDULUM_LOOSE_NEWTON, "rattle-2", "constraint drift"),
    (RIGID_ONE_NEWTON_STEP, "midpoint", "did not converge"),
    (PENDULUM_ONE_NEWTON_STEP, "rattle-2", "did not converge"),
], ids=["non-finite", "drift", "midpoint-newton", "rattle-newton"])
def test_guard_rail_stops_the_run_and_keeps_the_samples(scene, method, cause, tmp_path, run_cli):
    path = tmp_path / "scene.toml"
    path.write_text(scene)
    out = tmp_path / "out.npz"
    status, _, err = run_cli("run", str(path), "--out", str(out), "--no-progress")
    line = one_error_line(status, err)
    assert cause in line
    where = re.search(r"at t = ([0-9.eE+-]+) \(step (\d+)\) with method (\S+)", line)
    assert where is not None, line
    t_stop, step = float(where.group(1)), int(where.group(2))
    assert where.group(3).rstrip(";") == method
    arrays, meta = read_results(out)
    assert meta["complete"] is False
    assert cause in meta["message"] and meta["method"] == method
    t = arrays["t"]
    assert t.shape[0] >= 1 and t[0] == 0.0 and np.all(t <= t_stop)
    for name, values in arrays.items():
        assert values.shape[0] == t.shape[0], name
        assert np.all(np.isfinite(values)), name  # only states computed before the stop
    if cause == "did not converge":
        assert step >= 0 and t_stop < float(re.search(r"t_end = ([0-9.]+)", scene).group(1))
