"""Hard bodies of ``dirac bench --stress``: every method against the 50-digit reference.

Near the separatrix (``M(0)`` within ``1e-6, 1e-9, 1e-12`` of the intermediate axis, and
exactly on it), near-symmetric (``I_1 = I_2 (1 + 1e-9)``), needle-like (``I = (1e-4, 1, 1)``),
flat (``I_3 = I_1 + I_2``) and a fast spin about the axis of smallest moment. Every method's
error in ``M`` and ``R`` against :func:`~dirac.bench.taylor_reference.taylor_reference` is
reported; ``exact`` must be accurate to ``64 eps (1 + omega t_end)``
(``omega = |M| max 1/I_i``, :func:`exact_tolerance`), and no method may return a
non-finite value silently (a stop with an error is fine).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from dirac.bench.standard_body import STANDARD_INERTIA, quietly
from dirac.bench.stress_criteria import EPS
from dirac.bench.taylor_reference import taylor_reference

__all__ = ["HardBody", "HARD_BODIES", "HARD_BODY_METHODS", "exact_tolerance", "hard_body_rows"]


def _unit(v: Sequence[float]) -> tuple[float, float, float]:
    x = np.asarray(v, dtype=float)
    a, b, c = x / np.linalg.norm(x)
    return float(a), float(b), float(c)


def _scaled(factor: float, v: tuple[float, float, float]) -> tuple[float, float, float]:
    return factor * v[0], factor * v[1], factor * v[2]


@dataclass(frozen=True)
class HardBody:
    """A hard case: inertia, initial ``M`` (``R(0) = 1``), time span in radians of the
    fastest rotation (``t_end = radians / omega``, ``omega = |M| max 1/I_i``) unless
    ``t_end`` is given."""

    name: str
    inertia: tuple[float, float, float]
    M0: tuple[float, float, float]
    description: str
    radians: float = 60.0
    t_end: float | None = None

    @property
    def omega(self) -> float:
        """Fastest rotation rate ``|M| max 1/I_i``."""
        return float(np.linalg.norm(self.M0) / min(self.inertia))

    @property
    def span(self) -> float:
        """The integration time."""
        return float(self.t_end) if self.t_end is not None else self.radians / self.omega


_GENERIC = _unit([0.6, 0.48, 0.64])

#: The hard cases of the stress benchmark.
HARD_BODIES: tuple[HardBody, ...] = (
    HardBody("separatrix 1e-6", STANDARD_INERTIA, (0.6e-6, 1.0, 0.8e-6),
             "M(0) within 1e-6 of the intermediate axis (tennis racket): flips at t ~ 28, 90", t_end=120.0),
    HardBody("separatrix 1e-9", STANDARD_INERTIA, (0.6e-9, 1.0, 0.8e-9),
             "M(0) within 1e-9 of the intermediate axis: first flip at t ~ 42", t_end=120.0),
    HardBody("separatrix 1e-12", STANDARD_INERTIA, (0.6e-12, 1.0, 0.8e-12),
             "M(0) within 1e-12 of the intermediate axis: first flip at t ~ 55", t_end=120.0),
    HardBody("on the separatrix", STANDARD_INERTIA, (1e-9, 1.0, 1e-9),
             "M(0) exactly on the separatrix (m = 1): one flip, then the axis is approached forever", t_end=120.0),
    HardBody("near-symmetric", (1.0 + 1e-9, 1.0, 0.5), _GENERIC, "I_1 = I_2 (1 + 1e-9): modulus m ~ 1e-9"),
    HardBody("needle", (1e-4, 1.0, 1.0), _GENERIC, "I = (1e-4, 1, 1): spin 6000 times faster than the tumbling"),
    HardBody("flat", (1.0, 2.0, 3.0), _GENERIC, "I_3 = I_1 + I_2: the plane-body limit"),
    HardBody("fast spin", STANDARD_INERTIA, _scaled(1e3, _unit([1e-3, 2e-3, 1.0])),
             "|M| = 1000 nearly along the axis of smallest moment (I_3 = 2/3)"),
)

#: Methods compared on every hard body (fixed steps ``dt = 0.02 / omega``; scipy at 1e-10).
HARD_BODY_METHODS: tuple[str, ...] = (
    "exact", "lie-poisson-2", "lie-poisson-4", "lie-poisson-6", "lie-poisson-8", "lie-poisson-sym-4",
    "midpoint", "scipy-RK45", "scipy-DOP853",
)


def exact_tolerance(body: HardBody) -> float:
    """Accuracy ``exact`` must reach: ``64 eps (1 + omega t_end)`` (phase round-off)."""
    return 64.0 * EPS * (1.0 + body.omega * body.span)


def _method_error(body: HardBody, method: str, times: np.ndarray, M_ref: np.ndarray, R_ref: np.ndarray | None,
                  step_radians: float) -> dict:
    from dirac.errors import IntegrationError
    from dirac.flows.integration import integrate
    from dirac.flows.problems import RigidBodyProblem

    problem = quietly(lambda: RigidBodyProblem(np.array(body.inertia), np.array(body.M0)))
    outputs = ["M", "R"] if R_ref is not None else ["M"]
    dt = step_radians / body.omega
    row: dict = {"case": body.name, "method": method, "error_M": None, "error_R": None, "status": "ok"}
    start = time.perf_counter()
    try:
        solution = integrate(problem, method, t_end=float(times[-1]), dt=dt, samples=len(times),
                             outputs=outputs, tolerance=1e-10)
    except IntegrationError as exc:
        row["status"] = "stopped: " + " ".join(str(exc).split())
        row["wall_seconds"] = time.perf_counter() - start
        return row
    row["wall_seconds"] = time.perf_counter() - start
    row["steps"] = int(solution.steps)
    M = solution["M"]
    finite = bool(np.all(np.isfinite(M)))
    row["error_M"] = float(np.max(np.abs(M - M_ref)) / np.linalg.norm(body.M0))
    if R_ref is not None:
        R = solution["R"]
        finite = finite and bool(np.all(np.isfinite(R)))
        row["error_R"] = float(np.max(np.abs(R - R_ref)))
    if not finite:
        row["status"] = "NON-FINITE (silent)"
    return row


def hard_body_rows(body: HardBody, methods: Sequence[str] = HARD_BODY_METHODS, samples: int = 201,
                   with_R: bool = True, step_radians: float = 0.02, span_fraction: float = 1.0) -> list[dict]:
    """Error of each method on ``body`` against :func:`taylor_reference` (one row each).

    Over ``[0, span_fraction * body.span]`` with ``samples`` uniform output times and
    fixed steps ``dt = step_radians / omega``. ``exact`` passes when its errors are below
    :func:`exact_tolerance`; every method passes when it returns finite values or stops
    with an error (never a silent NaN).
    """
    times = np.linspace(0.0, body.span * span_fraction, samples)
    start = time.perf_counter()
    M_ref, R_ref = taylor_reference(body.inertia, body.M0, None, times, with_R=with_R)
    reference_seconds = time.perf_counter() - start
    rows = []
    for method in methods:
        row = _method_error(body, method, times, M_ref, R_ref, step_radians)
        if method == "exact":
            bound = exact_tolerance(body)
            row["bound"] = bound
            errors = [e for e in (row["error_M"], row["error_R"]) if e is not None]
            row["passed"] = row["status"] == "ok" and bool(errors) and max(errors) <= bound
        else:
            row["passed"] = not row["status"].startswith("NON-FINITE")
        row["reference_seconds"] = reference_seconds
        rows.append(row)
    return rows

