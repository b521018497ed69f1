"""The heavy top in ``dirac bench``: where the exact free flow + kick pays, measured.

Three things, each in the same run (the targets built from them are in
:mod:`dirac.bench.targets`):

- **Per-step cost** of ``exact-kick-4`` against ``lie-poisson-4`` on the asymmetric heavy top
  (``I = (1, 2, 3)``, ``M(0) = (1, 0.5, 2)``, ``m g = 0.5``, ``chi = (0.1, 0.2, 0.5)``):
  CPU of :func:`dirac.flows.integrate` over many steps, the two interleaved, minima.
- **A hand-written numba anchor** of the same algorithm (:func:`anchor_exact_kick`): the
  kick + exact-free-flow composition written the textbook way (Jacobi ``sn, cn, dn`` at
  ``u0 + lam t``, ``psi`` from two values of Legendre's ``Pi(n; am u | m)``; generic bodies
  only, no anchoring, no scaling), against which the package's kernel is timed; the states
  of the two are compared too.
- **Work–precision** of both families on a fast and a slow top (same body and ``chi``,
  ``M(0)`` scaled): the fast top has spin energy ``H_0(M(0)) = sum M_i^2 / (2 I_i)`` over
  112 times the largest gravitational energy ``m g |chi|`` (the bound of ``|V| = m g |<chi,
  gamma>|``), the slow one about once. Errors at ``T`` against DOP853 at ``rtol = atol =
  1e-13``; the reference's own error is estimated by its distance to ``lie-poisson-8`` at a
  fine step.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numba import njit

from dirac.bench.suite import MethodGrid
from dirac.rigidbody.elliptic import carlson_rf, complete_pi, elliptic_f, elliptic_pi, sncndn
from dirac.rigidbody.heavy_top import kick

__all__ = ["HeavyTopCase", "heavy_top_cases", "run_heavy_top_case", "anchor_exact_kick", "spin_over_gravity",
           "ASYMMETRIC_TOP"]

_INERTIA = (1.0, 2.0, 3.0)
_DIRECTION = (1.0, 0.5, 2.0)
_MASS_GRAVITY = 0.5
_CHI = (0.1, 0.2, 0.5)

#: The asymmetric top of the per-step figures: inertia, M(0), m g, chi.
ASYMMETRIC_TOP = (_INERTIA, _DIRECTION, _MASS_GRAVITY, _CHI)


@dataclass(frozen=True)
class HeavyTopCase:
    """A heavy top with ``R(0) = 1`` and the grids it is run with."""

    name: str
    description: str
    M0: tuple[float, float, float]
    t_end: float
    grids: tuple[MethodGrid, ...]
    inertia: tuple[float, float, float] = _INERTIA
    mass_gravity: float = _MASS_GRAVITY
    center_of_mass: tuple[float, float, float] = _CHI

    def problem(self):
        from dirac.flows import HeavyTopProblem

        return HeavyTopProblem(list(self.inertia), list(self.M0), mass_gravity=self.mass_gravity,
                               center_of_mass=list(self.center_of_mass))


def spin_over_gravity(inertia, M0, mass_gravity: float, center_of_mass) -> float:
    """``H_0(M0) / (m g |chi|)``: spin energy over the largest gravitational energy."""
    M = np.asarray(M0, dtype=float)
    spin = 0.5 * float(np.sum(M * M / np.asarray(inertia, dtype=float)))
    return spin / (mass_gravity * float(np.linalg.norm(center_of_mass)))


def heavy_top_cases(quick: bool) -> list[HeavyTopCase]:
    """The fast top (spin energy 112 x gravity) and the slow one (about 1 x)."""
    fast_scale, slow_scale = 5.0, 0.5
    x, y, z = _DIRECTION
    fast_M0 = (fast_scale * x, fast_scale * y, fast_scale * z)
    slow_M0 = (slow_scale * x, slow_scale * y, slow_scale * z)
    # exact-kick-4 steps ~2.4x the lie-poisson-4 ones cost about the same: its points fall
    # between theirs on the CPU axis, so the errors can be compared at equal CPU time
    if quick:
        fast: tuple[MethodGrid, ...] = (
            MethodGrid("lie-poisson-4", (0.01, 0.005), "dt"),
            MethodGrid("exact-kick-4", (0.0175,), "dt"),
        )
        slow: tuple[MethodGrid, ...] = (
            MethodGrid("lie-poisson-4", (0.05,), "dt"),
            MethodGrid("exact-kick-4", (0.05,), "dt"),
        )
    else:
        fast = (
            MethodGrid("lie-poisson-4", (0.02, 0.01, 0.005, 0.0025, 0.00125), "dt"),
            MethodGrid("exact-kick-4", (0.035, 0.0175, 0.00875, 0.004375), "dt"),
            MethodGrid("lie-poisson-8", (0.04, 0.02), "dt"),
            MethodGrid("exact-kick-8", (0.1, 0.05), "dt"),
            MethodGrid("scipy-DOP853", (1e-8, 1e-10), "tolerance"),
        )
        slow = (
            MethodGrid("lie-poisson-4", (0.1, 0.05, 0.025), "dt"),
            MethodGrid("exact-kick-4", (0.1, 0.05, 0.025), "dt"),
            MethodGrid("lie-poisson-8", (0.1, 0.05), "dt"),
            MethodGrid("exact-kick-8", (0.1, 0.05), "dt"),
            MethodGrid("scipy-DOP853", (1e-8, 1e-10), "tolerance"),
        )
    ratio_fast = spin_over_gravity(_INERTIA, fast_M0, _MASS_GRAVITY, _CHI)
    ratio_slow = spin_over_gravity(_INERTIA, slow_M0, _MASS_GRAVITY, _CHI)
    common = "I = (1, 2, 3), m g = 0.5, chi = (0.1, 0.2, 0.5)"
    return [
        HeavyTopCase("heavy top (fast)", f"{common}, M(0) = {fast_scale:g} (1, 0.5, 2): spin energy "
                     f"{ratio_fast:.0f} x m g |chi|, T = 10", fast_M0, 10.0, fast),
        HeavyTopCase("heavy top (slow)", f"{common}, M(0) = {slow_scale:g} (1, 0.5, 2): spin energy "
                     f"{ratio_slow:.1f} x m g |chi|, T = 10", slow_M0, 10.0, slow),
    ]


def _final(problem, method: str, t_end: float, value: float | None, parameter: str):
    from dirac.flows import integrate

    return integrate(problem, method, t_end=t_end, dt=value if parameter == "dt" else None,
                     tolerance=value if parameter == "tolerance" else 1e-8, samples=1,
                     outputs=["M", "R", "energy", "lab_momentum_z"])


def run_heavy_top_case(case: HeavyTopCase, repeats: int, progress: Callable[[str], None]) -> list[dict]:
    """Every method and parameter of ``case`` through :func:`dirac.flows.integrate`; one row
    per run in the layout of the rigid-body rows (``energy`` is ``H_0 + V``, ``|M|^2`` is not
    an invariant of the heavy top and left empty)."""
    from dirac.bench.workprecision import _median_runs

    problem = case.problem()
    progress(f"{case.name}: DOP853 reference (rtol = atol = 1e-13)")
    reference = _final(problem, "scipy-DOP853", case.t_end, 1e-13, "tolerance")
    check = _final(problem, "lie-poisson-8", case.t_end, 0.005, "dt")
    M_ref, R_ref = reference["M"][-1], reference["R"][-1]
    reference_error = max(float(np.max(np.abs(check["M"][-1] - M_ref))),
                          float(np.max(np.abs(check["R"][-1] - R_ref))))
    energy0 = float(reference["energy"][0])
    rows = []
    for grid in case.grids:
        for value in grid.values:
            progress(f"{case.name}: {grid.method} {grid.parameter} {value}")

            def run(grid: MethodGrid = grid, value: float | None = value) -> dict:
                c0 = time.process_time()
                solution = _final(problem, grid.method, case.t_end, value, grid.parameter)
                call = time.process_time() - c0
                M, R = solution["M"][-1], solution["R"][-1]
                error_M = float(np.max(np.abs(M - M_ref)))
                error_R = float(np.max(np.abs(R - R_ref)))
                return {
                    "cpu_s": solution.cpu_seconds,
                    "call_cpu_s": call,
                    "steps": int(solution.steps),
                    "evaluations": int(solution.evaluations),
                    "error_M": error_M,
                    "error_R": error_R,
                    "error": max(error_M, error_R),
                    "energy_error": abs(float(solution["energy"][-1]) - energy0) / abs(energy0),
                    "casimir_error": None,
                    "orthogonality_error": float(np.max(np.abs(R.T @ R - np.eye(3)))),
                    "lab_momentum_z_error": abs(float(solution["lab_momentum_z"][-1] - solution["lab_momentum_z"][0])),
                }

            row = {"problem": case.name, "method": grid.method, "parameter": grid.parameter, "value": value,
                   "t_end": case.t_end, "runner": "dirac.flows.integrate", "description": case.description,
                   "reference": "DOP853 rtol = atol = 1e-13 (distance to lie-poisson-8 dt = 0.005 as its error)",
                   "reference_error": reference_error}
            try:
                row.update(_median_runs(run, repeats))
            except Exception as exc:  # reported, not fatal
                row.update({"failed": f"{type(exc).__name__}: {' '.join(str(exc).split())[:200]}"})
            rows.append(row)
    return rows


# --------------------------------------------------------------------------- the anchor
@njit(cache=True, inline="always")
def _anchor_frame(v0, v1, v2, b):
    """Rows ``r1 = e_b x mu / |.|``, ``r2 = mu x r1``, ``r3 = mu`` (``mu = v/|v|``) as nine numbers."""
    norm = math.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
    m0, m1, m2 = v0 / norm, v1 / norm, v2 / norm
    if b == 0:
        x0, x1, x2 = 0.0, -m2, m1
    elif b == 1:
        x0, x1, x2 = m2, 0.0, -m0
    else:
        x0, x1, x2 = -m1, m0, 0.0
    rho = math.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
    x0, x1, x2 = x0 / rho, x1 / rho, x2 / rho
    return (x0, x1, x2, m1 * x2 - m2 * x1, m2 * x0 - m0 * x2, m0 * x1 - m1 * x0, m0, m1, m2)


@njit(cache=True)
def _anchor_free_flow(M, R, a, t, em, en):
    """Exact free flow of ``(M, R)`` for a time ``t``, generic asymmetric body, written plainly.

    Jacobi (Landau & Lifshitz §37): with the moments ordered ``(p1, p2, p3)``, ``p2`` the
    middle one and ``p3`` the axis the polhode encircles, ``M_p1 = A1 cn u``, ``M_p2 = s2 A2
    sn u``, ``M_p3 = s3 A3 dn u``, ``u = u0 + lam t``. Attitude (Celledoni, Fassò, Säfström &
    Zanna 2008): ``R(t) = R(0) A(M0)^T Z(psi) A(M(t))`` with ``A(M)`` the frame with rows
    ``e_p3 x mu / |.|``, ``mu x r1``, ``mu = M/|M|`` and ``psi = G a3 t + G (a1 - a3)/lam
    [Pi(n; am u) - Pi(n; am u0)]``, ``n = (a2 - a1)/(a2 - a3)``. ``em``, ``en``: scratch of
    40 numbers each for the AGM.
    """
    G2 = M[0] * M[0] + M[1] * M[1] + M[2] * M[2]
    G = math.sqrt(G2)
    E2 = a[0] * M[0] * M[0] + a[1] * M[1] * M[1] + a[2] * M[2] * M[2]
    lo, mid, hi = 0, 1, 2
    if a[mid] < a[lo]:
        lo, mid = mid, lo
    if a[hi] < a[mid]:
        mid, hi = hi, mid
        if a[mid] < a[lo]:
            lo, mid = mid, lo
    p2 = mid
    if E2 >= a[mid] * G2:
        p3, p1 = hi, lo
    else:
        p3, p1 = lo, hi
    a1, a2, a3 = a[p1], a[p2], a[p3]
    A1 = math.sqrt((E2 - a3 * G2) / (a1 - a3))
    A2 = math.sqrt((E2 - a3 * G2) / (a2 - a3))
    A3 = math.sqrt((E2 - a1 * G2) / (a3 - a1))
    mc = 1.0 - (E2 - a3 * G2) * (a2 - a1) / ((a2 - a3) * (E2 - a1 * G2))
    lam = abs((a3 - a2) * A2 * A3 / A1)
    s3 = 1.0 if M[p3] >= 0.0 else -1.0
    eps = 1.0 if p2 == (p1 + 1) % 3 else -1.0
    s2 = -s3 * eps * (1.0 if a3 > a2 else -1.0)  # from dM_p1/dt of Euler's equations (250)
    # AGM of (1, sqrt(mc)) for sn, cn, dn (Bulirsch); K = R_F(0, mc, 1)
    levels = 0
    x = 1.0
    y = mc
    c = 1.0
    for _ in range(40):
        em[levels] = x
        y = math.sqrt(y)
        en[levels] = y
        levels += 1
        c = 0.5 * (x + y)
        if abs(x - y) <= 1e-8 * x:
            break
        y *= x
        x = c
    K = carlson_rf(0.0, mc, 1.0)
    n = (a2 - a1) / (a2 - a3)
    pi_n = complete_pi(n, mc)
    amplitude0 = math.atan2(M[p2] / (s2 * A2), M[p1] / A1)
    u = elliptic_f(amplitude0, mc) + lam * t
    j = math.floor(u / (2.0 * K) + 0.5)
    sn, cn, dn = sncndn(u - 2.0 * j * K, em[:levels], en[:levels], c)
    amplitude = j * math.pi + math.atan2(sn, cn)
    if j % 2.0 != 0.0:
        sn, cn = -sn, -cn
    psi = G * a3 * t + G * (a1 - a3) / lam * (elliptic_pi(amplitude, n, mc, pi_n) - elliptic_pi(amplitude0, n, mc, pi_n))
    new0, new1, new2 = s3 * A3 * dn, s3 * A3 * dn, s3 * A3 * dn
    for index, value in ((p1, A1 * cn), (p2, s2 * A2 * sn)):
        if index == 0:
            new0 = value
        elif index == 1:
            new1 = value
        else:
            new2 = value
    f = _anchor_frame(M[0], M[1], M[2], p3)
    g = _anchor_frame(new0, new1, new2, p3)
    cs = math.cos(psi)
    sn_psi = math.sin(psi)
    # Z A(M(t)): rows (cos r1 - sin r2, sin r1 + cos r2, r3); R <- R A(M0)^T Z A(M(t))
    z = (cs * g[0] - sn_psi * g[3], cs * g[1] - sn_psi * g[4], cs * g[2] - sn_psi * g[5],
         sn_psi * g[0] + cs * g[3], sn_psi * g[1] + cs * g[4], sn_psi * g[2] + cs * g[5], g[6], g[7], g[8])
    for row in range(3):
        q0 = R[row, 0] * f[0] + R[row, 1] * f[1] + R[row, 2] * f[2]
        q1 = R[row, 0] * f[3] + R[row, 1] * f[4] + R[row, 2] * f[5]
        q2 = R[row, 0] * f[6] + R[row, 1] * f[7] + R[row, 2] * f[8]
        R[row, 0] = q0 * z[0] + q1 * z[3] + q2 * z[6]
        R[row, 1] = q0 * z[1] + q1 * z[4] + q2 * z[7]
        R[row, 2] = q0 * z[2] + q1 * z[5] + q2 * z[8]
    M[0] = new0
    M[1] = new1
    M[2] = new2


@njit(cache=True)
def anchor_exact_kick(M, R, a, w, gammas, dt, n_steps):
    """``n_steps`` of ``prod_i K(g_i dt/2) F(g_i dt) K(g_i dt/2)`` with the plain free flow
    above (kicks not merged): the hand-written baseline of ``exact-kick-*``."""
    em = np.empty(40)
    en = np.empty(40)
    for _ in range(n_steps):
        for g in gammas:
            kick(M, R, w, 0.5 * g * dt)
            _anchor_free_flow(M, R, a, g * dt, em, en)
            kick(M, R, w, 0.5 * g * dt)
