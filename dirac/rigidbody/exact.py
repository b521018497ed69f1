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

Evaluation: ``u0 = q0 K + x0`` with ``|x0| <= K/2`` and ``u = q0 K + (x0 + lam t)``, so the
rounding of ``u`` is that of ``x0 + lam t``, not of a ``u0`` of size ``~K`` (``~ln(1/|1 - m|)``,
large near the separatrix). ``Pi`` is split as ``u / (1 - n) + B(u)``: the first part enters
``psi`` as ``lam t / (1 - n)``, exactly, and ``B`` (``_phase_excess``) is anchored at the
nearest multiple of ``K``, where it is ``q D`` with ``D = Pi(n|m) - K/(1 - n) = O(1)``, and
changes only where ``cn^2 u`` is not small. A difference of two values of ``Pi`` of size
``~K``, which cost ``~|Pi| eps`` in the phase however short the time, is never formed.

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

from dirac.rigidbody.elliptic import agm_sequence, carlson_rf, carlson_rj, complete_pi, sncndn
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
        K = carlson_rf(0.0, mc, 1.0) if mc > 0.0 else math.inf
        if mc == 0.0:
            # separatrix: F(phi | 1) = asinh(tan phi); cn = dn there, and whichever of the
            # two did not underflow carries the phase
            u0 = math.asinh(sn0 / max(cn0, dn0))
        else:
            # u0 = F(am u0 | m) from (sn0, |cn0|, dn0) (DLMF 19.25.5); am u0 beyond pi/2
            # (cn0 < 0) by F(pi - phi) = 2K - F(phi).
            f_red = sn0 * carlson_rf(cn0 * cn0, dn0 * dn0, 1.0)
            u0 = f_red if cn0 >= 0.0 else math.copysign(2.0, sn0) * K - f_red
        G = math.sqrt(float(M @ M))  # 1 up to round-off in the scaled units of __init__
        self.m = m
        self.mc = mc
        self._perm = np.array([p1, p2, p3, b], dtype=np.int64)
        self._em, self._en = em, en
        # u0 = q0 K + x0 with |x0| <= K/2 (q0 = 0, x0 = u0 on the separatrix): times advance
        # x0 only, so no rounding of a large u0 + lam t enters M or psi
        q0 = float(math.floor(u0 / K + 0.5)) if mc > 0.0 else 0.0
        x0 = u0 - q0 * K if mc > 0.0 else u0
        # for B at odd multiples of K (see _phase_excess): n' = (m - n)/(1 - n), with 1 - n'
        # and n' - m = -n mc/(1 - n) >= 0 formed without cancellation
        one_n = 1.0 - n_char
        one_np = mc / one_n
        n_prime = (m - n_char) / one_n
        np_m = -n_char * mc / one_n
        # D = Pi(n|m) - K/(1 - n): a rounding of ~eps K in it enters psi once per half period
        D = complete_pi(n_char, mc) - K / one_n if mc > 0.0 and n_char != 0.0 else 0.0
        self._p = np.array(
            [
                s1 * A1,
                s2 * A2,
                s3 * A3,
                lam,
                x0,
                mc,
                n_char,
                q0,
                0.0,  # B(u0), set below
                # psi = (G a_b + G (a_o - a_b)/(1 - n)) t + G (a_o - a_b)/lam (B(u) - B(u0))
                G * a_b + G * (a_o - a_b) / one_n if n_char != 0.0 else G * a_o,
                G * (a_o - a_b) / lam if n_char != 0.0 else 0.0,  # (no 1/lam: lam may underflow)
                G,
                K,
                math.sqrt(mc),
                agm,
                n_prime,
                one_np,
                np_m,
                one_n,
                D,
                math.sqrt(-n_char),
            ]
        )
        self._p[8] = _phase_excess(x0, self._p, self._em, self._en)[3]
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
def _jacobi_anchored(y, p, em, en):
    """``u = q0 K + y`` as ``q K + x`` (``|x| <= K/2``, ``q`` an integer in a float) and
    ``sn, cn, dn (u)`` from ``s, c, d = sn, cn, dn (x)`` by the quarter-period shifts
    (``sn(K + x) = cd x``, ``cn(K + x) = -k' sd x``, ``dn(K + x) = k' nd x``), which keep
    ``cn`` and ``dn`` relatively accurate where they are small (the near-separatrix turning
    points). Returns ``q, x, s, c, d, sn, cn, dn``."""
    if p[5] == 0.0:  # separatrix: no period
        s, c, d = sncndn(y, em, en, p[14])
        return 0.0, y, s, c, d, s, c, d
    K = p[12]
    k = math.floor(y / K + 0.5)
    x = y - k * K
    s, c, d = sncndn(x, em, en, p[14])
    q = p[7] + k
    r = q - 4.0 * math.floor(q / 4.0)
    if r == 0.0:
        return q, x, s, c, d, s, c, d
    if r == 2.0:
        return q, x, s, c, d, -s, -c, d
    kp = p[13]
    sign = 1.0 if r == 1.0 else -1.0
    return q, x, s, c, d, sign * c / d, -sign * kp * s / d, kp / d


