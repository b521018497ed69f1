"""``dirac bench --stress``: long runs, hard bodies and constrained long runs (issue #6).

Three parts, each a list of rows with a pass/fail verdict against a stated criterion:

1. **Long runs** on the standard body (PHYSICS.md §4, ``I = (2, 1, 2/3)``,
   ``M(0) = (cos 1.1, 0, sin 1.1)``, ``R(0) = 1``): ``lie-poisson-2`` for ``1e7`` steps and
   ``lie-poisson-4``/``-6`` for ``1e6`` steps. The Casimir ``|M|^2`` and ``R^T R = 1`` of
   the Euler–Poisson flow (250)–(251) must stay within ``2e-12`` (the round-off random
   walk of ``1e7`` steps); the energy ``H_0`` (247) error must not grow secularly: its
   maximum over the last tenth of the run may exceed that over the first tenth by at
   most a factor 2 plus a round-off allowance ``10 eps sqrt(steps) |H_0|`` (a linear drift
   gives a factor of about 10).
2. **Hard bodies**: near the separatrix (``M(0)`` within ``1e-6, 1e-9, 1e-12`` of the
   intermediate axis, and exactly on it), near-symmetric (``I_1 = I_2 (1 + 1e-9)``),
   needle-like (``I = (1e-4, 1, 1)``), flat (``I_3 = I_1 + I_2``) and a fast spin about
   the axis of smallest moment. Every method's error in ``M`` and ``R`` against a
   high-precision reference (:func:`taylor_reference`) is reported; ``exact`` must be
   accurate to ``64 eps (1 + omega t_end)`` (``omega = |M| max 1/I_i``), and no method may
   return a non-finite value silently (a stop with an error is fine).
3. **Constrained long runs**: ``rattle-2`` on the pendulum and the double pendulum over
   ``1e6`` steps; the constraint residual stays at the Newton tolerance
   (``|chi(q)| <= tol (1 + |q|^2)``, the kernels' stopping rule) and the energy error is
   bounded as in part 1.

The reference of part 2 integrates (250)–(251) by Taylor series in fixed-point integer
arithmetic (168 fractional bits, about 50 digits) with step control on the scaled
coefficients: independent of every closed form and of every method under test.
"""

from __future__ import annotations

import json
import math
import sys
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np

__all__ = [
    "taylor_reference",
    "STANDARD_INERTIA",
    "STANDARD_M0",
    "HardBody",
    "HARD_BODIES",
    "HARD_BODY_METHODS",
    "exact_tolerance",
    "long_run",
    "energy_drift_verdict",
    "hard_body_rows",
    "constrained_long_run",
    "run_stress",
    "format_table",
    "main",
]

EPS = float(np.finfo(float).eps)

#: The standard body of PHYSICS.md §4 (no physical body: 1 + 2/3 < 2; warned about).
STANDARD_INERTIA = (2.0, 1.0, 2.0 / 3.0)
STANDARD_M0 = (math.cos(1.1), 0.0, math.sin(1.1))

# --------------------------------------------------------------------------------------
# 1. High-precision reference: Taylor series of the Euler-Poisson equations
# --------------------------------------------------------------------------------------
_BITS = 168
_ONE = 1 << _BITS


def _fixed(value: object) -> int:
    fraction = value if isinstance(value, Fraction) else Fraction(value)  # exact for floats
    return (fraction.numerator << _BITS) // fraction.denominator


def _float(value: int) -> float:
    return float(Fraction(value, _ONE))


def _dot(u: list[int], v: list[int]) -> int:
    return sum(map(int.__mul__, u, v))


