"""Work–precision runs: every method of the suite at every step size / tolerance.

Package methods run through :func:`dirac.flows.integrate` (``samples = 1``: only the
final state is kept) and are timed by the loop's own CPU clock (``Solution.cpu_seconds``:
the integration itself, compiled kernels, setup excluded) with the CPU time of the whole
call reported too. The scipy baselines of the rigid body are called directly as
``solve_ivp`` on the lean plain-float right-hand side
(:func:`dirac.rigidbody.euler_poisson.lean_rhs_full`), their best footing; for the
constrained systems they integrate the package's Dirac vector field through
``integrate``. Every run is repeated and the median reported.
"""

from __future__ import annotations

import math
import time
import warnings
from collections.abc import Callable

import numpy as np

from dirac.bench.suite import ConstrainedCase, MethodGrid, RigidBodyCase
from dirac.bench.timing import median_of
from dirac.errors import InputError

__all__ = ["run_rigid_body_case", "run_constrained_case"]

Progress = Callable[[str], None]


#: Slow runs are repeated fewer times: about this much CPU per configuration (seconds).
TIME_BUDGET = 0.6


def _median_runs(run: Callable[[], dict], repeats: int) -> dict:
    """One untimed warm-up run, then up to ``repeats`` timed runs; medians of their timings.

    The number of timed runs is cut so that they take about ``TIME_BUDGET`` of CPU in
    all (at least one), judged from the first timed run.
    """
    run()
    results = [run()]
    slow = max(results[0].get("call_cpu_s") or 0.0, results[0].get("cpu_s") or 0.0)
    repeats = max(1, min(int(repeats), int(TIME_BUDGET / max(slow, 1e-9))))
    results += [run() for _ in range(repeats - 1)]
    row = dict(results[-1])
    for key in ("cpu_s", "call_cpu_s", "wall_s"):
        values = [r[key] for r in results if r.get(key) is not None]
        if values:
            row[key] = median_of(values)
    row["cpu_min_s"] = min(r["cpu_s"] for r in results)
    row["repeats"] = len(results)
    return row


def _rigid_errors(M: np.ndarray, R: np.ndarray, case: RigidBodyCase, M_ref: np.ndarray, R_ref: np.ndarray) -> dict:
    inertia = np.array(case.inertia)
    M0 = np.array(case.M0)
    energy0 = 0.5 * float(np.sum(M0 * M0 / inertia))
    casimir0 = float(M0 @ M0)
    energy = 0.5 * float(np.sum(M * M / inertia))
    error_M = float(np.max(np.abs(M - M_ref)))
    error_R = float(np.max(np.abs(R - R_ref)))
    return {
        "error_M": error_M,
        "error_R": error_R,
        "error": max(error_M, error_R),
        "energy_error": abs(energy - energy0) / abs(energy0),
        "casimir_error": abs(float(M @ M) - casimir0) / casimir0,
        "orthogonality_error": float(np.max(np.abs(R.T @ R - np.eye(3)))),
    }


def _rigid_package_run(case: RigidBodyCase, grid: MethodGrid, value: float | None, problem, refs) -> Callable[[], dict]:
    from dirac.flows import integrate

    def run() -> dict:
        c0 = time.process_time()
        solution = integrate(
            problem,
            grid.method,
            t_end=case.t_end,
            dt=value if grid.parameter == "dt" else None,
            tolerance=value if grid.parameter == "tolerance" else 1e-8,
            samples=1,
            outputs=["M", "R"],
        )
        call = time.process_time() - c0
        M = solution.outputs["M"][-1]
        R = solution.outputs["R"][-1]
        return {
            "cpu_s": solution.cpu_seconds,
            "call_cpu_s": call,
            "steps": int(solution.steps),
            "evaluations": int(solution.evaluations),
            **_rigid_errors(M, R, case, *refs),
        }

    return run


def _rigid_scipy_run(case: RigidBodyCase, grid: MethodGrid, tolerance: float, refs) -> Callable[[], dict]:
    from scipy.integrate import solve_ivp

    from dirac.rigidbody.euler_poisson import lean_rhs_full

    y0 = np.concatenate([np.array(case.M0), np.eye(3).ravel()])
    method = grid.method.split("-", 1)[1]

    def run() -> dict:
        c0 = time.process_time()
        solution = solve_ivp(lean_rhs_full, (0.0, case.t_end), y0, method=method, rtol=tolerance,
                             atol=tolerance, args=case.inertia)
        cpu = time.process_time() - c0
        y = solution.y[:, -1]
        return {
            "cpu_s": cpu,
            "call_cpu_s": cpu,
            "steps": int(len(solution.t) - 1),
            "evaluations": int(solution.nfev),
            **_rigid_errors(y[:3], y[3:].reshape(3, 3), case, *refs),
        }

    return run


