"""A torqued rigid body in ``dirac bench``: the kick compositions against DOP853.

The body ``I = (3, 2, 1)``, ``M(0) = (0.2, 3, 0.4)``, ``R(0) = 1`` under the torque (body
frame)

    N = -k M + a sin(t) gamma,   k = 0.1,  a = 0.05,   gamma = R^T e_z = (R_31, R_32, R_33)

(a control torque that despins the body and a lab-fixed disturbance ``a sin(t) e_z``), to
``T = 20``. The package's methods (``exact-kick-*``, ``lie-poisson-*``: midpoint kicks,
since ``N`` depends on ``M``) run through :func:`dirac.flows.integrate`; the baseline is
scipy's ``DOP853`` on a hand-written float right-hand side of the same equations (its best
footing, as for the free body in :mod:`dirac.bench.workprecision`). The reference is DOP853
at ``rtol = atol = 1e-13``; its own error is estimated by its distance to ``exact-kick-8``
at a fine step. The ``energy`` column holds the error of the balance ``E - W`` (``W`` the
work of the torque), the invariant of the exact motion.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from dirac.bench.suite import MethodGrid

__all__ = ["TORQUED_BODY", "TorquedCase", "torqued_cases", "run_torqued_case", "torqued_rhs"]

_INERTIA = (3.0, 2.0, 1.0)
_M0 = (0.2, 3.0, 0.4)
_K = 0.1
_A = 0.05
#: The torque of the benchmark, as a scene gives it.
TORQUED_BODY = tuple(f"-{_K}*M_{i} + {_A}*sin(t)*R_3{i}" for i in (1, 2, 3))


@dataclass(frozen=True)
class TorquedCase:
    """The torqued body and the grids it is run with."""

    name: str
    description: str
    t_end: float
    grids: tuple[MethodGrid, ...]

    def problem(self):
        from dirac.flows import RigidBodyProblem

        return RigidBodyProblem(list(_INERTIA), list(_M0), torque=list(TORQUED_BODY))


def torqued_cases(quick: bool) -> list[TorquedCase]:
    """One case; fewer grid points with ``quick``."""
    if quick:
        grids: tuple[MethodGrid, ...] = (
            MethodGrid("exact-kick-6", (0.2, 0.1), "dt"),
            MethodGrid("lie-poisson-6", (0.1, 0.05), "dt"),
            MethodGrid("lie-poisson-8", (0.1,), "dt"),
            MethodGrid("scipy-DOP853", (1e-9, 1e-10), "tolerance"),
        )
    else:
        grids = (
            MethodGrid("exact-kick-4", (0.1, 0.05, 0.025), "dt"),
            MethodGrid("exact-kick-6", (0.2, 0.1, 0.05), "dt"),
            MethodGrid("exact-kick-8", (0.2, 0.1, 0.05), "dt"),
            MethodGrid("lie-poisson-4", (0.025, 0.0125, 0.00625), "dt"),
            MethodGrid("lie-poisson-6", (0.1, 0.05, 0.025), "dt"),
            MethodGrid("lie-poisson-8", (0.1, 0.05, 0.025), "dt"),
            MethodGrid("scipy-DOP853", (1e-7, 1e-8, 1e-9, 1e-10, 1e-11), "tolerance"),
        )
    description = (f"I = (3, 2, 1), M(0) = (0.2, 3, 0.4), N = -{_K} M + {_A} sin(t) R^T e_z, T = 20; "
                   "energy column: |E - W - E0| / E0")
    return [TorquedCase("torqued body", description, 20.0, grids)]


def torqued_rhs(t: float, y: np.ndarray) -> np.ndarray:
    """Euler's equations with the benchmark torque, ``dM/dt = M x Omega + N``,
    ``dR/dt = R hat(Omega)``, ``dW/dt = N·Omega``, in plain float arithmetic; ``y`` is
    ``M`` (3), ``R`` row by row (9), ``W``."""
    m0, m1, m2 = y[0], y[1], y[2]
    w0, w1, w2 = m0 / 3.0, m1 / 2.0, m2 / 1.0
    s = _A * math.sin(t)
    n0 = -_K * m0 + s * y[9]
    n1 = -_K * m1 + s * y[10]
    n2 = -_K * m2 + s * y[11]
    dy = np.empty(13)
    dy[0] = m1 * w2 - m2 * w1 + n0
    dy[1] = m2 * w0 - m0 * w2 + n1
    dy[2] = m0 * w1 - m1 * w0 + n2
    for row in range(3):
        r0, r1, r2 = y[3 + 3 * row], y[4 + 3 * row], y[5 + 3 * row]
        # (R hat(w))_{row, :} = r x ... : row of R times hat(w) = (r1 w2 - r2 w1, r2 w0 - r0 w2, r0 w1 - r1 w0)
        dy[3 + 3 * row] = r1 * w2 - r2 * w1
        dy[4 + 3 * row] = r2 * w0 - r0 * w2
        dy[5 + 3 * row] = r0 * w1 - r1 * w0
    dy[12] = n0 * w0 + n1 * w1 + n2 * w2
    return dy


def _dop853(t_end: float, tolerance: float) -> tuple[np.ndarray, np.ndarray, float, float, int, int]:
    """``M, R, W`` at ``t_end``, CPU seconds, steps and RHS calls of scipy's DOP853."""
    from scipy.integrate import solve_ivp

    y0 = np.concatenate([_M0, np.eye(3).ravel(), [0.0]])
    c0 = time.process_time()
    solution = solve_ivp(torqued_rhs, (0.0, t_end), y0, method="DOP853", rtol=tolerance, atol=tolerance)
    cpu = time.process_time() - c0
    y = solution.y[:, -1]
    return y[:3], y[3:12].reshape(3, 3), float(y[12]), cpu, int(solution.t.size - 1), int(solution.nfev)