@njit(cache=True)
def _phase_excess(y, p, em, en):
    """``B(u) = Pi(n; am u | m) - u / (1 - n)`` at ``u = q0 K + y = q K + x``, and
    ``sn, cn, dn (u)``.

    ``psi`` takes the part ``u / (1 - n)`` of ``Pi`` as ``lam t / (1 - n)``, exactly; ``B`` has
    derivative ``1/(1 - n sn^2) - 1/(1 - n) = -n cn^2 / ((1 - n)(1 - n sn^2))``, which is small
    at the turning points ``u = K (mod 2K)``, where a near-separatrix body spends its time,
    and ``B(q K) = q D``, ``D = Pi(n|m) - K/(1 - n)``, stays ``O(1)`` however large ``K`` grows.
    Neither the size of ``Pi`` (``~ K``) nor the rounding of a large ``u`` reaches the phase.
    With ``|x| <= K/2`` (DLMF 19.25.14):

    - ``q`` even: ``Pi(n; am u) = q Pi(n) + x + (n/3) s^3 R_J(c^2, d^2, 1, 1 - n s^2)``;
    - ``q`` odd: ``sn^2 u = cd^2 x`` and ``1 - n cd^2 = (1 - n)(1 - n' s^2) / d^2`` with
      ``n' = (m - n)/(1 - n)``, so ``Pi(n; am u) = q Pi(n) + (x + (n' - m) int_0^x sn^2 /
      (1 - n' sn^2)) / (1 - n)``, the integral ``s^3 R_J(c^2, d^2, 1, 1 - n' s^2) / 3`` and
      ``n' - m = -n (1 - m)/(1 - n) >= 0``. Its integrand is about ``|n| k'`` at most for
      ``|x| <= K/2``, so it is dropped for ``1 - m < 1e-40`` (``|term| < K |n| 1e-20``).

    On the separatrix ``B = sqrt(-n) atan(sqrt(-n) tanh u) / (1 - n)``.
    """
    q, x, s, c, d, sn, cn, dn = _jacobi_anchored(y, p, em, en)
    n = p[6]
    if n == 0.0:
        return sn, cn, dn, 0.0
    if p[5] == 0.0:
        r = p[20]
        return sn, cn, dn, r * math.atan(r * s) / p[18]
    value = q * p[19]
    if q - 2.0 * math.floor(q / 2.0) == 0.0:
        rj = carlson_rj(c * c, d * d, 1.0, 1.0 - n * s * s)
        value += n / 3.0 * s * s * s * rj - n / p[18] * x
    elif p[5] >= 1e-40:
        c2 = c * c
        rj = carlson_rj(c2, d * d, 1.0, p[16] + p[15] * c2)
        value += p[17] / 3.0 * s * s * s * rj / p[18]
    return sn, cn, dn, value


@njit(cache=True)
def _eval_M(times, p, perm, em, en, out):
    for i in range(times.shape[0]):
        q, x, s, c, d, sn, cn, dn = _jacobi_anchored(p[3] * times[i] + p[4], p, em, en)
        out[i, perm[0]] = p[0] * cn
        out[i, perm[1]] = p[1] * sn
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
        sn, cn, dn, excess = _phase_excess(p[3] * t + p[4], p, em, en)
        M_out[i, perm[0]] = p[0] * cn
        M_out[i, perm[1]] = p[1] * sn
        M_out[i, perm[2]] = p[2] * dn
        M0 = M_out[i, 0]
        M1 = M_out[i, 1]
        M2 = M_out[i, 2]
        psi = p[9] * t + p[10] * (excess - p[8])
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
