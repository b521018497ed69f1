"""Guard rails of the ``integrate`` loop: non-finite states, Newton non-convergence,
constraint drift and interruption stop the run with an ``IntegrationError`` that names
the time, the step and the method, and keeps what was computed (``complete = False``)."""

from __future__ import annotations

import numpy as np
import pytest

from dirac.errors import IntegrationError
from dirac.flows import ConstrainedProblem, MechanicalSystem, RigidBodyProblem, integrate
from dirac.flows.integration import IntegrationInterrupted
from dirac.model.lagrangian import Lagrangian


def _pendulum(system, theta=1.0):
    return ConstrainedProblem(system, [np.sin(theta), -np.cos(theta)], [0.0, 0.0])


def test_non_finite_state_stops_the_run_with_partial_results():
    # V = -x^4: the particle escapes to infinity in finite time (t* ~ 0.5 from x = 2)
    escape = Lagrangian.from_strings("escape", ["x"], "x_dot**2/2 + x**4")
    problem = ConstrainedProblem(MechanicalSystem.from_lagrangian(escape), [2.0], [0.0])
    with pytest.raises(IntegrationError, match=r"non-finite values .* at t = [0-9.e+-]+ \(step \d+\) with method rattle-2") as info:
        integrate(problem, "rattle-2", t_end=5.0, dt=0.01, samples=51, outputs=["q"])
    partial = info.value.partial
    assert partial.complete is False
    assert 1 <= len(partial.t) < 51
    assert np.all(np.isfinite(partial["q"]))
    assert partial.meta()["complete"] is False


def test_newton_non_convergence_names_time_step_and_method(pendulum_system):
    with pytest.raises(IntegrationError, match=r"rattle-2: Newton iteration did not converge in 2 iterations.*"
                                                r"at t = [0-9.]+ \(step \d+\) with method rattle-2") as info:
        integrate(_pendulum(pendulum_system, 2.0), "rattle-2", t_end=5.0, dt=0.3, samples=6, outputs=["q"],
                  max_newton_iterations=2)
    partial = info.value.partial
    assert partial.complete is False and partial.message
    assert len(partial.t) >= 1 and partial.t[0] == 0.0


def test_midpoint_newton_failure_on_the_rigid_body_is_reported():
    problem = RigidBodyProblem([1.0, 2.0, 3.0], [30.0, 40.0, 25.0])
    with pytest.raises(IntegrationError, match=r"midpoint: Newton iteration did not converge.*with method midpoint"):
        integrate(problem, "midpoint", t_end=10.0, dt=2.0, samples=3, outputs=["M"], max_newton_iterations=3)


def test_constraint_drift_beyond_the_limit_stops_the_run(pendulum_system):
    with pytest.raises(IntegrationError, match=r"constraint drift .* exceeds the limit 1e-30 at t = .* with method rattle-2") as info:
        integrate(_pendulum(pendulum_system), "rattle-2", t_end=20.0, dt=0.001, samples=3, outputs=["q"],
                  drift_limit=1e-30)
    assert info.value.partial.complete is False


def test_interruption_keeps_the_samples_computed_so_far(monkeypatch):
    from dirac.flows.methods.lie_poisson import LiePoissonStepper

    calls = {"n": 0}
    original = LiePoissonStepper.step

    def step(self, n_steps, dt):
        calls["n"] += 1
        if calls["n"] == 4:
            raise KeyboardInterrupt
        return original(self, n_steps, dt)

    monkeypatch.setattr(LiePoissonStepper, "step", step)
    with pytest.raises(IntegrationInterrupted, match="interrupted at t = ") as info:
        integrate(RigidBodyProblem([1.0, 2.0, 3.0], [0.6, 0.8, 0.5]), "lie-poisson-2", t_end=10.0, dt=0.1,
                  samples=11, outputs=["M", "energy"])
    partial = info.value.partial
    assert partial.complete is False
    assert partial.t.tolist() == [0.0, 1.0, 2.0, 3.0]
    assert partial["M"].shape == (4, 3) and partial["energy"].shape == (4,)