def run_torqued_case(case: TorquedCase, repeats: int, progress: Callable[[str], None]) -> list[dict]:
    """Every method and parameter of ``case``; one row per run in the layout of the
    rigid-body rows."""
    from dirac.bench.workprecision import _median_runs
    from dirac.flows import integrate

    problem = case.problem()
    progress(f"{case.name}: DOP853 reference (rtol = atol = 1e-13)")
    M_ref, R_ref, _, _, _, _ = _dop853(case.t_end, 1e-13)
    check = integrate(problem, "exact-kick-8", t_end=case.t_end, dt=0.01, samples=1, outputs=["M", "R"])
    reference_error = max(float(np.max(np.abs(check["M"][-1] - M_ref))),
                          float(np.max(np.abs(check["R"][-1] - R_ref))))
    inverse = 1.0 / np.asarray(_INERTIA)
    energy0 = 0.5 * float(np.sum(np.square(_M0) * inverse))
    rows = []
    for grid in case.grids:
        for value in grid.values:
            progress(f"{case.name}: {grid.method} {grid.parameter} {value}")

            def run(grid: MethodGrid = grid, value: float | None = value) -> dict:
                c0 = time.process_time()
                if grid.method == "scipy-DOP853":
                    M, R, W, cpu, steps, evaluations = _dop853(case.t_end, float(value))  # type: ignore[arg-type]
                else:
                    solution = integrate(problem, grid.method, t_end=case.t_end, dt=value, samples=1,
                                         outputs=["M", "R", "work"])
                    M, R, W = solution["M"][-1], solution["R"][-1], float(solution["work"][-1])
                    cpu, steps, evaluations = solution.cpu_seconds, solution.steps, solution.evaluations
                call = time.process_time() - c0
                error_M = float(np.max(np.abs(M - M_ref)))
                error_R = float(np.max(np.abs(R - R_ref)))
                energy = 0.5 * float(np.sum(M * M * inverse))
                return {
                    "cpu_s": cpu, "call_cpu_s": call, "steps": int(steps), "evaluations": int(evaluations),
                    "error_M": error_M, "error_R": error_R, "error": max(error_M, error_R),
                    "energy_error": abs(energy - W - energy0) / energy0, "casimir_error": None,
                    "orthogonality_error": float(np.max(np.abs(R.T @ R - np.eye(3)))),
                }

            row = {"problem": case.name, "method": grid.method, "parameter": grid.parameter, "value": value,
                   "t_end": case.t_end, "runner": "scipy.integrate.solve_ivp (lean float RHS)"
                   if grid.method == "scipy-DOP853" else "dirac.flows.integrate", "description": case.description,
                   "reference": "DOP853 rtol = atol = 1e-13 (distance to exact-kick-8 dt = 0.01 as its error)",
                   "reference_error": reference_error}
            try:
                row.update(_median_runs(run, repeats))
            except Exception as exc:  # reported, not fatal
                row.update({"failed": f"{type(exc).__name__}: {' '.join(str(exc).split())[:200]}"})
            rows.append(row)
    return rows
