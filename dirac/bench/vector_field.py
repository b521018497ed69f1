"""Per-call cost of the compiled Dirac vector field against a lean Python right-hand side.

The pendulum in Cartesian coordinates with its multiplier as a coordinate (the state
``(x, y, lambda_1, p_x, p_y, p_lambda_1)`` of its analysis) is evaluated at points of its
constraint surface by

* ``analysis.vector_field()``: the public compiled field ``f(t, y)`` (a new array);
* a lean hand-written right-hand side in plain float arithmetic
  (:func:`pendulum_lean_rhs`, the closed form of the same field on the surface,
  returning a list: the cheapest a Python ``fun(t, y)`` can be);
* the fields the package had before: :meth:`dirac.flows.AnalysedSystem.field` (the
  analysed system's kernel with its generated functions passed as first-class
  functions) and ``ConstrainedField.scipy_rhs`` of the mechanical system (state
  ``(x, y, p_x, p_y)``), used by the scipy baselines;
* ``f.batch`` on many states at once (cost per state).

Calls are timed in loops, the candidates interleaved, and the minimum over repeats of
the CPU time per call is reported (the machine is shared: the minimum is the figure
least disturbed by other jobs). ``solve_ivp(DOP853, rtol = atol = 1e-10)`` to
``t = 10`` on ``f`` and on the lean right-hand side gives the end-to-end figure.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

import numpy as np

from dirac.bench.targets import Target

__all__ = ["pendulum_lean_rhs", "measure_vector_field", "format_vector_field_table"]

#: the pendulum of the suite: m = 1, g = 9.81, l = 1 (its defaults)
M, G, L = 1.0, 9.81, 1.0


def pendulum_lean_rhs(t: float, y: np.ndarray) -> list[float]:
    """The pendulum's Dirac field on its constraint surface, by hand (plain floats).

    ``x_dot = p_x/m``, ``y_dot = p_y/m``, ``lambda_dot = -3 g p_y / (2 l^2)``,
    ``p_x_dot = -2 lambda x``, ``p_y_dot = -m g - 2 lambda y``, ``p_lambda_dot = 0``
    (``H_c = |p|^2/(2m) + m g y + lambda (x^2 + y^2 - l^2)``; ``lambda_dot`` is the time
    derivative of the multiplier solved from the fourth-stage constraint).
    """
    x, yy, lam, px, py, _ = y
    return [px / M, py / M, -1.5 * G * py / (L * L), -2.0 * lam * x, -M * G - 2.0 * lam * yy, 0.0]


def _surface_points(count: int) -> np.ndarray:
    """Surface points by hand: angle and angular velocity -> (x, y, lambda, p_x, p_y, 0)."""
    rng = np.random.default_rng(2024)
    points = []
    for theta, omega in zip(rng.uniform(-math.pi, math.pi, count), rng.normal(scale=3.0, size=count)):
        x, y = L * math.sin(theta), -L * math.cos(theta)
        px, py = M * L * omega * math.cos(theta), M * L * omega * math.sin(theta)
        lam = ((px * px + py * py) / M - M * G * y) / (2 * L * L)
        points.append((x, y, lam, px, py, 0.0))
    return np.array(points)


def _per_call(function: Callable[[], object], calls: int) -> float:
    """CPU seconds per call of ``calls`` calls in a loop."""
    start = time.process_time()
    for _ in range(calls):
        function()
    return (time.process_time() - start) / calls


def measure_vector_field(repeats: int, calls: int, batch: int, before: bool = True) -> tuple[list[dict], Target]:
    """The vector-field table (one row per candidate) and its target (``f`` / lean < 1).

    Parameters
    ----------
    repeats
        Interleaved rounds; each candidate's figure is its minimum over the rounds.
    calls
        Calls per candidate and round.
    batch
        States of the batched evaluation.
    before
        Also time the fields the package had before (their first use compiles their
        kernels: ``dirac bench --quick`` leaves them out).
    """
    from scipy.integrate import solve_ivp

    from dirac.flows import AnalysedSystem, MechanicalSystem
    from dirac.flows.dirac_field import ConstrainedField
    from dirac.model.systems import load_system

    lagrangian = load_system("pendulum")
    analysed = AnalysedSystem.from_lagrangian(lagrangian)
    f = analysed.analysis.vector_field()
    points = _surface_points(64)
    agreement = max(float(np.max(np.abs(f(0.0, z) - np.array(pendulum_lean_rhs(0.0, z))))) for z in points)
    z = points[0].copy()
    many = np.repeat(points, batch // len(points) + 1, axis=0)[:batch].copy()
    candidates: dict[str, tuple[Callable[[], object], int]] = {
        "analysis.vector_field(): f(t, y)": (lambda: f(0.0, z), calls),
        "lean Python RHS (plain floats, list)": (lambda: pendulum_lean_rhs(0.0, z), calls),
    }
    if before:
        old = ConstrainedField(MechanicalSystem.from_lagrangian(lagrangian))
        state = np.concatenate([z[:2], z[3:5]])
        candidates["AnalysedSystem.field(z) (before)"] = (lambda: analysed.field(z), max(1, calls // 20))
        candidates["ConstrainedField.scipy_rhs (before, q and p only)"] = (lambda: old.scipy_rhs(0.0, state),
                                                                            max(1, calls // 20))
    candidates[f"f.batch on {batch} states, per state"] = (lambda: f.batch(many), 1)
    best = {name: math.inf for name in candidates}
    for function, _ in candidates.values():
        function()  # compilation and first-call costs outside the timed loops
    for _ in range(max(1, repeats)):
        for name, (function, count) in candidates.items():
            per = _per_call(function, count)
            if name.startswith("f.batch"):
                per /= batch
            best[name] = min(best[name], per)

    def integrate(fun: Callable) -> tuple[float, int, float]:
        start = time.process_time()
        result = solve_ivp(fun, (0.0, 10.0), points[0], method="DOP853", rtol=1e-10, atol=1e-10)
        seconds = time.process_time() - start
        drift = float(np.max(np.abs(result.y[0] ** 2 + result.y[1] ** 2 - L * L)))
        return seconds, int(result.nfev), drift

    integrate(f)
    runs_f = [integrate(f) for _ in range(3)]
    runs_lean = [integrate(pendulum_lean_rhs) for _ in range(3)]
    ivp_f, ivp_lean = min(runs_f), min(runs_lean)
    lean = best["lean Python RHS (plain floats, list)"]
    rows = [{"field": name, "us_per_call": best[name] * 1e6, "ratio_to_lean": best[name] / lean} for name in candidates]
    rows.append({"field": "solve_ivp DOP853 1e-10 to t = 10 on f (ms)", "ms": ivp_f[0] * 1e3, "evaluations": ivp_f[1],
                 "circle_drift": ivp_f[2]})
    rows.append({"field": "solve_ivp DOP853 1e-10 to t = 10 on the lean RHS (ms)", "ms": ivp_lean[0] * 1e3,
                 "evaluations": ivp_lean[1], "circle_drift": ivp_lean[2]})
    ratio = best["analysis.vector_field(): f(t, y)"] / lean
    target = Target(
        "vector field: f(t, y) per call / lean Python RHS (pendulum)", ratio, "x", 1.0, "<=",
        f"f {best['analysis.vector_field(): f(t, y)'] * 1e6:.2f} us, lean {lean * 1e6:.2f} us per call (min of "
        f"{max(1, repeats)} interleaved rounds of {calls} calls); agree to {agreement:.1e} at 64 surface points; "
        f"solve_ivp DOP853 1e-10 to t = 10: {ivp_f[0] * 1e3:.1f} ms on f, {ivp_lean[0] * 1e3:.1f} ms on the lean RHS, "
        f"circle kept to {ivp_f[2]:.1e}",
        {"agreement": agreement},
    )
    return rows, target


def format_vector_field_table(rows: list[dict]) -> str:
    """The vector-field table of ``dirac bench``."""
    lines = ["\n== Dirac vector field of the pendulum: CPU per call (min over interleaved rounds) ==",
             f"{'right-hand side':<52}{'us/call':>10}{'x lean':>9}", "-" * 71]
    for row in rows:
        if "us_per_call" in row:
            lines.append(f"{row['field']:<52}{row['us_per_call']:>10.3f}{row['ratio_to_lean']:>9.3f}")
    for row in rows:
        if "ms" in row:
            lines.append(f"{row['field']}: {row['ms']:.1f} ms, {row['evaluations']} RHS calls, "
                         f"max |x^2 + y^2 - l^2| {row['circle_drift']:.1e}")
    return "\n".join(lines)
