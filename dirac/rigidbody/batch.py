"""Batched Lie–Poisson splitting: many free rigid bodies advanced together (numba).

The step is the one of :mod:`dirac.rigidbody.splitting` (3-term split
``H_0 = M_1^2/(2 I_1) + M_2^2/(2 I_2) + M_3^2/(2 I_3)`` of (247), each sub-flow exact for
(250)–(251): ``M`` turns about body axis ``e_k`` by ``-theta`` and ``R`` on the right by
``+theta``, ``theta = fraction dt M_k / I_k``), composed with the same coefficients and
the same first-same-as-last merging, so each body follows exactly the single-body
kernel up to the rounding of ``sin`` and ``cos``.

What makes it fast:

* bodies are processed in blocks of :data:`BLOCK` held in structure-of-arrays form
  (one contiguous row per component), so the innermost loop runs over bodies with no
  branches and LLVM vectorises it;
* ``sin`` and ``cos`` are polynomials on the reduced angle (:func:`sincos_poly`):
  Cody–Waite reduction by ``pi/2`` and the fdlibm minimax kernels, branch-free (the
  quadrant is applied with float arithmetic), so they vectorise too;
* the blocks are shared out over the cores with ``numba.prange``.

Also here: :func:`advance_batch_numpy`, the same step in plain numpy vectorisation over
the bodies (the baseline of ``dirac bench``).
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
from numba import njit, prange

from dirac.errors import InputError

__all__ = [
    "BLOCK",
    "MAX_POLY_ANGLE",
    "advance_batch",
    "advance_batch_numpy",
    "choose_trigonometry",
    "composed_sequence",
    "rotate_block",
    "sincos_poly",
    "sincos_poly_array",
]

#: Bodies per block of the compiled loop (12 rows x BLOCK doubles stay in the L1/L2 cache).
BLOCK = 256

#: Largest ``|theta|`` for which the Cody–Waite reduction (3-part ``pi/2``, the quotient
#: ``n`` exact in the 33-bit leading part) keeps full accuracy; larger rotation angles per
#: sub-step use libm ``sin``/``cos`` instead.
MAX_POLY_ANGLE = 1.0e5

# Cody–Waite split of pi/2 (fdlibm e_rem_pio2.c): PIO2_1, PIO2_2, PIO2_3 have 33
# significant bits, so n * PIO2_k is exact for |n| < 2**20; PIO2_kT = pi/2 - PIO2_1 - ...
# - PIO2_k are the tails.
_TWO_OVER_PI = 6.36619772367581382433e-01
_PIO2_1 = 1.57079632673412561417e00
_PIO2_2 = 6.07710050630396597660e-11
_PIO2_2T = 2.02226624879595063154e-21
_PIO2_3 = 2.02226624871116645580e-21
_PIO2_3T = 8.47842766036889956997e-32
# fdlibm k_sin.c / k_cos.c minimax coefficients on |r| <= pi/4 (error < 2**-58).
_S1 = -1.66666666666666324348e-01
_S2 = 8.33333333332248946124e-03
_S3 = -1.98412698298579493134e-04
_S4 = 2.75573137070700676789e-06
_S5 = -2.50507602534068634195e-08
_S6 = 1.58969099521155010221e-10
_C1 = 4.16666666666666019037e-02
_C2 = -1.38888888888741095749e-03
_C3 = 2.48015872894767294178e-05
_C4 = -2.75573143513906633035e-07
_C5 = 2.08757232129817482790e-09
_C6 = -1.13596475577881948265e-11


@njit(cache=True, inline="always")
def _sin_poly(z):
    """``S2 + z (S3 + z (S4 + z (S5 + z S6)))`` of fdlibm ``k_sin.c`` (``z = r^2``)."""
    return _S2 + z * (_S3 + z * (_S4 + z * (_S5 + z * _S6)))


@njit(cache=True, inline="always")
def _cos_poly(z):
    """``z (C1 + z (C2 + ... + z C6))`` of fdlibm ``k_cos.c`` (``z = r^2``)."""
    return z * (_C1 + z * (_C2 + z * (_C3 + z * (_C4 + z * (_C5 + z * _C6)))))


@njit(cache=True, inline="always")
def _cos_sum(z, rest):
    """``1 - z/2 + rest`` with the compensated sum of fdlibm ``k_cos.c``."""
    hz = 0.5 * z
    w = 1.0 - hz
    return w + (((1.0 - w) - hz) + rest)


@njit(cache=True, inline="always")
def _sincos_reduced(r):
    """``(sin r, cos r)`` for ``|r| <= pi/4``: fdlibm ``k_sin.c`` / ``k_cos.c`` kernels."""
    z = r * r
    v = z * r
    sr = r + v * (_S1 + z * _sin_poly(z))
    cr = _cos_sum(z, z * _cos_poly(z))
    return sr, cr


@njit(cache=True, inline="always")
def _sincos_reduced_tail(x, y):
    """``(sin(x + y), cos(x + y))`` for ``|x| <= pi/4``, ``|y| <= ulp(x)/2`` (fdlibm kernels
    with the tail ``y`` of a double-double reduced angle)."""
    z = x * x
    v = z * x
    sr = x - ((z * (0.5 * y - v * _sin_poly(z)) - y) - v * _S1)
    cr = _cos_sum(z, z * _cos_poly(z) - x * y)
    return sr, cr


@njit(cache=True, inline="always")
def _two_sum(a, b):
    """Knuth's TwoSum: ``s = fl(a + b)`` and the exact rounding error ``e = a + b - s``."""
    s = a + b
    bv = s - a
    av = s - bv
    return s, (a - av) + (b - bv)


