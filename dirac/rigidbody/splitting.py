"""Lie–Poisson splitting methods for the free rigid body (numba kernels).

Two splittings of ``H_0 = sum_i M_i^2 / (2 I_i)`` (247), each sub-flow exact for ``M``
and ``R`` (so ``|M|^2``, ``R^T R = 1`` and ``m = R M`` are kept to round-off):

``axes`` (the plain 3-term split, McLachlan 1993; Reich 1994; Touma & Wisdom 1994)
    ``H = H_1 + H_2 + H_3`` with ``H_k = M_k^2 / (2 I_k)``. The flow of ``H_k`` has
    ``Omega = (M_k / I_k) e_k`` constant, so (250)–(251) give
    ``M(t) = exp(-theta hat(e_k)) M(0)``, ``R(t) = R(0) exp(theta hat(e_k))`` with
    ``theta = t M_k / I_k``: ``M`` turns about body axis ``e_k`` by ``-theta`` and ``R``
    turns on the right by ``+theta`` (``m = R M`` fixed). Base step (Strang):
    ``H_1(h/2) H_2(h/2) H_3(h) H_2(h/2) H_1(h/2)``.

``symmetric`` (symmetric-top split, Fassò 2003, J. Comput. Phys. 189, 527;
Celledoni, Fassò, Säfström & Zanna 2008)
    ``H = |M|^2 / (2 I_a) + sum_{i != a} (1/I_i - 1/I_a) M_i^2 / 2``. The Casimir term
    commutes with everything; its flow leaves ``M`` fixed and turns ``R`` on the left by
    ``exp(t (|m| / I_a) hat(m/|m|))`` about the conserved lab vector ``m``, and it commutes
    with the right-multiplications of the other sub-flows, so it is applied exactly, once,
    at the end of :func:`advance_sequence`. Only the two-term remainder is split, with
    coefficients ``1/I_i - 1/I_a`` that are small when ``a`` is the middle axis; the
    base step is ``H_b(h/2) H_c(h) H_b(h/2)``, two rotations per step after merging.

Higher order comes from symmetric compositions of the base step ``S(h)``:
``S(gamma_s h) ... S(gamma_1 h)``; a :class:`CompositionScheme` holds the ``gamma`` as
data, taken from the rows of :data:`dirac.compositions.COMPOSITIONS` (a new scheme is a
new row there). Adjacent half-steps of the same sub-flow are merged, also across steps
(first-same-as-last).
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
from numba import njit

from dirac.errors import InputError
from dirac.rigidbody.schemes import SCHEMES, CompositionScheme, build_sequence

__all__ = [
    "CompositionScheme",
    "SCHEMES",
    "build_sequence",
    "advance",
    "advance_scheme",
    "advance_sequence",
]


@njit(cache=True, inline="always")
def _turn_M(M, j, l, c, s):
    mj = M[j]
    ml = M[l]
    M[j] = c * mj + s * ml
    M[l] = c * ml - s * mj


@njit(cache=True, inline="always")
def _turn_R(R, j, l, c, s):
    for row in range(3):
        rj = R[row, j]
        rl = R[row, l]
        R[row, j] = c * rj + s * rl
        R[row, l] = c * rl - s * rj


@njit(cache=True, inline="always")
def _sub_step(M, R, k, j, l, h, with_R):
    """Exact flow of ``rate M_k^2 / 2`` for ``h = fraction dt rate``: ``theta = h M_k``,
    ``M`` turned about ``e_k`` by ``-theta`` and (``with_R``) ``R`` on the right by ``+theta``."""
    theta = h * M[k]
    c = math.cos(theta)
    s = math.sin(theta)
    _turn_M(M, j, l, c, s)
    if with_R:
        _turn_R(R, j, l, c, s)


@njit(cache=True)
def advance_sequence(M, R, axes, rates, fractions, casimir_rate, dt, n_steps, with_R):
    """Advance ``(M, R)`` in place by ``n_steps`` composed steps of size ``dt``.

    Each sub-step ``(k, rate, fraction)`` turns ``M`` about body axis ``e_k`` by
    ``-theta`` and ``R`` on the right by ``+theta``, ``theta = fraction dt rate M_k``
    (exact flow of ``rate M_k^2 / 2`` under (250)–(251)). The last sub-step of a step is
    merged with the first of the next. With ``casimir_rate != 0`` the exact Casimir flow
    ``R <- exp(n_steps dt casimir_rate |m| hat(m/|m|)) R`` (``m = R M`` at entry) is applied
    at the end. With ``with_R = False``, ``R`` is never read or written.
    """
    length = axes.shape[0]
    if n_steps <= 0:
        return
    h = np.empty(length)
    for j in range(length):
        h[j] = fractions[j] * dt * rates[j]
    h_join = (fractions[0] + fractions[length - 1]) * dt * rates[0]
    # (k, j, l) cyclic: the sub-step about e_k mixes components j and l
    js = np.empty(length, dtype=np.int64)
    ls = np.empty(length, dtype=np.int64)
    for j in range(length):
        js[j] = (axes[j] + 1) % 3
        ls[j] = (axes[j] + 2) % 3
    last = length - 1
    m0 = 0.0
    m1 = 0.0
    m2 = 0.0
    if with_R and casimir_rate != 0.0:
        m0 = R[0, 0] * M[0] + R[0, 1] * M[1] + R[0, 2] * M[2]
        m1 = R[1, 0] * M[0] + R[1, 1] * M[1] + R[1, 2] * M[2]
        m2 = R[2, 0] * M[0] + R[2, 1] * M[1] + R[2, 2] * M[2]
    _sub_step(M, R, axes[0], js[0], ls[0], h[0], with_R)
    for step in range(n_steps):
        for q in range(1, last):
            _sub_step(M, R, axes[q], js[q], ls[q], h[q], with_R)
        h_last = h_join if step < n_steps - 1 else h[last]
        _sub_step(M, R, axes[last], js[last], ls[last], h_last, with_R)
    if with_R and casimir_rate != 0.0:
        norm = math.sqrt(m0 * m0 + m1 * m1 + m2 * m2)
        if norm > 0.0:
            n0 = m0 / norm
            n1 = m1 / norm
            n2 = m2 / norm
            angle = n_steps * dt * casimir_rate * norm
            c = math.cos(angle)
            s = math.sin(angle)
            t = 1.0 - c
            q00 = c + t * n0 * n0
            q01 = t * n0 * n1 - s * n2
            q02 = t * n0 * n2 + s * n1
            q10 = t * n1 * n0 + s * n2
            q11 = c + t * n1 * n1
            q12 = t * n1 * n2 - s * n0
            q20 = t * n2 * n0 - s * n1
            q21 = t * n2 * n1 + s * n0
            q22 = c + t * n2 * n2
            for col in range(3):
                r0 = R[0, col]
                r1 = R[1, col]
                r2 = R[2, col]
                R[0, col] = q00 * r0 + q01 * r1 + q02 * r2
                R[1, col] = q10 * r0 + q11 * r1 + q12 * r2
                R[2, col] = q20 * r0 + q21 * r1 + q22 * r2


@lru_cache(maxsize=64)
def _cached_sequence(
    inv_key: tuple[float, float, float], coefficients: tuple[float, ...], splitting: str
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    return build_sequence(np.array(inv_key), coefficients, splitting)


def advance(
    M: np.ndarray,
    R: np.ndarray,
    inv_inertia: np.ndarray,
    dt: float,
    n_steps: int,
    coefficients: tuple[float, ...],
    with_R: bool = True,
    splitting: str = "axes",
) -> None:
    """Advance ``(M, R)`` in place with a composed Lie–Poisson splitting method.

    Parameters
    ----------
    M : numpy.ndarray, shape (3,), float64, C-contiguous
        Body angular momentum; overwritten.
    R : numpy.ndarray, shape (3, 3), float64
        Attitude (body to lab); overwritten when ``with_R``.
    inv_inertia : array_like, shape (3,)
        ``1 / I_i``.
    dt : float
        Step size (negative steps run backwards).
    n_steps : int
        Number of steps; the loop runs inside compiled code.
    coefficients : tuple of float
        Composition fractions of the Strang base step (``SCHEMES[name].coefficients``).
    with_R : bool
        Also advance ``R`` (otherwise ``R`` is not touched).
    splitting : {"axes", "symmetric"}
        3-term split or symmetric-top split (module docstring).
    """
    key = tuple(float(x) for x in np.asarray(inv_inertia, dtype=float))
    axes, rates, fractions, casimir_rate = _cached_sequence(key, tuple(coefficients), splitting)
    advance_sequence(M, R, axes, rates, fractions, casimir_rate, float(dt), int(n_steps), bool(with_R))


def advance_scheme(
    name: str,
    M: np.ndarray,
    R: np.ndarray,
    inertia: np.ndarray,
    dt: float,
    n_steps: int,
    with_R: bool = True,
) -> None:
    """Advance ``(M, R)`` in place with the named method of :data:`SCHEMES`.

    Parameters
    ----------
    name : str
        A key of :data:`SCHEMES`, e.g. ``"lie-poisson-4"``.
    M, R, dt, n_steps, with_R
        As in :func:`advance`.
    inertia : array_like, shape (3,)
        Principal moments ``I_i``.

    Raises
    ------
    InputError
        Unknown method name.
    """
    try:
        scheme = SCHEMES[name]
    except KeyError:
        raise InputError(
            f"method {name!r} is not a Lie-Poisson splitting; choose one of {sorted(SCHEMES)}"
        ) from None
    inv = 1.0 / np.asarray(inertia, dtype=float)
    advance(M, R, inv, dt, n_steps, scheme.coefficients, with_R, scheme.splitting)