def _scaled_coefficients(M: list[int], R: list[list[int]], ha: list[int], order: int, with_R: bool):  # noqa: ANN202
    """Taylor coefficients of ``M(t0 + h s)``, ``R(t0 + h s)`` in ``s`` (fixed point).

    ``dM/ds = M x (h a M)``, ``dR/ds = R hat(h a M)`` (250)-(251) with ``a = 1/I``: the
    coefficients of products are Cauchy products, those of ``d/ds`` divide by ``k + 1``.
    Scaling by ``h`` keeps every coefficient near 1 (no underflow of the tail).
    """
    m = [[x] for x in M]
    w = [[(ha[i] * M[i]) >> _BITS] for i in range(3)]
    r = [[[R[i][j]] for j in range(3)] for i in range(3)] if with_R else []
    for k in range(order):
        rw = [w[i][::-1] for i in range(3)]
        d = (
            _dot(m[1], rw[2]) - _dot(m[2], rw[1]),
            _dot(m[2], rw[0]) - _dot(m[0], rw[2]),
            _dot(m[0], rw[1]) - _dot(m[1], rw[0]),
        )
        if with_R:
            dr = [
                (
                    _dot(row[1], rw[2]) - _dot(row[2], rw[1]),
                    _dot(row[2], rw[0]) - _dot(row[0], rw[2]),
                    _dot(row[0], rw[1]) - _dot(row[1], rw[0]),
                )
                for row in r
            ]
        for i in range(3):
            c = (d[i] >> _BITS) // (k + 1)
            m[i].append(c)
            w[i].append((ha[i] * c) >> _BITS)
        if with_R:
            for i in range(3):
                for j in range(3):
                    r[i][j].append((dr[i][j] >> _BITS) // (k + 1))
    return m, r


def taylor_reference(
    inertia: Sequence[object],
    M0: Sequence[object],
    R0: object | None,
    times: Sequence[float],
    *,
    with_R: bool = True,
    order: int = 36,
    tolerance: float = 2.0**-112,
) -> tuple[np.ndarray, np.ndarray | None]:
    """High-precision solution of the Euler–Poisson equations (250)–(251).

    Taylor series of order ``order`` in fixed-point integer arithmetic (168 fractional
    bits). The coefficients are those of ``(M, R)(t0 + h s)`` in ``s``; a step is accepted
    when the last two coefficients are below ``tolerance`` (relative to ``max |M_i|`` for
    ``M``, absolute for ``R``), halved otherwise, and doubled after a step whose tail was
    ``2^order`` times smaller. Step ends are dyadic rationals, so times are exact.
    Independent of every closed form and integrator of the project.

    Parameters
    ----------
    inertia : sequence of 3 numbers (float or :class:`fractions.Fraction`, exact)
    M0 : sequence of 3 numbers
        Initial body angular momentum (floats are taken exactly).
    R0 : array_like (3, 3) or None
        Initial attitude; default the identity.
    times : increasing sequence of floats >= 0
    with_R : bool
        Also integrate ``R`` (about 7 times the work of ``M`` alone).

    Returns
    -------
    M : numpy.ndarray, shape (len(times), 3)
    R : numpy.ndarray, shape (len(times), 3, 3), or None without ``with_R``
    """
    a = [1 / (v if isinstance(v, Fraction) else Fraction(float(v))) for v in inertia]
    M = [_fixed(v if isinstance(v, Fraction) else float(v)) for v in M0]
    R0 = np.eye(3) if R0 is None else np.asarray(R0, dtype=float)
    R = [[_fixed(float(R0[i][j])) for j in range(3)] for i in range(3)]
    scale = max(abs(x) for x in M)
    if scale == 0:
        M_out = np.zeros((len(times), 3))
        return M_out, (np.repeat(R0[None], len(times), axis=0) if with_R else None)
    speed = _float(scale) * float(max(a))
    h = Fraction(2.0 ** math.floor(math.log2(1.0 / (16.0 * speed))))
    t = Fraction(0)
    out_M: list[list[float]] = []
    out_R: list[list[list[float]]] = []
    for target_value in times:
        target = Fraction(float(target_value))
        while t < target:
            step = min(h, target - t)
            ha = [_fixed(x * step) for x in a]
            m, r = _scaled_coefficients(M, R, ha, order, with_R)
            tail = max(abs(m[i][-1]) + abs(m[i][-2]) for i in range(3)) / scale
            if with_R:
                tail = max(tail, max(abs(r[i][j][-1]) + abs(r[i][j][-2]) for i in range(3) for j in range(3)) / _ONE)
            if tail > tolerance:
                h = step / 2
                continue
            M = [sum(c) for c in m]
            if with_R:
                R = [[sum(r[i][j]) for j in range(3)] for i in range(3)]
            t += step
            if step == h and tail < tolerance / 2.0**order:
                h *= 2
        out_M.append([_float(x) for x in M])
        if with_R:
            out_R.append([[_float(x) for x in row] for row in R])
    return np.array(out_M), (np.array(out_R) if with_R else None)


# --------------------------------------------------------------------------------------
# 2. Long runs of the splitting methods
# --------------------------------------------------------------------------------------
def energy_drift_verdict(energy_error: np.ndarray, steps: int, energy: float) -> tuple[float, float, bool]:
    """``(max over first tenth, max over last tenth, bounded?)`` of an energy error series.

    Bounded means ``last <= 2 first + 10 eps sqrt(steps) |energy|`` (module docstring).
    """
    error = np.abs(np.asarray(energy_error, dtype=float))
    tenth = max(1, error.shape[0] // 10)
    first = float(np.max(error[1 : tenth + 1])) if error.shape[0] > 1 else float(error[0])
    last = float(np.max(error[-tenth:]))
    allowance = 10.0 * EPS * math.sqrt(max(steps, 1)) * abs(energy)
    return first, last, bool(last <= 2.0 * first + allowance)


def _quiet_problem(factory: Callable[[], object]) -> object:
    """Build a problem with the standard body's triangle-inequality warning silenced."""
    from dirac.errors import DiracWarning

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DiracWarning)
        return factory()


def long_run(method: str, steps: int, dt: float, samples: int = 1001) -> dict:
    """Run ``method`` for ``steps`` steps of ``dt`` on the standard body; one table row.

    ``casimir`` is ``max | |M|^2 - |M(0)|^2 |``, ``orthogonality`` is
    ``max |R^T R - 1|`` over the samples; both must stay within ``2e-12``.
    """
    from dirac.flows.integration import integrate
    from dirac.flows.problems import RigidBodyProblem

    problem = _quiet_problem(lambda: RigidBodyProblem(STANDARD_INERTIA, STANDARD_M0))
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
    passed = casimir <= 2e-12 and orthogonality <= 2e-12 and bounded and bool(np.all(np.isfinite(energy)))
    return {
        "case": "standard body", "method": method, "steps": int(solution.steps), "dt": float(solution.dt),
        "casimir_error": casimir, "orthogonality_error": orthogonality,
        "energy_error_first_tenth": first, "energy_error_last_tenth": last,
        "cpu_seconds": float(solution.cpu_seconds), "wall_seconds": wall, "passed": bool(passed),
    }


# --------------------------------------------------------------------------------------
# 3. Hard bodies
# --------------------------------------------------------------------------------------
def _unit(v: Sequence[float]) -> tuple[float, float, float]:
    x = np.asarray(v, dtype=float)
    return tuple(float(c) for c in x / np.linalg.norm(x))  # type: ignore[return-value]


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

#: The hard cases of issue #6, item 2.
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
    HardBody("fast spin", STANDARD_INERTIA, tuple(1e3 * c for c in _unit([1e-3, 2e-3, 1.0])),  # type: ignore[arg-type]
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

    problem = _quiet_problem(lambda: RigidBodyProblem(body.inertia, body.M0))
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


# --------------------------------------------------------------------------------------
# 4. Constrained long runs
# --------------------------------------------------------------------------------------
def _constrained_problem(system: str):  # noqa: ANN202
    import dirac
    from dirac.flows.mechanics import MechanicalSystem
    from dirac.flows.problems import ConstrainedProblem

    mechanics = MechanicalSystem.from_lagrangian(dirac.load_system(system))
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
        "case": system, "method": method, "steps": int(solution.steps), "dt": float(solution.dt),
        "position_residual": position, "velocity_residual": velocity,
        "energy_error_first_tenth": first, "energy_error_last_tenth": last,
        "cpu_seconds": float(solution.cpu_seconds), "wall_seconds": wall,
        "passed": bool(position_ok and velocity_ok and bounded),
    }


# --------------------------------------------------------------------------------------
# 5. The whole suite, the table, the command
# --------------------------------------------------------------------------------------
@dataclass
class StressPlan:
    """Sizes of one stress run (``quick`` shrinks every part)."""

    long_runs: list[tuple[str, int, float]] = field(default_factory=list)
    constrained: list[tuple[str, str, int, float]] = field(default_factory=list)
    bodies: tuple[HardBody, ...] = HARD_BODIES
    samples: int = 201


def plan(quick: bool) -> StressPlan:
    """The full sizes of issue #6, or a quick version (``--quick``) 100 times shorter."""
    factor = 100 if quick else 1
    return StressPlan(
        long_runs=[("lie-poisson-2", 10_000_000 // factor, 0.01), ("lie-poisson-4", 1_000_000 // factor, 0.05),
                   ("lie-poisson-6", 1_000_000 // factor, 0.05)],
        constrained=[("pendulum", "rattle-2", 1_000_000 // factor, 0.01),
                     ("double_pendulum", "rattle-2", 1_000_000 // factor, 0.01)],
        bodies=HARD_BODIES,
        samples=101 if quick else 201,
    )


def run_stress(quick: bool = False, progress: Callable[[str], None] | None = None) -> dict:
    """Run every part; return ``{"machine", "long_runs", "hard_bodies", "constrained", "passed"}``."""
    from dirac.bench.report import machine_description

    say = progress or (lambda message: None)
    sizes = plan(quick)
    document: dict = {"machine": machine_description(), "quick": bool(quick)}
    start = time.perf_counter()
    document["long_runs"] = []
    for method, steps, dt in sizes.long_runs:
        say(f"long run: {method}, {steps} steps")
        document["long_runs"].append(long_run(method, steps, dt))
    document["hard_bodies"] = []
    for body in sizes.bodies:
        say(f"hard body: {body.name}")
        document["hard_bodies"].extend(hard_body_rows(body, samples=sizes.samples))
    document["constrained"] = []
    for system, method, steps, dt in sizes.constrained:
        say(f"constrained long run: {system}, {method}, {steps} steps")
        document["constrained"].append(constrained_long_run(system, method, steps, dt))
    document["wall_seconds"] = time.perf_counter() - start
    rows = document["long_runs"] + document["hard_bodies"] + document["constrained"]
    document["passed"] = all(row["passed"] for row in rows)
    return document


def _e(value: float | None) -> str:
    return "-" if value is None else f"{value:.2e}"


def format_table(document: dict) -> str:
    """The three parts as fixed-width text tables (also valid Markdown)."""
    lines = ["Long runs, standard body I = (2, 1, 2/3) (limits: deviations of M.M and R^T R <= 2e-12; energy bounded)", ""]
    lines.append("| method | steps | dt | max dev. of M.M | max dev. of R^T R from 1 | energy err. first 1/10 | energy err. last 1/10 | CPU s | pass |")
    lines.append("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |")
    for r in document["long_runs"]:
        lines.append(f"| {r['method']} | {r['steps']:.0e} | {r['dt']:g} | {_e(r['casimir_error'])} | "
                     f"{_e(r['orthogonality_error'])} | {_e(r['energy_error_first_tenth'])} | "
                     f"{_e(r['energy_error_last_tenth'])} | {r['cpu_seconds']:.1f} | {'yes' if r['passed'] else 'NO'} |")
    lines += ["", "Hard bodies: max error over the samples against the 50-digit Taylor reference "
              "(M relative to the norm of M(0); exact must stay below its bound; no silent NaN)", ""]
    lines.append("| body | method | error M | error R | status | pass |")
    lines.append("| --- | --- | ---: | ---: | --- | --- |")
    for r in document["hard_bodies"]:
        status = r["status"] if len(r["status"]) <= 60 else r["status"][:57] + "..."
        if r["method"] == "exact" and "bound" in r:
            status += f" (bound {r['bound']:.1e})"
        lines.append(f"| {r['case']} | {r['method']} | {_e(r['error_M'])} | {_e(r['error_R'])} | {status} | "
                     f"{'yes' if r['passed'] else 'NO'} |")
    lines += ["", "Constrained long runs (limits: abs chi <= tol (1 + q.q), tol = 1e-12; velocity residual at "
              "round-off; energy bounded)", ""]
    lines.append("| system | method | steps | dt | max abs chi(q) | max abs G M^-1 p | energy err. first 1/10 | "
                 "energy err. last 1/10 | CPU s | pass |")
    lines.append("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |")
    for r in document["constrained"]:
        lines.append(f"| {r['case']} | {r['method']} | {r['steps']:.0e} | {r['dt']:g} | {_e(r['position_residual'])} | "
                     f"{_e(r['velocity_residual'])} | {_e(r['energy_error_first_tenth'])} | "
                     f"{_e(r['energy_error_last_tenth'])} | {r['cpu_seconds']:.1f} | {'yes' if r['passed'] else 'NO'} |")
    lines += ["", f"all passed: {'yes' if document['passed'] else 'NO'}; wall time {document['wall_seconds']:.0f} s"]
    return "\n".join(lines)


def main(args: object) -> int:
    """Entry point of ``dirac bench --stress [--quick] [--json FILE]``.

    Prints the machine line and the tables; writes every row as JSON with ``--json``.
    Returns 0 when every row passed, 1 otherwise.
    """
    from dirac.bench.report import machine_line

    quick = bool(getattr(args, "quick", False))
    json_path = getattr(args, "json", None)
    show = not bool(getattr(args, "no_progress", False))

    def progress(message: str) -> None:
        if show:
            print(f"stress: {message}", file=sys.stderr, flush=True)

    document = run_stress(quick=quick, progress=progress)
    print(f"machine: {machine_line(document['machine'])}")
    print(format_table(document))
    if json_path:
        with open(json_path, "w", encoding="utf-8") as stream:
            json.dump(document, stream, indent=1, default=lambda v: v.item() if hasattr(v, "item") else str(v))
    return 0 if document["passed"] else 1

