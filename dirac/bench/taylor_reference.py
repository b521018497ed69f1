"""A 50-digit reference solution of the free rigid body: Taylor series in integer arithmetic.

What it integrates: the Euler–Poisson equations of the free asymmetric rigid body,
``dM/dt = M x (a M)``, ``dR/dt = R hat(a M)`` with ``a = 1/I`` (the equations (250)–(251)
of A. A. Deriglazov, "Lagrangian and Hamiltonian formulations of asymmetric rigid body,
considered as a constrained system" (2024); see docs/conventions.md).

How: the Taylor series method (A. Jorba and M. Zou, "A software package for the numerical
integration of ODEs by means of high-order Taylor methods", Experimental Mathematics 14
(2005) 99–117): the coefficients of the solution's series are generated recursively from
those of the right-hand side (Cauchy products for the products ``M x (a M)`` and
``R hat(a M)``), here to order 36, in fixed-point integer arithmetic with 168 fractional
bits (about 50 decimal digits).

To what precision: a step is accepted when the last two coefficients of the step-scaled
series are below ``2^-112`` (about ``2e-34``; relative to ``max |M_i|`` for ``M``,
absolute for ``R``), so the reference is some 18 digits more accurate than a double. Step
ends are dyadic rationals, so the output times are hit exactly.

It is independent of every closed form and of every integrator of the project, which makes
it the judge of the hard-body part of ``dirac bench --stress``
(:mod:`dirac.bench.hard_bodies`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from fractions import Fraction

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["taylor_reference"]

_BITS = 168
_ONE = 1 << _BITS


def _fixed(value: float | Fraction) -> int:
    fraction = value if isinstance(value, Fraction) else Fraction(value)  # exact for floats
    return (fraction.numerator << _BITS) // fraction.denominator


def _float(value: int) -> float:
    return float(Fraction(value, _ONE))


def _dot(u: list[int], v: list[int]) -> int:
    return sum(map(int.__mul__, u, v))


def _scaled_coefficients(M: list[int], R: list[list[int]], ha: list[int], order: int, with_R: bool):
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
    inertia: Sequence[float | Fraction],
    M0: Sequence[float | Fraction],
    R0: ArrayLike | None,
    times: Sequence[float] | np.ndarray,
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
    R_start = np.eye(3) if R0 is None else np.asarray(R0, dtype=float)
    R = [[_fixed(float(R_start[i][j])) for j in range(3)] for i in range(3)]
    scale = max(abs(x) for x in M)
    if scale == 0:
        M_out = np.zeros((len(times), 3))
        return M_out, (np.repeat(R_start[None], len(times), axis=0) if with_R else None)
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