@njit(cache=True, inline="always")
def sincos_poly(theta):
    """``(sin theta, cos theta)`` by polynomials on the reduced angle, branch-free.

    ``n = round(2 theta / pi)`` and ``r = theta - n pi/2`` as a double-double
    ``x + y`` (Cody–Waite: ``pi/2`` in 33-bit parts as in fdlibm ``e_rem_pio2.c``, the
    subtractions carried exactly with TwoSum), so ``|x| <= pi/4``; then the fdlibm minimax
    kernels ``sin r = r + r^3 P(r^2)``, ``cos r = 1 - r^2/2 + r^4 Q(r^2)`` (polynomial
    error below ``2^-58``) with the compensated sum of ``k_cos.c``; the quadrant
    ``q = n mod 4`` swaps and signs the pair by exact arithmetic selects (no branch), so a
    loop that calls it vectorises. Accurate to about one ulp for ``|theta| <= MAX_POLY_ANGLE``.
    """
    n = math.floor(theta * _TWO_OVER_PI + 0.5)
    fn = float(n)
    a = theta - fn * _PIO2_1  # exact (Sterbenz; fn * _PIO2_1 is exact)
    # a - fn * (PIO2_2 + PIO2_3 + PIO2_3T) as a double-double x + y (two TwoSums)
    s1, e1 = _two_sum(a, -(fn * _PIO2_2))
    tail = (e1 - fn * _PIO2_3) - fn * _PIO2_3T
    x, y = _two_sum(s1, tail)
    sr, cr = _sincos_reduced_tail(x, y)
    q = n & 3
    odd = float(q & 1)  # quadrants 1, 3 swap sin and cos
    even = 1.0 - odd
    sign_s = 1.0 - 2.0 * float(q >> 1)  # sin < 0 in quadrants 2, 3
    sign_c = 1.0 - 2.0 * float(((q + 1) & 3) >> 1)  # cos < 0 in quadrants 1, 2
    # exact selects: one product is 0, the other the unrounded value
    s = sign_s * (even * sr + odd * cr)
    c = sign_c * (even * cr + odd * sr)
    return s, c


@njit(cache=True)
def _sincos_poly_array(theta, s_out, c_out):
    for i in range(theta.shape[0]):
        s, c = sincos_poly(theta[i])
        s_out[i] = s
        c_out[i] = c


