"""Forced systems in ``dirac bench``: work–precision of the damped pendulum.

The damped pendulum in Cartesian coordinates (``m = l = 1``, ``g = 9.81``, friction
``Q = -c q_dot`` with ``c = 0.3``, released at rest 1 rad from the vertical, ``T = 10``)
is integrated by the forced methods of the package (``forced-rattle-2/4``,
``conformal-2/4``) at several steps and by scipy's DOP853 at several tolerances, on the
same forced vector field (the system's generated Dirac field, which includes ``Q``:
:mod:`dirac.codegen.kernel_source`). The error is ``max |q(T) - q_ref(T)|`` against the
angle equation ``theta'' = -(g/l) sin theta - (c/m) theta'`` solved by DOP853 at
``rtol = atol = 1e-13`` (an independent, minimal-coordinate reference). CPU times are
medians over the repeats of the integration alone (compilation excluded).

Target: at error ``1e-8`` the fastest package method is ahead of DOP853: the ratio
``DOP853 CPU / package CPU`` (each the cheapest run reaching ``1e-8``) is at least 1.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

import numpy as np

from dirac.bench.targets import Target

__all__ = ["forced_rows", "forced_target", "format_forced_rows"]

M, G, ELL, C, THETA0, T_END = 1.0, 9.81, 1.0, 0.3, 1.0, 10.0
THRESHOLD = 1e-8
_PROBLEM = "damped pendulum"


def _reference() -> np.ndarray:
    from scipy.integrate import solve_ivp

    def angle(t: float, s: np.ndarray) -> list[float]:
        return [s[1], -G / ELL * math.sin(s[0]) - C / M * s[1]]

    theta = solve_ivp(angle, (0.0, T_END), [THETA0, 0.0], method="DOP853", rtol=1e-13, atol=1e-13).y[0, -1]
    return np.array([ELL * math.sin(theta), -ELL * math.cos(theta)])


def _problem():
    from dirac.flows.problems import ForcedProblem
    from dirac.model.lagrangian import Lagrangian

    system = Lagrangian.from_strings(
        "damped_pendulum", ["x", "y"], "m/2*(x_dot**2 + y_dot**2) - m*g*y", constraints=["x**2 + y**2 - l**2"],
        parameters={"m": M, "g": G, "l": ELL, "c": C}, forces={"x": "-c*x_dot", "y": "-c*y_dot"})
    return ForcedProblem(system, [ELL * math.sin(THETA0), -ELL * math.cos(THETA0)], [0.0, 0.0])


def forced_rows(quick: bool, repeats: int, say: Callable[[str], None]) -> list[dict]:
    """Work–precision rows of the damped pendulum (see the module docstring)."""
    from scipy.integrate import solve_ivp

    from dirac.flows.dirac_field import ConstrainedField
    from dirac.flows.integration import integrate

    say("forced systems: damped pendulum, package methods and DOP853")
    reference = _reference()
    problem = _problem()
    rows: list[dict] = []
    grids = {
        "forced-rattle-2": (0.01, 0.003, 0.001, 0.0003) if not quick else (0.003, 0.001),
        "forced-rattle-4": (0.04, 0.02, 0.01, 0.005, 0.0025) if not quick else (0.01, 0.005, 0.0025),
        "conformal-2": (0.01, 0.003, 0.001, 0.0003) if not quick else (0.003, 0.001),
        "conformal-4": (0.04, 0.02, 0.01, 0.005, 0.004, 0.0025) if not quick else (0.005, 0.004, 0.0025),
    }
    for method, steps in grids.items():
        for dt in steps:
            cpu, error, count = [], math.inf, 0
            for _ in range(repeats):
                solution = integrate(problem, method, t_end=T_END, dt=dt, samples=1, outputs=["q"])
                cpu.append(solution.cpu_seconds)
                error = float(np.max(np.abs(solution.outputs["q"][-1] - reference)))
                count = solution.steps
            rows.append({"problem": _PROBLEM, "method": method, "parameter": "dt", "value": dt, "t_end": T_END,
                         "cpu_s": float(np.median(cpu)), "error": error, "steps": count})
    field = ConstrainedField(problem.mechanics)
    y0 = np.concatenate([problem.q0[0], problem.p0[0]])
    field.scipy_rhs(0.0, y0)  # compiled before the timed runs
    for tol in ((1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-12) if not quick else (1e-8, 1e-9, 1e-10)):
        cpu, error, count = [], math.inf, 0
        for _ in range(repeats):
            start = time.process_time()
            sol = solve_ivp(field.scipy_rhs, (0.0, T_END), y0, method="DOP853", rtol=tol, atol=tol)
            cpu.append(time.process_time() - start)
            error = float(np.max(np.abs(sol.y[:2, -1] - reference)))
            count = int(sol.nfev)
        rows.append({"problem": _PROBLEM, "method": "scipy-DOP853", "parameter": "tol", "value": tol, "t_end": T_END,
                     "cpu_s": float(np.median(cpu)), "error": error, "evaluations": count})
    return rows


def forced_target(rows: list[dict]) -> Target:
    """``DOP853 CPU / fastest package CPU`` at error ``<= 1e-8`` on the damped pendulum."""
    name = f"forced: damped pendulum, DOP853 CPU / fastest forced method (error <= {THRESHOLD:g})"
    reached = [r for r in rows if r.get("problem") == _PROBLEM and r["error"] <= THRESHOLD]
    ours = [r for r in reached if not r["method"].startswith("scipy-")]
    dop = [r for r in reached if r["method"] == "scipy-DOP853"]
    if not ours or not dop:
        return Target(name, None, "x", 1.0, ">=", "the package or DOP853 did not reach 1e-8 in this run")
    best = min(ours, key=lambda r: r["cpu_s"])
    best_dop = min(dop, key=lambda r: r["cpu_s"])
    general = [r for r in ours if r["method"].startswith("forced-rattle-")]
    also = ""
    if general:
        g = min(general, key=lambda r: r["cpu_s"])
        also = f" (general forces: {g['method']} dt = {g['value']:g}, {g['cpu_s'] * 1e3:.2f} ms)"
    return Target(name, best_dop["cpu_s"] / best["cpu_s"], "x", 1.0, ">=",
                  f"{best['method']} dt = {best['value']:g}: {best['cpu_s'] * 1e3:.2f} ms, error {best['error']:.2g}{also}; "
                  f"DOP853 tol {best_dop['value']:g} on the same forced field: {best_dop['cpu_s'] * 1e3:.2f} ms, "
                  f"error {best_dop['error']:.2g}, {best_dop['evaluations']} RHS calls")


def format_forced_rows(rows: list[dict]) -> str:
    """The table of the forced runs."""
    lines = ["", f"forced systems: {_PROBLEM} (c = {C}, T = {T_END:g}), error of q(T) against the angle equation",
             f"{'method':18s} {'dt / tol':>10s} {'CPU ms':>9s} {'error':>9s}"]
    for r in rows:
        if r.get("problem") != _PROBLEM:
            continue
        lines.append(f"{r['method']:18s} {r['value']:10.3g} {r['cpu_s'] * 1e3:9.3f} {r['error']:9.2g}")
    return "\n".join(lines)
