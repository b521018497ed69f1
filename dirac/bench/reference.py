"""Independent high-precision references for the work–precision benchmark.

Rigid body: a Taylor-series integrator of the Euler–Poisson equations (250)–(251) in
exact fixed-point arithmetic (Python integers scaled by ``2**FRACTION_BITS``, about 36
digits). The vector field ``dM/dt = M x Omega``, ``dR/dt = R hat(Omega)``,
``Omega = I^{-1} M`` is bilinear, so the Taylor coefficients follow exactly from Cauchy
products: ``y_{k+1} = B_k / (k+1)``, ``B_k = sum_{s<=k} B(y_s, y_{k-s})``. It shares no code
with the package's methods (no splitting, no elliptic functions), so it checks all of
them. The step ``h`` keeps the last two terms of the series below ``1e-28``; the result
is accurate to about 1e-30 (the test suite checks it against the 40-digit
values of the standard test case in docs/conventions.md). The inertia and initial values are taken exactly as the double-precision
numbers the methods receive.

Pendulum: the period ``T = 4 K(sin^2(theta0/2)) / sqrt(g/l)`` with ``K`` the complete
elliptic integral of the first kind (mpmath, 30 digits): after whole periods the state
returns to its initial value exactly.

Double pendulum: no closed form; the reference is scipy DOP853 at ``rtol = 1e-13`` on the
minimal (angle) formulation, a different set of equations from the constrained Cartesian
ones the package integrates; its own error is estimated by a second run at
``rtol = 1e-12`` and reported.

Slow references are cached as JSON under the user cache directory
(``$DIRAC_CACHE_DIR/bench`` or ``~/.cache/dirac/bench``), keyed by their inputs.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import tempfile
from collections.abc import Iterable, Sequence
from fractions import Fraction
from operator import mul
from pathlib import Path
from typing import SupportsFloat

import numpy as np
from numpy.typing import ArrayLike

__all__ = [
    "FRACTION_BITS",
    "rigid_body_reference",
    "taylor_rigid_body",
    "pendulum_period",
    "double_pendulum_reference",
    "cache_directory",
]

#: Fixed-point scale of the Taylor integrator: numbers are integers times 2**-FRACTION_BITS.
FRACTION_BITS = 124
_ONE = 1 << FRACTION_BITS
_FLOOR = 2.0 ** (8 - FRACTION_BITS)  # coefficient sizes below this are not resolved
_REFERENCE_VERSION = 2


def cache_directory() -> Path:
    """``$DIRAC_CACHE_DIR/bench``, else ``~/.cache/dirac/bench`` (temp dir if not writable)."""
    base = os.environ.get("DIRAC_CACHE_DIR")
    root = Path(base) if base else Path.home() / ".cache" / "dirac"
    path = root / "bench"
    try:
        path.mkdir(parents=True, exist_ok=True)
        return path
    except OSError:
        fallback = Path(tempfile.gettempdir()) / "dirac-bench-cache"
        fallback.mkdir(parents=True, exist_ok=True)
        return fallback


def _fixed(x: float | Fraction) -> int:
    """Round an exact rational (a double is one) to the fixed-point grid."""
    f = Fraction(x)
    return (f.numerator * _ONE * 2 + f.denominator) // (2 * f.denominator)


# an input taken exactly: a float (or anything float() takes), a Fraction, or a string of decimal digits
_ExactInput = SupportsFloat | Fraction | str


def _exact(x: _ExactInput) -> Fraction:
    """An exact rational: floats exactly, strings as exact decimals, Fractions as they are."""
    if isinstance(x, (Fraction, str)):
        return Fraction(x)
    return Fraction(float(x))


def _to_float(n: int) -> float:
    return float(Fraction(n, _ONE))


def _taylor_step(y: list[int], a: list[int], order: int) -> list[list[int]]:
    """Taylor coefficients ``y_0..y_order`` (fixed point, 12 components each) at ``y``."""
    shift = FRACTION_BITS
    coeffs = [list(y)]
    # columns of the coefficient history, one list per component, for fast Cauchy sums
    cols = [[v] for v in y]
    wcols = [[(y[i] * a[i]) >> shift] for i in range(3)]  # Omega = a * M
    for k in range(order):
        m0, m1, m2 = cols[0], cols[1], cols[2]
        w0, w1, w2 = (c[::-1] for c in wcols)

        def dot(u: list[int], v: list[int]) -> int:
            return sum(map(mul, u, v))

        dm = [dot(m1, w2) - dot(m2, w1), dot(m2, w0) - dot(m0, w2), dot(m0, w1) - dot(m1, w0)]
        dr = []
        for row in range(3):
            r0, r1, r2 = cols[3 + 3 * row], cols[4 + 3 * row], cols[5 + 3 * row]
            dr += [dot(r1, w2) - dot(r2, w1), dot(r2, w0) - dot(r0, w2), dot(r0, w1) - dot(r1, w0)]
        divisor = (k + 1) << shift
        new = [(v + (divisor >> 1)) // divisor for v in dm + dr]
        coeffs.append(new)
        for i in range(12):
            cols[i].append(new[i])
        for i in range(3):
            wcols[i].append((new[i] * a[i]) >> shift)
    return coeffs


def taylor_rigid_body(
    inertia: Iterable[_ExactInput], M0: Iterable[_ExactInput], R0: Iterable[Iterable[_ExactInput]],
    times: list[float], order: int = 30, tol: float = 1e-28,
) -> tuple[np.ndarray, np.ndarray]:
    """Integrate (250)–(251) by fixed-point Taylor series and return ``M``, ``R`` at ``times``.

    Parameters
    ----------
    inertia : sequence of 3 numbers
        Floats are taken exactly; ``fractions.Fraction`` entries give exact rationals.
    M0 : sequence of 3 numbers
        Floats, Fractions, or strings of decimal digits (exact decimals).
    R0 : 3 x 3 nested sequence of numbers
    times : list of float
        Increasing output times > 0 (each hit exactly, as a rational step end).
    order : int
        Degree of the Taylor polynomial.
    tol : float
        Bound on the last two series terms ``|y_k| h^k`` of a step.

    Returns
    -------
    M : numpy.ndarray, shape (len(times), 3)
    R : numpy.ndarray, shape (len(times), 3, 3)
    """
    a = [_fixed(Fraction(1) / _exact(i)) for i in inertia]
    y = [_fixed(_exact(v)) for v in M0] + [_fixed(_exact(v)) for row in R0 for v in row]
    t = Fraction(0)
    M_out, R_out = [], []
    for time_point in times:
        target = Fraction(float(time_point))
        while t < target:
            coeffs = _taylor_step(y, a, order)
            # the last two terms set h; coefficients that fall below the fixed-point grid
            # are floored (else h would be unbounded), and h stays below 2 / |Omega|
            size = [max(max(abs(v) for v in coeffs[k]) / _ONE, _FLOOR) for k in (order - 1, order)]
            omega = max(abs(y[i] * a[i]) for i in range(3)) / _ONE / _ONE * math.sqrt(3.0)
            h_float = min(
                (tol / size[0]) ** (1.0 / (order - 1)),
                (tol / size[1]) ** (1.0 / order),
                2.0 / max(omega, 1e-300),
            )
            h = Fraction(h_float).limit_denominator(1 << 40)
            if t + h >= target:
                h = target - t
            hf = _fixed(h)
            # Horner: y(t + h) = sum_k y_k h^k
            acc = list(coeffs[order])
            for k in range(order - 1, -1, -1):
                acc = [((v * hf) >> FRACTION_BITS) + c for v, c in zip(acc, coeffs[k])]
            y = acc
            t += h
        M_out.append([_to_float(v) for v in y[:3]])
        R_out.append([_to_float(v) for v in y[3:]])
    return np.array(M_out), np.array(R_out).reshape(-1, 3, 3)


def _cached(kind: str, key: dict, compute) -> dict:
    text = json.dumps({"kind": kind, "version": _REFERENCE_VERSION, **key}, sort_keys=True)
    name = hashlib.sha256(text.encode()).hexdigest()[:20]
    path = cache_directory() / f"{kind}_{name}.json"
    if path.exists():
        try:
            return json.loads(path.read_text())
        except (OSError, ValueError):
            pass
    value = compute()
    tmp = path.with_suffix(".tmp")
    try:
        tmp.write_text(json.dumps(value))
        tmp.replace(path)
    except OSError:
        pass
    return value


def rigid_body_reference(inertia: ArrayLike, M0: ArrayLike, t_end: float) -> tuple[np.ndarray, np.ndarray]:
    """``M(t_end)``, ``R(t_end)`` of the body with ``R(0) = 1`` (cached Taylor reference)."""
    inertia_values = [float(v) for v in np.asarray(inertia, dtype=float)]
    M0_values = [float(v) for v in np.asarray(M0, dtype=float)]
    key = {"inertia": [v.hex() for v in inertia_values], "M0": [v.hex() for v in M0_values],
           "t_end": float(t_end).hex()}

    def compute() -> dict:
        M, R = taylor_rigid_body(inertia_values, M0_values, np.eye(3), [float(t_end)])
        return {"M": M[0].tolist(), "R": R[0].tolist()}

    value = _cached("rigid_body", key, compute)
    return np.array(value["M"]), np.array(value["R"])


def pendulum_period(g: float, length: float, theta0: float) -> float:
    """Period of the planar pendulum released at rest from angle ``theta0`` (from the
    downward vertical): ``T = 4 sqrt(l/g) K(m)``, ``m = sin^2(theta0/2)``, in 30 digits."""
    import mpmath

    with mpmath.workdps(30):
        m = mpmath.sin(mpmath.mpf(theta0) / 2) ** 2
        return float(4 * mpmath.sqrt(mpmath.mpf(length) / mpmath.mpf(g)) * mpmath.ellipk(m))


def _double_pendulum_angles_rhs(t: float, y: np.ndarray, m1: float, m2: float, l1: float, l2: float, g: float) -> list[float]:
    """Double pendulum in the angles from the downward vertical (textbook minimal form).

    ``den = 2 m1 + m2 - m2 cos(2 a1 - 2 a2)``;
    ``a1'' = [-g (2 m1 + m2) sin a1 - m2 g sin(a1 - 2 a2)
    - 2 sin(a1 - a2) m2 (w2^2 l2 + w1^2 l1 cos(a1 - a2))] / (l1 den)``;
    ``a2'' = 2 sin(a1 - a2) [w1^2 l1 (m1 + m2) + g (m1 + m2) cos a1
    + w2^2 l2 m2 cos(a1 - a2)] / (l2 den)``.
    """
    a1, a2, w1, w2 = y
    d = a1 - a2
    den = 2.0 * m1 + m2 - m2 * math.cos(2.0 * d)
    dw1 = (
        -g * (2.0 * m1 + m2) * math.sin(a1)
        - m2 * g * math.sin(a1 - 2.0 * a2)
        - 2.0 * math.sin(d) * m2 * (w2 * w2 * l2 + w1 * w1 * l1 * math.cos(d))
    ) / (l1 * den)
    dw2 = (
        2.0 * math.sin(d) * (w1 * w1 * l1 * (m1 + m2) + g * (m1 + m2) * math.cos(a1) + w2 * w2 * l2 * m2 * math.cos(d))
    ) / (l2 * den)
    return [w1, w2, dw1, dw2]


def double_pendulum_reference(
    angles: Sequence[float], rates: Sequence[float], t_end: float, params: dict[str, float]
) -> tuple[np.ndarray, float]:
    """Cartesian positions ``(x1, y1, x2, y2)`` at ``t_end`` and an estimate of their error.

    ``angles`` and ``rates`` are the two initial angles and angular velocities.

    Integrates the angle equations with DOP853 at ``rtol = 1e-13`` (and ``1e-12`` for the
    error estimate); ``y`` points up, the angles are measured from the downward vertical.
    """
    from scipy.integrate import solve_ivp

    m1, m2, l1, l2, g = (float(params[k]) for k in ("m1", "m2", "l1", "l2", "g"))
    key = {"angles": list(angles), "rates": list(rates), "t_end": t_end, "params": [m1, m2, l1, l2, g]}

    def positions(rtol: float) -> np.ndarray:
        sol = solve_ivp(
            _double_pendulum_angles_rhs, (0.0, t_end), [*angles, *rates], method="DOP853",
            rtol=rtol, atol=rtol * 1e-2, args=(m1, m2, l1, l2, g),
        )
        a1, a2 = sol.y[0, -1], sol.y[1, -1]
        x1, y1 = l1 * math.sin(a1), -l1 * math.cos(a1)
        return np.array([x1, y1, x1 + l2 * math.sin(a2), y1 - l2 * math.cos(a2)])

    def compute() -> dict:
        fine = positions(1e-13)
        coarse = positions(1e-12)
        return {"q": fine.tolist(), "error": float(np.max(np.abs(fine - coarse)))}

    value = _cached("double_pendulum", key, compute)
    return np.array(value["q"]), float(value["error"])
