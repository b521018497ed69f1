"""Long runs of ``dirac bench --stress``: splittings on the standard body, RATTLE on pendulums.

* :func:`long_run`: ``lie-poisson-2``/``-4``/``-6`` for up to ``1e7`` steps on the standard
  body (:mod:`dirac.bench.standard_body`). The Casimir ``|M|^2`` and ``R^T R = 1`` of the
  Euler–Poisson flow (250)–(251) must stay within
  :data:`~dirac.bench.stress_criteria.INVARIANT_LIMIT` and the energy error must stay bounded
  (:func:`~dirac.bench.stress_criteria.energy_drift_verdict`).
* :func:`constrained_long_run`: ``rattle-2`` on the pendulum and the double pendulum; the
  constraint residual stays at the Newton tolerance (``|chi(q)| <= tol (1 + |q|^2)``, the
  kernels' stopping rule) and the energy error is bounded as above.

Each returns one table row (a dict with a ``passed`` verdict).
"""

from __future__ import annotations

import math
import time

import numpy as np

from dirac.bench.standard_body import STANDARD_INERTIA, STANDARD_M0, quietly
from dirac.bench.stress_criteria import EPS, INVARIANT_LIMIT, energy_drift_verdict

__all__ = ["long_run", "constrained_long_run"]


def long_run(method: str, steps: int, dt: float, samples: int = 1001) -> dict:
    """Run ``method`` for ``steps`` steps of ``dt`` on the standard body; one table row.

    ``casimir`` is ``max | |M|^2 - |M(0)|^2 |``, ``orthogonality`` is
    ``max |R^T R - 1|`` over the samples; both must stay within :data:`INVARIANT_LIMIT`.
    """
    from dirac.flows.integration import integrate
    from dirac.flows.problems import RigidBodyProblem

    problem = quietly(lambda: RigidBodyProblem(np.array(STANDARD_INERTIA), np.array(STANDARD_M0)))
    start = time.perf_counter()
    solution = integrate(problem, method, t_end=steps * dt, dt=dt, samples=samples,
                         outputs=["M", "R", "energy", "casimir"])
    wall = time.perf_counter() - start
    R = solution["R"]
    orthogonality = float(np.max(np.abs(np.einsum("ski,skj->sij", R, R) - np.eye(3))))
    casimir0 = float(np.dot(STANDARD_M0, STANDARD_M0))
    casimir = float(np.max(np.abs(solution["casimir"] - casimir0)))
    energy = solution["energy"]
    first, last, bounded = energy_drift_verdict(energy - energy[0], solution.steps, float(energy[0]))
    passed = casimir <= INVARIANT_LIMIT and orthogonality <= INVARIANT_LIMIT and bounded and bool(np.all(np.isfinite(energy)))
    return {
        "case": "standard body", "method": method, "steps": int(solution.steps), "dt": float(solution.dt or 0.0),
        "casimir_error": casimir, "orthogonality_error": orthogonality,
        "energy_error_first_tenth": first, "energy_error_last_tenth": last,
        "cpu_seconds": float(solution.cpu_seconds), "wall_seconds": wall, "passed": bool(passed),
    }



def _constrained_problem(system: str):
    from dirac.flows.mechanics import MechanicalSystem
    from dirac.flows.problems import ConstrainedProblem
    from dirac.model.systems import load_system

    mechanics = MechanicalSystem.from_lagrangian(load_system(system))
    if system == "pendulum":
        q = np.array([math.sin(1.0), -math.cos(1.0)])
    elif system == "double_pendulum":
        q = np.array([math.sin(1.0), -math.cos(1.0), math.sin(1.0) + math.sin(0.5), -math.cos(1.0) - math.cos(0.5)])
    else:
        raise ValueError(f"no stress scene for {system!r}")
    return ConstrainedProblem(mechanics, q, np.zeros_like(q))


def constrained_long_run(system: str, method: str, steps: int, dt: float, samples: int = 1001,
                         newton_tolerance: float = 1e-12) -> dict:
    """``method`` (RATTLE) for ``steps`` steps on ``pendulum`` or ``double_pendulum``.

    Released from rest at 1 rad (the double pendulum's second rod at 1.5 rad). Passes when
    every sample has ``|chi(q)| <= newton_tolerance (1 + |q|^2)``, a velocity residual
    ``|G M^{-1} p|`` at round-off (``<= 1e3 eps (1 + |q|^2)(1 + |p|)``) and a bounded energy
    error (:func:`energy_drift_verdict`).
    """
    from dirac.flows.integration import integrate

    problem = _constrained_problem(system)
    mechanics = problem.mechanics
    start = time.perf_counter()
    solution = integrate(problem, method, t_end=steps * dt, dt=dt, samples=samples,
                         outputs=["q", "p", "energy"], newton_tolerance=newton_tolerance)
    wall = time.perf_counter() - start
    q, p = solution["q"], solution["p"]
    position = velocity = 0.0
    position_ok = velocity_ok = True
    for qk, pk in zip(q, p):
        chi, dchi = mechanics.residuals(qk, pk)
        scale = 1.0 + float(qk @ qk)
        position = max(position, float(np.max(np.abs(chi))))
        velocity = max(velocity, float(np.max(np.abs(dchi))))
        position_ok &= bool(np.max(np.abs(chi)) <= newton_tolerance * scale)
        velocity_ok &= bool(np.max(np.abs(dchi)) <= 1e3 * EPS * scale * (1.0 + float(np.linalg.norm(pk))))
    energy = solution["energy"]
    first, last, bounded = energy_drift_verdict(energy - energy[0], solution.steps, float(energy[0]))
    return {
        "case": system, "method": method, "steps": int(solution.steps), "dt": float(solution.dt or 0.0),
        "position_residual": position, "velocity_residual": velocity,
        "energy_error_first_tenth": first, "energy_error_last_tenth": last,
        "cpu_seconds": float(solution.cpu_seconds), "wall_seconds": wall,
        "passed": bool(position_ok and velocity_ok and bounded),
    }