def sincos_poly_array(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Vectorised :func:`sincos_poly` over a 1-D array (for tests and benchmarks).

    Parameters
    ----------
    theta : array_like, shape (n,)
        Angles with ``|theta| <= MAX_POLY_ANGLE``.

    Returns
    -------
    sin, cos : numpy.ndarray, shape (n,)
    """
    theta = np.ascontiguousarray(theta, dtype=float).ravel()
    s = np.empty_like(theta)
    c = np.empty_like(theta)
    _sincos_poly_array(theta, s, c)
    return s, c


# Trigonometry modes of the block kernel, chosen once per call from a bound on |theta|.
_TRIG_LIBM = 0  # libm sin/cos (angles beyond MAX_POLY_ANGLE)
_TRIG_POLY = 1  # reduction + polynomial
_TRIG_SMALL = 2  # |theta| <= pi/4 for every sub-step: polynomial, no reduction needed


@njit(cache=True)
def rotate_block(X, S, C, width, k, h, with_R, trig):
    """One exact sub-flow ``H_k`` for the ``width`` bodies of the SoA block ``X``.

    ``X`` rows: 0-2 ``M``, 3-5 ``1/I``, 6-14 ``R`` (row-major); ``S``, ``C`` scratch rows.
    ``h`` is ``fraction * dt``; ``theta = (h / I_k) M_k``. Two branch-free loops over the
    bodies (angles, then rotations) so that both vectorise.
    """
    j = (k + 1) % 3
    l = (k + 2) % 3
    mk = X[k]
    wk = X[3 + k]
    if trig == _TRIG_SMALL:
        for i in range(width):
            s, c = _sincos_reduced((h * wk[i]) * mk[i])
            S[i] = s
            C[i] = c
    elif trig == _TRIG_POLY:
        for i in range(width):
            s, c = sincos_poly((h * wk[i]) * mk[i])
            S[i] = s
            C[i] = c
    else:
        for i in range(width):
            theta = (h * wk[i]) * mk[i]
            S[i] = math.sin(theta)
            C[i] = math.cos(theta)
    _turn_rows(X[j], X[l], S, C, width)
    if with_R:
        for row in range(3):
            _turn_rows(X[6 + 3 * row + j], X[6 + 3 * row + l], S, C, width)


@njit(cache=True, inline="always")
def _turn_rows(a, b, S, C, width):
    for i in range(width):
        ai = a[i]
        bi = b[i]
        a[i] = C[i] * ai + S[i] * bi
        b[i] = C[i] * bi - S[i] * ai


@njit(cache=True, parallel=True)
def _advance_blocks(M, R, inv, axes, fractions, dt, n_steps, with_R, trig, n_workers):
    n_bodies = M.shape[0]
    length = axes.shape[0]
    last = length - 1
    n_blocks = (n_bodies + BLOCK - 1) // BLOCK
    # h of each sub-step, and of the merged last+first sub-step, as fractions[q] * dt
    # (then times 1/I_k per body): the same rounding as the single-body kernel
    fd = np.empty(length)
    for q in range(length):
        fd[q] = fractions[q] * dt
    fd_join = (fractions[0] + fractions[last]) * dt
    scratch = np.empty((n_workers, 17, BLOCK))  # one private block per worker
    for worker in prange(n_workers):
        X = scratch[worker]
        S = X[15]
        C = X[16]
        for block in range(worker, n_blocks, n_workers):
            start = block * BLOCK
            width = min(BLOCK, n_bodies - start)
            for i in range(width):
                b = start + i
                for a in range(3):
                    X[a, i] = M[b, a]
                    X[3 + a, i] = inv[b, a]
                if with_R:
                    for a in range(3):
                        for col in range(3):
                            X[6 + 3 * a + col, i] = R[b, a, col]
            # first sub-step, then per step the inner ones and the (merged) last one
            rotate_block(X, S, C, width, axes[0], fd[0], with_R, trig)
            for step in range(n_steps):
                for q in range(1, last):
                    rotate_block(X, S, C, width, axes[q], fd[q], with_R, trig)
                h_last = fd_join if step < n_steps - 1 else fd[last]
                rotate_block(X, S, C, width, axes[last], h_last, with_R, trig)
            for i in range(width):
                b = start + i
                for a in range(3):
                    M[b, a] = X[a, i]
                if with_R:
                    for a in range(3):
                        for col in range(3):
                            R[b, a, col] = X[6 + 3 * a + col, i]


@lru_cache(maxsize=64)
def composed_sequence(coefficients: tuple[float, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Axes and step fractions of the merged composed step (inertia-independent).

    Cached: an ensemble calls the kernel once per sample with the same coefficients. The
    arrays are shared between calls and only read.
    """
    from dirac.rigidbody.splitting import build_sequence

    axes, _, fractions, _ = build_sequence(np.ones(3), coefficients, "axes")
    return axes, fractions


def _prepare(
    M: np.ndarray,
    R: np.ndarray | None,
    inv_inertia: np.ndarray,
    n_steps: int,
    coefficients: tuple[float, ...],
    with_R: bool,
) -> tuple[np.ndarray, int, np.ndarray, np.ndarray] | None:
    """Validate a batch call; ``(inv, n_steps, axes, fractions)``, or None if nothing moves."""
    inv = _validate_batch(M, R, inv_inertia, with_R)
    n_steps = int(n_steps)
    if n_steps <= 0 or M.shape[0] == 0:
        return None
    axes, fractions = composed_sequence(tuple(float(c) for c in coefficients))
    return inv, n_steps, axes, fractions


def _validate_batch(
    M: np.ndarray, R: np.ndarray | None, inv_inertia: np.ndarray, with_R: bool
) -> np.ndarray:
    """Check shapes/dtypes/layout; return the inverse inertias as a (B, 3) array."""
    if not (isinstance(M, np.ndarray) and M.ndim == 2 and M.shape[1] == 3):
        raise InputError(f"M must be a float64 array of shape (B, 3); got {np.shape(M)}")
    if M.dtype != np.float64 or not M.flags.c_contiguous or not M.flags.writeable:
        raise InputError("M must be a writeable C-contiguous float64 array (it is updated in place)")
    n_bodies = M.shape[0]
    if with_R:
        if not (isinstance(R, np.ndarray) and R.shape == (n_bodies, 3, 3)):
            raise InputError(
                f"R must be a float64 array of shape ({n_bodies}, 3, 3) matching M; got {np.shape(R) if R is not None else ()}"
            )
        if R.dtype != np.float64 or not R.flags.c_contiguous or not R.flags.writeable:
            raise InputError("R must be a writeable C-contiguous float64 array (it is updated in place)")
    inv = np.asarray(inv_inertia, dtype=float)
    if inv.shape == (3,):
        inv = np.broadcast_to(inv, (n_bodies, 3))
    if inv.shape != (n_bodies, 3):
        raise InputError(
            f"inv_inertia must have shape (3,) or ({n_bodies}, 3) (one 1/I per body); got {inv.shape}"
        )
    if not np.all(np.isfinite(inv)) or np.any(inv <= 0.0):
        raise InputError("inv_inertia must hold finite positive 1/I_i; check the inertias")
    return np.ascontiguousarray(inv)


def advance_batch(
    M: np.ndarray,
    R: np.ndarray | None,
    inv_inertia: np.ndarray,
    dt: float,
    n_steps: int,
    coefficients: tuple[float, ...],
    with_R: bool = True,
) -> None:
    """Advance ``B`` rigid bodies in place by ``n_steps`` composed Lie–Poisson steps.

    Each body follows the Euler–Poisson equations (250)–(251) with its own inertia,
    integrated by the 3-term splitting of (247) composed with ``coefficients`` (the
    Strang step ``H_1(h/2) H_2(h/2) H_3(h) H_2(h/2) H_1(h/2)`` for ``(1.0,)``); the result
    equals :func:`dirac.rigidbody.splitting.advance` body by body up to the rounding of
    the polynomial ``sin``/``cos`` (a few ulp per step).

    Parameters
    ----------
    M : numpy.ndarray, shape (B, 3), float64, C-contiguous
        Body angular momenta; overwritten.
    R : numpy.ndarray, shape (B, 3, 3), float64, C-contiguous, or None
        Attitudes (body to lab); overwritten when ``with_R``, ignored (may be None) otherwise.
    inv_inertia : array_like, shape (3,) or (B, 3)
        ``1 / I_i``, shared or one triple per body (parameter sweeps).
    dt : float
        Step size.
    n_steps : int
        Number of steps (the loop runs in compiled code, in parallel over blocks of bodies).
    coefficients : tuple of float
        Composition fractions (``dirac.rigidbody.splitting.SCHEMES[name].coefficients``).
    with_R : bool
        Also advance ``R``; without it ``R`` is never read and the cost drops.

    Raises
    ------
    InputError
        Wrong shapes, dtypes or non-positive inverse inertias.
    """
    prepared = _prepare(M, R, inv_inertia, n_steps, coefficients, with_R)
    if prepared is None:
        return
    inv, n_steps, axes, fractions = prepared
    trig = choose_trigonometry(M, inv, fractions, dt)
    R_arg = R if with_R else np.zeros((1, 3, 3))
    n_workers = max(1, min(_num_threads(), -(-M.shape[0] // BLOCK)))
    _advance_blocks(M, R_arg, inv, axes, fractions, float(dt), n_steps, bool(with_R), trig, n_workers)


def choose_trigonometry(M: np.ndarray, inv: np.ndarray, fractions: np.ndarray, dt: float) -> int:
    """The trigonometry of :func:`rotate_block` for bodies ``M`` (rows) with ``1/I`` ``inv``.

    From the largest rotation angle of any sub-step,
    ``|theta| <= (max |fraction| + |fraction_0|) |dt| max(1/I) max |M|`` (the merged
    first-same-as-last sub-step included): libm ``sin``/``cos`` beyond
    :data:`MAX_POLY_ANGLE` (or a non-finite bound), the plain polynomial kernels when every
    angle is within ``pi/4``, else reduction and polynomials (:func:`sincos_poly`).
    """
    if M.shape[0] == 0:
        return _TRIG_SMALL
    bound = (
        float(np.max(np.abs(fractions)) + np.abs(fractions[0]))
        * abs(float(dt))
        * float(np.max(inv))
        * float(np.sqrt(np.max(np.einsum("ij,ij->i", M, M))))
    )
    if not np.isfinite(bound) or bound > MAX_POLY_ANGLE:
        return _TRIG_LIBM
    if bound <= 0.25 * math.pi:
        return _TRIG_SMALL
    return _TRIG_POLY


def _num_threads() -> int:
    import numba

    return int(numba.get_num_threads())


def advance_batch_numpy(
    M: np.ndarray,
    R: np.ndarray | None,
    inv_inertia: np.ndarray,
    dt: float,
    n_steps: int,
    coefficients: tuple[float, ...],
    with_R: bool = True,
) -> None:
    """The step of :func:`advance_batch` in plain numpy vectorisation (benchmark baseline).

    Same arguments and result; every sub-flow is a handful of whole-array numpy
    operations over the ``B`` bodies (``np.sin``, ``np.cos`` and column updates).
    """
    prepared = _prepare(M, R, inv_inertia, n_steps, coefficients, with_R)
    if prepared is None:
        return
    inv, n_steps, axes, fractions = prepared
    last = len(axes) - 1
    fd = fractions * float(dt)
    fd_join = (fractions[0] + fractions[last]) * float(dt)
    # SoA columns (views would be strided; contiguous copies are what numpy code would use)
    m = [np.ascontiguousarray(M[:, a]) for a in range(3)]
    w = [np.ascontiguousarray(inv[:, a]) for a in range(3)]
    r = [[np.ascontiguousarray(R[:, a, b]) for b in range(3)] for a in range(3)] if with_R and R is not None else None

    def rotate(k: int, h: float) -> None:
        j, l = (k + 1) % 3, (k + 2) % 3
        theta = (h * w[k]) * m[k]
        c = np.cos(theta)
        s = np.sin(theta)
        mj, ml = m[j], m[l]
        m[j], m[l] = c * mj + s * ml, c * ml - s * mj
        if r is not None:
            for row in range(3):
                a, b = r[row][j], r[row][l]
                r[row][j], r[row][l] = c * a + s * b, c * b - s * a

    rotate(int(axes[0]), fd[0])
    for step in range(n_steps):
        for q in range(1, last):
            rotate(int(axes[q]), fd[q])
        rotate(int(axes[last]), fd_join if step < n_steps - 1 else fd[last])
    for a in range(3):
        M[:, a] = m[a]
    if r is not None and R is not None:
        for a in range(3):
            for b in range(3):
                R[:, a, b] = r[a][b]
