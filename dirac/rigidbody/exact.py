"""Exact flow of the free asymmetric rigid body: ``M(t)`` and ``R(t)`` in closed form.

``M(t)`` (Jacobi; Landau & Lifshitz, Mechanics §37; the encyclopedia seed): order the
axes as ``(p1, p2, p3)`` with ``p2`` the middle moment and ``p3`` the extreme axis the
polhode encircles (the sign of ``D2 = 2E - |M|^2 / I_p2`` decides). With
``a_i = 1 / I_i``, ``G = |M|``, ``2E = sum a_i M_i^2``::

    M_p1 = s1 A1 cn(u),  M_p2 = s2 A2 sn(u),  M_p3 = s3 A3 dn(u),  u = lam t + u0,
    A1^2 = (2E - a3 G^2)/(a1 - a3),  A2^2 = (2E - a3 G^2)/(a2 - a3),
    A3^2 = (2E - a1 G^2)/(a3 - a1),  lam = |(a3 - a2) A2 A3 / A1|,
    m = (2E - a3 G^2)(a2 - a1) / ((a2 - a3)(2E - a1 G^2)),
    1 - m = (a1 - a3) D2 / ((a2 - a3)(2E - a1 G^2)),

so ``0 <= m <= 1`` for either polhode family and any ordering of the moments; every
difference above is formed from ``M`` as a sum of same-sign terms (no cancellation),
so the separatrix ``m -> 1`` keeps full accuracy (the Jacobi functions take ``1 - m``).
``s3 = sign M_p3(0)``, ``s2`` follows from Euler's equation (250), and
``u0 = F(am u0 | m) = sn R_F(cn^2, dn^2, 1)`` (DLMF 19.25.5) with ``sn, cn, dn (u0)`` read off
``M(0)`` (reflected through ``2K`` when ``cn < 0``).

``R(t)`` (Jacobi; Celledoni, Fassò, Säfström & Zanna, SIAM J. Sci. Comput. 30 (2008)):
with ``b`` one of the extreme axes ``p3`` or ``p1`` and ``A(M)`` the rotation whose rows are
``r1 = e_b x M^/|e_b x M^|``, ``r2 = M^ x r1``, ``r3 = M^`` (``M^ = M/G``; ``A M = G e_3``)::

    R(t) = Q Z(psi(t)) A(M(t)),   Q = R(0) A(M(0))^T,   Z(psi) = exp(psi hat(e_3)),

keeps ``R M = Q G e_3 = m`` fixed, and ``dR/dt = R hat(Omega)`` (251) reduces to
``psi' = G (2E - a_b M_b^2) / (G^2 - M_b^2) = G (a_b + (a_o - a_b) / (1 - n sn^2 u))``
(``o`` the other extreme axis) with the characteristic ``n = (a2 - a1)/(a2 - a3)`` for
``b = p3`` and ``n = -A1^2/A3^2`` for ``b = p1`` (both ``<= 0``; the smaller ``|n|`` is
used, since ``Pi = F + n J`` cancels by about ``sqrt|n|``), whence::

    psi(t) = G a_b t + G (a_o - a_b) / lam * [Pi(n; am u | m) - Pi(n; am u0 | m)].

On the separatrix (``1 - m = 0``, also when it underflows for perturbations below
``~1e-154 |M|``) ``sn = tanh``, ``cn = dn = sech`` and
``Pi(n; am u | 1) = (u + sqrt(-n) atan(sqrt(-n) tanh u)) / (1 - n)``.

Accuracy: about ``1e-13`` in ``M`` and ``R`` over ``t <= 50`` for ordinary bodies, including
``m -> 1`` (``cn``, ``dn`` stay relatively accurate at the turning points). For bodies within
``~1e-9`` (relative) of an axial symmetry with ``M`` near the plane of the two almost equal
moments, ``R`` agrees with DOP853 and the splitting methods to ``~2e-11`` only, the
level at which those integrators also disagree with each other there.

No time stepping: the cost per output time is independent of ``t``. Bodies at
relative equilibrium (``M`` an eigenvector of ``I``, including totally symmetric bodies and
``M`` in the plane of two equal moments) rotate uniformly: ``R(t) = R(0) exp(t hat(Omega))``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from dirac.rigidbody.elliptic import (
    agm_sequence,
    carlson_rf,
    carlson_rf_rj,
    complete_pi,
    reduced_sncndn,
)
from dirac.rigidbody.inertia import validate_inertia, validate_momentum, validate_rotation

__all__ = ["ExactRigidBodyFlow"]


def _levi_civita_sign(p1: int, p2: int, p3: int) -> float:
    return 1.0 if (p1, p2, p3) in ((0, 1, 2), (1, 2, 0), (2, 0, 1)) else -1.0


def _frame(M: np.ndarray, p3: int) -> np.ndarray:
    """The rotation ``A(M)`` of the module docstring (rows ``r1, r2, r3``)."""
    G = math.sqrt(float(M[0] * M[0] + M[1] * M[1] + M[2] * M[2]))
    mu = [float(M[0]) / G, float(M[1]) / G, float(M[2]) / G]
    j, l = (p3 + 1) % 3, (p3 + 2) % 3
    r1 = [0.0, 0.0, 0.0]
    r1[j] = -mu[l]  # e_p3 x mu for the cyclic triple (p3, j, l)
    r1[l] = mu[j]
    rho = math.hypot(r1[j], r1[l])
    r1 = [x / rho for x in r1]
    r2 = [
        mu[1] * r1[2] - mu[2] * r1[1],
        mu[2] * r1[0] - mu[0] * r1[2],
        mu[0] * r1[1] - mu[1] * r1[0],
    ]
    return np.array([r1, r2, mu])


class ExactRigidBodyFlow:
    """Exact solution of the Euler–Poisson equations (250)–(251) of the free rigid body.

    Parameters
    ----------
    inertia : array_like, shape (3,)
        Principal moments ``I_i`` (any ordering, equal moments allowed).
    M0 : array_like, shape (3,)
        Body angular momentum at ``t = 0``.
    R0 : array_like, shape (3, 3), optional
        Attitude at ``t = 0`` (body to lab); default the identity.

    Notes
    -----
    ``M(times)`` never computes ``R``. See the module docstring for the formulas.

    Examples
    --------
    The standard test case of docs/conventions.md (its inertia triggers a triangle-inequality warning):

    >>> import numpy as np
    >>> flow = ExactRigidBodyFlow([2.0, 1.0, 2.0 / 3.0], [np.cos(1.1), 0.0, np.sin(1.1)])
    >>> flow.M([10.0]).round(8)
    array([[0.40706614, 0.28300743, 0.86844917]])
    >>> round(float(flow.period), 10)
    10.7314652349
    """

    def __init__(self, inertia: object, M0: object, R0: object | None = None) -> None:
        self.inertia = validate_inertia(inertia)
        self.M0 = validate_momentum(M0)
        self.R0 = np.eye(3) if R0 is None else validate_rotation(R0)
        a = 1.0 / self.inertia
        M = self.M0
        self.casimir = float(M @ M)
        with np.errstate(over="ignore"):
            self.energy = 0.5 * float(np.sum(a * M * M))
        nonzero = M != 0.0
        self.equilibrium = (not np.any(nonzero)) or float(np.ptp(a[nonzero])) == 0.0
        self._p = np.zeros(15)
        self._perm = np.zeros(4, dtype=np.int64)
        self._em = np.zeros(0)
        self._en = np.zeros(0)
        self._Q = np.array(self.R0)
        self._size = 1.0
        self._rate = 1.0
        if self.equilibrium:
            self.m = 0.0
            self.mc = 1.0
            self.omega = a * M
            return
        # Homogeneity of (250)-(251): with G = |M(0)| and alpha = max 1/I_i,
        # M(t) = G Mu(G alpha t) and R(t) = Ru(G alpha t), where (Mu, Ru) is the flow of the
        # moments I alpha with |Mu(0)| = 1. The set-up works in these units, so no product
        # M_i^2 (a_i - a_j) under- or overflows however small |M| or I_i are.
        largest = float(np.max(np.abs(M)))
        self._size = largest * float(np.linalg.norm(M / largest))
        alpha = float(np.max(a))
        self._rate = self._size * alpha
        self._setup(a / alpha, M / self._size)

    def _setup(self, a: np.ndarray, M: np.ndarray) -> None:
        lo, mid, hi = (int(k) for k in np.argsort(a, kind="stable"))
        p2 = mid
        d2 = M[hi] ** 2 * (a[hi] - a[mid]) - M[lo] ** 2 * (a[mid] - a[lo])
        if a[hi] == a[mid]:  # symmetric body: the polhodes circle the distinct axis, whatever
            p3, p1 = lo, hi  # d2 says after M_lo^2 underflowed (d2 = -0.0 would pick a = a)
        elif a[mid] == a[lo]:
            p3, p1 = hi, lo
        else:
            p3, p1 = (hi, lo) if d2 >= 0.0 else (lo, hi)
        a1, a2, a3 = a[p1], a[p2], a[p3]
        # same-sign sums: e_ak = 2E - a_k G^2 = sum_{i != k} M_i^2 (a_i - a_k); e_a1 and e_a3
        # enter only through the hypotenuses below, e_a2 is computed
        e_a2 = M[p1] ** 2 * (a1 - a2) + M[p3] ** 2 * (a3 - a2)
        if a1 == a2:
            # symmetric top, m = 0: the values below without squares, which may underflow
            # (e_a1 = M_p3^2 (a3 - a1) gives A3 = |M_p3|, e_a3 / (a1 - a3) = M_p1^2 + M_p2^2)
            A1 = A2 = math.hypot(float(M[p1]), float(M[p2]))
            A3 = abs(float(M[p3]))
            m, mc = 0.0, 1.0
            lam = abs(a3 - a2) * A3
        else:
            # A1^2 = e_a3 / (a1 - a3) etc. as hypotenuses: no square of a component near
            # a principal axis underflows (M within 1e-170 of an axis keeps its amplitude)
            A1 = math.hypot(float(M[p1]), float(M[p2]) * math.sqrt((a2 - a3) / (a1 - a3)))
            A2 = math.hypot(float(M[p1]) * math.sqrt((a1 - a3) / (a2 - a3)), float(M[p2]))
            A3 = math.hypot(float(M[p2]) * math.sqrt((a2 - a1) / (a3 - a1)), float(M[p3]))
            m = (A2 / A3) ** 2 * ((a2 - a1) / (a3 - a1))
            # 1 - m = (a1 - a3) e_a2 / ((a2 - a3) e_a1) with e_a1 = A3^2 (a3 - a1); e_a2 is
            # the distance from the separatrix (it underflows only within ~1e-154 of it)
            mc = (a1 - a3) / (a2 - a3) * (float(e_a2) / (A3 * A3 * (a3 - a1)))
            m = min(max(m, 0.0), 1.0)
            mc = min(max(mc, 0.0), 1.0)
            lam = abs((a3 - a2) * A3 * (A2 / A1))
        s3 = 1.0 if M[p3] >= 0.0 else -1.0
        s1 = 1.0
        cn0 = M[p1] / A1
        if mc == 0.0:  # on the separatrix (or 1 - m underflowed): cn = sech > 0 per branch
            s1 = 1.0 if M[p1] >= 0.0 else -1.0
            cn0 = abs(cn0)
        eps = _levi_civita_sign(p1, p2, p3)
        s2 = -s1 * s3 * eps * math.copysign(1.0, a3 - a2)
        sn0 = M[p2] / (s2 * A2)
        dn0 = abs(M[p3]) / A3
        # normalise (sn0, cn0) on the unit circle; cn0 and dn0 keep their relative accuracy
        scale = math.hypot(sn0, cn0)
        sn0, cn0 = sn0 / scale, cn0 / scale
        em, en, agm = agm_sequence(mc)
        # Euler-angle axis b: p3 gives n = (a2 - a1)/(a2 - a3), p1 gives n = -A1^2/A3^2
        # (psi' = G (a_b + (a_o - a_b)/(1 - n sn^2)), o the other extreme axis). Take the
        # smaller |n|: Pi = F + n J cancels by a factor ~ sqrt|n| when |n| is large.
        n_p3 = (a2 - a1) / (a2 - a3)
        n_p1 = -(A1 * A1) / (A3 * A3) if n_p3 != 0.0 else -math.inf
        if abs(n_p3) <= abs(n_p1):
            b, a_b, a_o, n_char = p3, a3, a1, n_p3
        else:
            b, a_b, a_o, n_char = p1, a1, a3, n_p1
        if mc > 0.0:
            K = carlson_rf(0.0, mc, 1.0)
            pi_complete = complete_pi(n_char, mc)
        else:
            K = math.inf
            pi_complete = 0.0
        if mc == 0.0:
            # separatrix: F(phi | 1) = asinh(tan phi); cn = dn there, and whichever of the
            # two did not underflow carries the phase
            u0 = math.asinh(sn0 / max(cn0, dn0))
            pi0 = _pi_separatrix(u0, n_char)
        else:
            # u0 = F(am u0 | m), Pi(n; am u0 | m) from (sn0, |cn0|, dn0) (DLMF 19.25.5,
            # 19.25.14); am u0 beyond pi/2 (cn0 < 0) by F(pi - phi) = 2K - F(phi).
            f_red = sn0 * carlson_rf(cn0 * cn0, dn0 * dn0, 1.0)
            pi_red = _pi_of_reduced(0.0, sn0, abs(cn0), dn0, n_char, pi_complete)
            if cn0 >= 0.0:
                u0, pi0 = f_red, pi_red
            else:
                half = math.copysign(2.0, sn0)
                u0 = half * K - f_red
                pi0 = half * pi_complete - pi_red
        G = math.sqrt(float(M @ M))  # 1 up to round-off in the scaled units of __init__
        self.m = m
        self.mc = mc
        self._perm = np.array([p1, p2, p3, b], dtype=np.int64)
        self._em, self._en = em, en
        self._p = np.array(
            [
                s1 * A1,
                s2 * A2,
                s3 * A3,
                lam,
                u0,
                mc,
                n_char,
                pi_complete,
                pi0,
                G * a_b if n_char != 0.0 else G * a_o,  # n = 0 (symmetric top): psi' = G a_o
                G * (a_o - a_b) / lam if n_char != 0.0 else 0.0,  # (no 1/lam: lam may underflow)
                G,
                K,
                math.sqrt(mc),
                agm,
            ]
        )
        self._Q = self.R0 @ _frame(M, b).T

    # ------------------------------------------------------------------ public API
    @property
    def period(self) -> float:
        """Period of ``M(t)``: ``4 K(m) / lam`` (``cn``, ``sn`` have period ``4K``).

        ``math.inf`` exactly on the separatrix (``m = 1``); ``0.0`` at a relative
        equilibrium (``M`` constant).
        """
        if self.equilibrium:
            return 0.0
        if self.mc == 0.0:
            return math.inf
        return 4.0 * self._p[12] / self._p[3] / self._rate

    def M(self, times: object) -> np.ndarray:
        """Body angular momentum ``M(t)`` (Jacobi elliptic solution of (250)).

        Parameters
        ----------
        times : array_like, shape (N,) or scalar

        Returns
        -------
        numpy.ndarray, shape (N, 3)
        """
        t = np.atleast_1d(np.asarray(times, dtype=float)).ravel()
        if self.equilibrium:
            return np.tile(self.M0, (t.shape[0], 1))
        out = np.empty((t.shape[0], 3))
        _eval_M(t * self._rate, self._p, self._perm, self._em, self._en, out)
        return out * self._size

    def state(self, times: object) -> tuple[np.ndarray, np.ndarray]:
        """``(M(t), R(t))`` at the given times.

        Parameters
        ----------
        times : array_like, shape (N,) or scalar

        Returns
        -------
        M : numpy.ndarray, shape (N, 3)
        R : numpy.ndarray, shape (N, 3, 3)
        """
        t = np.atleast_1d(np.asarray(times, dtype=float)).ravel()
        if self.equilibrium:
            return np.tile(self.M0, (t.shape[0], 1)), _uniform_rotation(self.R0, self.omega, t)
        M_out = np.empty((t.shape[0], 3))
        R_out = np.empty((t.shape[0], 3, 3))
        _eval_state(t * self._rate, self._p, self._perm, self._em, self._en, self._Q, M_out, R_out)
        return M_out * self._size, R_out

    def R(self, times: object) -> np.ndarray:
        """Attitude ``R(t)`` (body to lab) solving (251).

        Parameters
        ----------
        times : array_like, shape (N,) or scalar

        Returns
        -------
        numpy.ndarray, shape (N, 3, 3)
        """
        return self.state(times)[1]


def _uniform_rotation(R0: np.ndarray, omega: np.ndarray, t: np.ndarray) -> np.ndarray:
    """``R0 exp(t hat(omega))`` (Rodrigues) for a relative equilibrium."""
    speed = float(np.linalg.norm(omega))
    out = np.empty((t.shape[0], 3, 3))
    if speed == 0.0:
        out[:] = R0
        return out
    n = omega / speed
    K = np.array([[0.0, -n[2], n[1]], [n[2], 0.0, -n[0]], [-n[1], n[0], 0.0]])
    angle = speed * t
    s = np.sin(angle)[:, None, None]
    c = np.cos(angle)[:, None, None]
    E = np.eye(3) + s * K + (1.0 - c) * (K @ K)
    return R0 @ E


@njit(cache=True)
def _reduced_jacobi(u, p, em, en):
    return reduced_sncndn(u, em, en, p[14], p[12], p[13])


@njit(cache=True)
def _pi_of_reduced(j, sn, cn, dn, n, pi_complete):
    """``Pi(n; am u | m)`` from ``u = 2 j K + w`` and ``sn, cn, dn (w)`` (DLMF 19.25.14)."""
    if n == 0.0:
        value = sn * carlson_rf(cn * cn, dn * dn, 1.0)
    else:
        rf, rj = carlson_rf_rj(cn * cn, dn * dn, 1.0, 1.0 - n * sn * sn)
        value = sn * rf + n / 3.0 * sn * sn * sn * rj
    if j != 0.0:
        value += 2.0 * j * pi_complete
    return value


@njit(cache=True)
def _pi_separatrix(u, n):
    """``Pi(n; am u | 1)`` for ``n <= 0``: ``sin am u = tanh u``, ``atanh(tanh u) = u``, and
    ``1/((1 - n s^2)(1 - s^2)) = (1/(1 - s^2) - n/(1 - n s^2)) / (1 - n)`` give
    ``(u + sqrt(-n) atan(sqrt(-n) tanh u)) / (1 - n)``."""
    r = math.sqrt(-n)
    return (u + r * math.atan(r * math.tanh(u))) / (1.0 - n)


@njit(cache=True)
def _eval_M(times, p, perm, em, en, out):
    for i in range(times.shape[0]):
        j, sn, cn, dn = _reduced_jacobi(p[3] * times[i] + p[4], p, em, en)
        parity = 1.0 - 2.0 * (j % 2.0)
        out[i, perm[0]] = p[0] * parity * cn
        out[i, perm[1]] = p[1] * parity * sn
        out[i, perm[2]] = p[2] * dn


@njit(cache=True)
def _eval_state(times, p, perm, em, en, Q, M_out, R_out):
    p3 = perm[3]  # the Euler-angle axis b
    j3 = (p3 + 1) % 3
    l3 = (p3 + 2) % 3
    G = p[11]
    A = np.empty((3, 3))
    for i in range(times.shape[0]):
        t = times[i]
        j, sn, cn, dn = _reduced_jacobi(p[3] * t + p[4], p, em, en)
        parity = 1.0 - 2.0 * (j % 2.0)
        M_out[i, perm[0]] = p[0] * parity * cn
        M_out[i, perm[1]] = p[1] * parity * sn
        M_out[i, perm[2]] = p[2] * dn
        M0 = M_out[i, 0]
        M1 = M_out[i, 1]
        M2 = M_out[i, 2]
        if p[5] == 0.0:
            pi_t = _pi_separatrix(p[3] * t + p[4], p[6])
        else:
            pi_t = _pi_of_reduced(j, sn, cn, dn, p[6], p[7])
        psi = p[9] * t + p[10] * (pi_t - p[8])
        # frame A(M): r3 = M/G, r1 = e_p3 x r3 / rho, r2 = r3 x r1
        mu0 = M0 / G
        mu1 = M1 / G
        mu2 = M2 / G
        r1 = np.zeros(3)
        mu = (mu0, mu1, mu2)
        # e_p3 x mu: components j3 -> -mu[l3], l3 -> mu[j3] (cyclic p3, j3, l3)
        r1[j3] = -mu[l3]
        r1[l3] = mu[j3]
        rho = math.hypot(r1[j3], r1[l3])  # the only nonzero components; no underflow
        r1[0] /= rho
        r1[1] /= rho
        r1[2] /= rho
        A[0, 0] = r1[0]
        A[0, 1] = r1[1]
        A[0, 2] = r1[2]
        A[1, 0] = mu1 * r1[2] - mu2 * r1[1]
        A[1, 1] = mu2 * r1[0] - mu0 * r1[2]
        A[1, 2] = mu0 * r1[1] - mu1 * r1[0]
        A[2, 0] = mu0
        A[2, 1] = mu1
        A[2, 2] = mu2
        c = math.cos(psi)
        s = math.sin(psi)
        # Z(psi) A: rows (c r1 - s r2, s r1 + c r2, r3)
        for col in range(3):
            z0 = c * A[0, col] - s * A[1, col]
            z1 = s * A[0, col] + c * A[1, col]
            z2 = A[2, col]
            for row in range(3):
                R_out[i, row, col] = Q[row, 0] * z0 + Q[row, 1] * z1 + Q[row, 2] * z2