def run_rigid_body_case(case: RigidBodyCase, repeats: int, progress: Progress) -> list[dict]:
    """Run every method and parameter of ``case``; one row per run."""
    from dirac.bench.reference import rigid_body_reference
    from dirac.flows import RigidBodyProblem

    progress(f"{case.name}: high-precision reference (Taylor series, 36 digits; cached)")
    refs = rigid_body_reference(case.inertia, case.M0, case.t_end)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the standard body violates the triangle inequality
        problem = RigidBodyProblem(list(case.inertia), list(case.M0))
    rows = []
    for grid in case.grids:
        for value in grid.values:
            progress(f"{case.name}: {grid.method} {grid.parameter} {value if value is not None else ''}".rstrip())
            if grid.method.startswith("scipy-"):
                if value is None:  # a scipy grid lists tolerances; None belongs to the exact flow only
                    raise InputError(f"{case.name}: {grid.method} needs a tolerance, the grid gives None")
                run = _rigid_scipy_run(case, grid, float(value), refs)
                runner = "solve_ivp, lean float RHS"
            else:
                run = _rigid_package_run(case, grid, value, problem, refs)
                runner = "dirac.flows.integrate"
            row = {"problem": case.name, "method": grid.method, "parameter": grid.parameter,
                   "value": value, "t_end": case.t_end, "runner": runner}
            try:
                row.update(_median_runs(run, repeats))
            except Exception as exc:  # a method that fails on this problem is reported, not fatal
                row.update({"failed": f"{type(exc).__name__}: {' '.join(str(exc).split())[:200]}"})
            rows.append(row)
    return rows


def _constrained_problem(case: ConstrainedCase):
    from dirac.flows import ConstrainedProblem, MechanicalSystem
    from dirac.model.systems import load_system

    mechanics = MechanicalSystem.from_lagrangian(load_system(case.system))
    params = mechanics.parameter_values
    if case.system == "pendulum":
        (a,) = case.angles
        l = params["l"]
        q0 = np.array([l * math.sin(a), -l * math.cos(a)])
    else:
        a1, a2 = case.angles
        l1, l2 = params["l1"], params["l2"]
        x1, y1 = l1 * math.sin(a1), -l1 * math.cos(a1)
        q0 = np.array([x1, y1, x1 + l2 * math.sin(a2), y1 - l2 * math.cos(a2)])
    p0 = np.zeros_like(q0)  # released at rest
    return ConstrainedProblem(mechanics, q0, p0), params


def run_constrained_case(case: ConstrainedCase, repeats: int, progress: Progress) -> list[dict]:
    """Run every method and parameter of a constrained case; one row per run.

    Errors: the pendulum returns exactly to its initial state after whole periods of the
    exact elliptic period; the double pendulum is compared with the angle-equation
    reference of :func:`dirac.bench.reference.double_pendulum_reference`.
    """
    from dirac.bench.reference import double_pendulum_reference, pendulum_period
    from dirac.flows import integrate

    progress(f"{case.name}: building the system (codegen, cached) and the reference")
    problem, params = _constrained_problem(case)
    mechanics = problem.mechanics
    q0, p0 = problem.q0[0], problem.p0[0]
    energy0 = mechanics.energy(q0, p0)
    if case.system == "pendulum":
        t_end = case.periods * pendulum_period(params["g"], params["l"], case.angles[0])
        q_ref, p_ref, reference_error = q0, p0, 0.0
        reference = f"exact elliptic period x {case.periods:g}"
    else:
        t_end = case.periods
        q_ref, reference_error = double_pendulum_reference(case.angles, (0.0, 0.0), t_end, params)
        p_ref = None
        reference = "DOP853 rtol 1e-13 on the angle equations"
    rows = []
    for grid in case.grids:
        for value in grid.values:
            progress(f"{case.name}: {grid.method} {grid.parameter} {value}")

            def run(grid: MethodGrid = grid, value: float | None = value) -> dict:
                c0 = time.process_time()
                solution = integrate(
                    problem, grid.method, t_end=t_end,
                    dt=value if grid.parameter == "dt" else None,
                    tolerance=value if grid.parameter == "tolerance" else 1e-8,
                    samples=1, outputs=["q", "p", "constraint_residual"],
                    # the baselines drift off the constraints: report it, do not stop them
                    drift_limit=1e3 if grid.method.startswith("scipy-") else 1e-6,
                )
                call = time.process_time() - c0
                q = solution.outputs["q"][-1]
                p = solution.outputs["p"][-1]
                error_q = float(np.max(np.abs(q - q_ref)))
                error_p = float(np.max(np.abs(p - p_ref))) if p_ref is not None else None
                energy = mechanics.energy(q, p)
                return {
                    "cpu_s": solution.cpu_seconds,
                    "call_cpu_s": call,
                    "steps": int(solution.steps),
                    "evaluations": int(solution.evaluations),
                    "error_q": error_q,
                    "error_p": error_p,
                    "error": error_q if error_p is None else max(error_q, error_p),
                    "energy_error": abs(energy - energy0) / abs(energy0),
                    "constraint_residual": float(np.max(solution.outputs["constraint_residual"])),
                }

            row = {"problem": case.name, "method": grid.method, "parameter": grid.parameter, "value": value,
                   "t_end": t_end, "runner": "dirac.flows.integrate", "reference": reference,
                   "reference_error": reference_error}
            try:
                row.update(_median_runs(run, repeats))
            except Exception as exc:  # reported, not fatal
                row.update({"failed": f"{type(exc).__name__}: {' '.join(str(exc).split())[:200]}"})
            rows.append(row)
    return rows
