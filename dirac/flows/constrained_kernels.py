"""Step loops of general constrained systems (numba, compiled once per machine).

The system-specific pieces -- ``mass``, ``mass_derivative``, ``potential``,
``grad_potential``, ``constraints``, ``constraint_jacobian``, ``constraint_hessian`` --
are generated per system by :mod:`dirac.codegen.numba_backend` as ``numba.cfunc`` objects of the
one signature ``void(float64[::1] x, float64[::1] params, float64[::1] out)`` and handed to
these kernels as a tuple ``fns`` of first-class functions (indices ``MASS`` ...). The
kernels therefore compile once and are cached on disk for every system.

Notation: ``n`` coordinates, ``m`` holonomic constraints ``chi(q) = 0`` with Jacobian
``G = dchi/dq``; ``H = 1/2 p^T M(q)^{-1} p + V(q)``, ``v = M^{-1} p = dH/dp``,
``f = dH/dq = dV/dq - 1/2 v^T (dM/dq_k) v``.

``info`` arrays (float64) report back: ``[steps_done, failed (0/1), evaluations,
last_residual]``.
"""

import warnings

import numba
import numpy as np


def _experimental_feature_warning() -> type[Warning]:
    """First-class function types are flagged experimental by numba; they are what we need."""
    try:
        from numba.core.errors import NumbaExperimentalFeatureWarning
    except ImportError:  # pragma: no cover
        return Warning
    return NumbaExperimentalFeatureWarning


NumbaExperimentalFeatureWarning = _experimental_feature_warning()


class quiet(warnings.catch_warnings):
    """Context that hides numba's 'first-class function type is experimental' warning,
    which numba issues on every call of a kernel taking the generated functions."""

    def __enter__(self):
        result = super().__enter__()
        warnings.filterwarnings("ignore", category=NumbaExperimentalFeatureWarning)
        return result

MASS = 0
MASS_DERIVATIVE = 1
POTENTIAL = 2
GRAD_POTENTIAL = 3
CONSTRAINTS = 4
CONSTRAINT_JACOBIAN = 5
CONSTRAINT_HESSIAN = 6
#: the same tuple layout for an analysed system (padded to 7 with the gradient)
ANALYSED_GRADIENT = 0
ANALYSED_CONSTRAINTS = 1
ANALYSED_JACOBIAN = 2
FUNCTION_NAMES = ("mass", "mass_derivative", "potential", "grad_potential", "constraints",
                  "constraint_jacobian", "constraint_hessian")


@numba.njit(cache=True)
def evaluate(f, x, params, out):
    """Call a generated function from Python: ``f(x, params, out)``."""
    f(x, params, out)


def call(f: object, x: np.ndarray, params: np.ndarray, size: int) -> np.ndarray:
    """``f(x, params, out)`` from Python with a fresh flat ``out`` of ``size`` entries, returned."""
    out = np.empty(size)
    with quiet():
        evaluate(f, np.ascontiguousarray(x, dtype=float), params, out)
    return out


@numba.njit(cache=True)
def _mass(fns, q, params, n):
    out = np.empty(n * n)
    fns[MASS](q, params, out)
    return out.reshape((n, n))


@numba.njit(cache=True)
def _mass_derivative(fns, q, params, n):
    out = np.empty(n * n * n)
    fns[MASS_DERIVATIVE](q, params, out)
    return out.reshape((n, n, n))


@numba.njit(cache=True)
def _jacobian(fns, q, params, m, n):
    out = np.empty(m * n)
    if m > 0:
        fns[CONSTRAINT_JACOBIAN](q, params, out)
    return out.reshape((m, n))


@numba.njit(cache=True)
def _hessian(fns, q, params, m, n):
    out = np.empty(m * n * n)
    if m > 0:
        fns[CONSTRAINT_HESSIAN](q, params, out)
    return out.reshape((m, n, n))


# ---------------------------------------------------------------- shared helpers
@numba.njit(cache=True)
def _solve(A, b):
    """Solve A x = b (b 1-D or 2-D) by Gaussian elimination with partial pivoting.
    Small dense systems only; avoids compiling LAPACK bindings into every system module."""
    n = A.shape[0]
    M = A.copy()
    if b.ndim == 1:
        X = b.copy().reshape((n, 1))
    else:
        X = b.copy()
    k = X.shape[1]
    for c in range(n):
        piv = c
        best = abs(M[c, c])
        for r in range(c + 1, n):
            if abs(M[r, c]) > best:
                best = abs(M[r, c])
                piv = r
        if piv != c:
            for j in range(n):
                tmp = M[c, j]
                M[c, j] = M[piv, j]
                M[piv, j] = tmp
            for j in range(k):
                tmp = X[c, j]
                X[c, j] = X[piv, j]
                X[piv, j] = tmp
        d = M[c, c]
        for r in range(c + 1, n):
            f = M[r, c] / d
            if f != 0.0:
                for j in range(c, n):
                    M[r, j] -= f * M[c, j]
                for j in range(k):
                    X[r, j] -= f * X[c, j]
    for c in range(n - 1, -1, -1):
        for j in range(k):
            acc = X[c, j]
            for r in range(c + 1, n):
                acc -= M[c, r] * X[r, j]
            X[c, j] = acc / M[c, c]
    return X


@numba.njit(cache=True)
def _solve_vec(A, b):
    return _solve(A, b.reshape((b.shape[0], 1)))[:, 0].copy()


@numba.njit(cache=True)
def _velocity(fns, q, p, params, v):
    """v = M(q)^{-1} p."""
    n = q.shape[0]
    mm = _mass(fns, q, params, n)
    sol = _solve_vec(mm, p)
    for i in range(n):
        v[i] = sol[i]


@numba.njit(cache=True)
def _force(fns, q, v, params, f):
    """f = dH/dq = dV/dq - 1/2 v^T dM/dq_k v."""
    n = q.shape[0]
    fns[GRAD_POTENTIAL](q, params, f)
    dm = _mass_derivative(fns, q, params, n)
    for k in range(n):
        s = 0.0
        for i in range(n):
            for j in range(n):
                s += v[i] * dm[k, i, j] * v[j]
        f[k] -= 0.5 * s


@numba.njit(cache=True)
def _scale(q):
    s = 1.0
    for i in range(q.shape[0]):
        s += q[i] * q[i]
    return s


@numba.njit(cache=True)
def _max_abs(x):
    r = 0.0
    for i in range(x.shape[0]):
        a = abs(x[i])
        if a > r or a != a:
            r = a if a == a else np.inf
    return r


@numba.njit(cache=True)
def report(info, steps_done, failed, evals, residual):
    """Fill ``info = [steps_done, failed (0/1), evaluations, last_residual]``."""
    info[0] = steps_done
    info[1] = 1.0 if failed else 0.0
    info[2] = evals
    info[3] = residual


@numba.njit(cache=True)
def _minv_gt(minv, G, A):
    """``A <- M^{-1} G^T`` (n, m) for a constant ``M^{-1}``."""
    n = minv.shape[0]
    m = G.shape[0]
    for i in range(n):
        for a in range(m):
            acc = 0.0
            for j in range(n):
                acc += minv[i, j] * G[a, j]
            A[i, a] = acc


# ---------------------------------------------------------------- RATTLE, constant mass
@numba.njit(cache=True)
def _project_momentum(G, W, u, p, h, m, n):
    """RATTLE's closing projection onto the hidden constraints, in place.

    With ``G`` the constraint Jacobian at the new position, ``W = M^{-1} G^T`` and
    ``u = M^{-1} p``, solve ``(h/2) G W mu = G u`` and set ``p <- p - (h/2) G^T mu``, so
    that ``G M^{-1} p = 0`` (the third-stage constraints) holds afterwards
    (Hairer, Lubich & Wanner, VII.1.4).
    """
    S = np.empty((m, m))
    rhs = np.empty(m)
    for a in range(m):
        acc = 0.0
        for i in range(n):
            acc += G[a, i] * u[i]
        rhs[a] = acc
        for b in range(m):
            acc = 0.0
            for i in range(n):
                acc += G[a, i] * W[i, b]
            S[a, b] = 0.5 * h * acc
    mu = _solve_vec(S, rhs)
    for i in range(n):
        acc = 0.0
        for a in range(m):
            acc += G[a, i] * mu[a]
        p[i] -= 0.5 * h * acc


@numba.njit(cache=True)
def rattle_constant_mass(fns, q, p, minv, params, m, fractions, dt, n_steps, tol, max_iter, info):
    """RATTLE (Andersen 1983; Hairer, Lubich & Wanner VII.1.4) with constant M.

    p_half = p - h/2 (grad V(q) + G(q)^T lam),  q1 = q + h M^{-1} p_half,  chi(q1) = 0,
    p1 = p_half - h/2 (grad V(q1) + G(q1)^T mu),  G(q1) M^{-1} p1 = 0.
    One step of the composed method runs h = dt * fractions[s] for each s.
    Newton on lam (m unknowns); mu from an m x m linear solve.
    """
    n = q.shape[0]
    q_save = q.copy()
    p_save = p.copy()
    gv = np.empty(n)
    G0_flat = np.zeros(m * n)  # the generated Jacobian writes here; G0, G1 are (m, n) views
    G1_flat = np.zeros(m * n)
    G0 = G0_flat.reshape((m, n))
    G1 = G1_flat.reshape((m, n))
    chi = np.zeros(m)
    A = np.zeros((n, m))
    lam = np.zeros(m)
    ph = np.empty(n)
    qp = np.empty(n)
    q1 = np.empty(n)
    u = np.empty(n)
    J = np.empty((m, m))
    evals = 0.0
    residual = 0.0
    for step in range(n_steps):
        q_save[:] = q
        p_save[:] = p
        for s in range(fractions.shape[0]):
            h = dt * fractions[s]
            fns[GRAD_POTENTIAL](q, params, gv)
            evals += 1.0
            for i in range(n):
                ph[i] = p[i] - 0.5 * h * gv[i]
            for i in range(n):
                acc = 0.0
                for j in range(n):
                    acc += minv[i, j] * ph[j]
                qp[i] = q[i] + h * acc
            if m > 0:
                fns[CONSTRAINT_JACOBIAN](q, params, G0_flat)
                _minv_gt(minv, G0, A)
                for a in range(m):
                    lam[a] = 0.0
                q1[:] = qp
                converged = False
                for _it in range(max_iter):
                    fns[CONSTRAINTS](q1, params, chi)
                    evals += 1.0
                    residual = _max_abs(chi)
                    if residual <= tol * _scale(q1):
                        converged = True
                        break
                    if residual != residual:
                        break
                    fns[CONSTRAINT_JACOBIAN](q1, params, G1_flat)
                    for a in range(m):
                        for b in range(m):
                            acc = 0.0
                            for i in range(n):
                                acc += G1[a, i] * A[i, b]
                            J[a, b] = -0.5 * h * h * acc
                    d = _solve_vec(J, chi)
                    for a in range(m):
                        lam[a] -= d[a]
                    for i in range(n):
                        acc = 0.0
                        for a in range(m):
                            acc += A[i, a] * lam[a]
                        q1[i] = qp[i] - 0.5 * h * h * acc
                if not converged:
                    q[:] = q_save
                    p[:] = p_save
                    report(info, step, True, evals, residual)
                    return
                for i in range(n):
                    acc = 0.0
                    for a in range(m):
                        acc += G0[a, i] * lam[a]
                    ph[i] -= 0.5 * h * acc
                q[:] = q1
            else:
                q[:] = qp
            fns[GRAD_POTENTIAL](q, params, gv)
            evals += 1.0
            for i in range(n):
                p[i] = ph[i] - 0.5 * h * gv[i]
            if m > 0:
                fns[CONSTRAINT_JACOBIAN](q, params, G1_flat)
                _minv_gt(minv, G1, A)
                for j in range(n):
                    acc = 0.0
                    for i in range(n):
                        acc += minv[i, j] * p[i]
                    u[j] = acc
                _project_momentum(G1, A, u, p, h, m, n)
    report(info, n_steps, False, evals, residual)


# ---------------------------------------------------------------- RATTLE, general mass
@numba.njit(cache=True)
def _rattle_residual(fns, x, q, p, G0, h, params, n, m, r):
    """Residual of RATTLE's implicit stage at ``x = (p_half, q1, lam)``; ``G0 = G(q)``
    is fixed over the sub-step and passed in."""
    ph = x[:n].copy()
    q1 = x[n:2 * n].copy()
    v0 = np.empty(n)
    f0 = np.empty(n)
    v1 = np.empty(n)
    _velocity(fns, q, ph, params, v0)
    _force(fns, q, v0, params, f0)
    for i in range(n):
        acc = 0.0
        for a in range(m):
            acc += G0[a, i] * x[2 * n + a]
        r[i] = ph[i] - p[i] + 0.5 * h * (f0[i] + acc)
    _velocity(fns, q1, ph, params, v1)
    for i in range(n):
        r[n + i] = q1[i] - q[i] - 0.5 * h * (v0[i] + v1[i])
    if m > 0:
        chi = np.empty(m)
        fns[CONSTRAINTS](q1, params, chi)
        for a in range(m):
            r[2 * n + a] = chi[a]


@numba.njit(cache=True)
def rattle_general(fns, q, p, params, m, fractions, dt, n_steps, tol, max_iter, info):
    """RATTLE for H = 1/2 p^T M(q)^{-1} p + V(q) (Jay 1996; Hairer, Lubich & Wanner
    VII.1.4, eq. (1.26)):

    p_half = p - h/2 (H_q(q, p_half) + G(q)^T lam)
    q1 = q + h/2 (H_p(q, p_half) + H_p(q1, p_half)),  chi(q1) = 0
    p1 = p_half - h/2 (H_q(q1, p_half) + G(q1)^T mu),  G(q1) H_p(q1, p1) = 0.

    Simplified Newton on (p_half, q1, lam) with a finite-difference Jacobian formed once
    per sub-step; mu from an m x m linear solve.
    """
    n = q.shape[0]
    N = 2 * n + m
    q_save = q.copy()
    p_save = p.copy()
    x = np.empty(N)
    xx = np.empty(N)
    r = np.empty(N)
    rr = np.empty(N)
    J = np.empty((N, N))
    v = np.empty(n)
    f = np.empty(n)
    evals = 0.0
    residual = 0.0
    for step in range(n_steps):
        q_save[:] = q
        p_save[:] = p
        for s in range(fractions.shape[0]):
            h = dt * fractions[s]
            _velocity(fns, q, p, params, v)
            for i in range(n):
                x[i] = p[i]
                x[n + i] = q[i] + h * v[i]
            for a in range(m):
                x[2 * n + a] = 0.0
            G0 = _jacobian(fns, q, params, m, n)
            _rattle_residual(fns, x, q, p, G0, h, params, n, m, r)
            evals += 1.0
            for j in range(N):
                xx[:] = x
                d = 1e-7 * (1.0 + abs(x[j]))
                xx[j] += d
                _rattle_residual(fns, xx, q, p, G0, h, params, n, m, rr)
                for i in range(N):
                    J[i, j] = (rr[i] - r[i]) / d
            evals += N
            converged = False
            for _it in range(max_iter):
                delta = _solve_vec(J, r)
                for i in range(N):
                    x[i] -= delta[i]
                _rattle_residual(fns, x, q, p, G0, h, params, n, m, r)
                evals += 1.0
                residual = _max_abs(r)
                if residual <= tol * _scale(x[:2 * n]):
                    converged = True
                    break
                if residual != residual:
                    break
            if not converged:
                q[:] = q_save
                p[:] = p_save
                report(info, step, True, evals, residual)
                return
            ph = x[:n].copy()
            q[:] = x[n:2 * n]
            _velocity(fns, q, ph, params, v)
            _force(fns, q, v, params, f)
            evals += 1.0
            for i in range(n):
                p[i] = ph[i] - 0.5 * h * f[i]
            if m > 0:
                G1 = _jacobian(fns, q, params, m, n)
                mm = _mass(fns, q, params, n)
                W = _solve(mm, np.ascontiguousarray(G1.T))
                u = _solve_vec(mm, p)
                _project_momentum(G1, W, u, p, h, m, n)
    report(info, n_steps, False, evals, residual)


# ---------------------------------------------------------------- Dirac vector field
@numba.njit(cache=True)
def dirac_field(fns, z, params, n, m, out):
    """z_dot = J grad H - J grad Phi^T C^{-1} (grad Phi J grad H), C = grad Phi J grad Phi^T,
    on z = (q, p) with the second-class constraints Phi = (chi(q), G(q) M(q)^{-1} p)
    (the paper's second and third stages; Dirac bracket (240)). C is evaluated and
    solved numerically at z.
    """
    q = z[:n].copy()
    p = z[n:2 * n].copy()
    v = np.empty(n)
    f = np.empty(n)
    _velocity(fns, q, p, params, v)
    _force(fns, q, v, params, f)
    for i in range(n):
        out[i] = v[i]
        out[n + i] = -f[i]
    if m == 0:
        return
    G = _jacobian(fns, q, params, m, n)
    hc = _hessian(fns, q, params, m, n)
    mm = _mass(fns, q, params, n)
    W = _solve(mm, np.ascontiguousarray(G.T))  # (n, m) = M^{-1} G^T
    dm = _mass_derivative(fns, q, params, n)
    D = np.zeros((2 * m, 2 * n))
    for a in range(m):
        for k in range(n):
            D[a, k] = G[a, k]
            s = 0.0
            for j in range(n):
                s += hc[a, k, j] * v[j]
            t = 0.0
            for i in range(n):
                for j in range(n):
                    t += W[i, a] * dm[k, i, j] * v[j]
            D[m + a, k] = s - t
            D[m + a, n + k] = W[k, a]
    _dirac_projection(D, n, 2 * m, out)


@numba.njit(cache=True)
def _dirac_projection(D, n, k, out):
    """out <- out - J D^T C^{-1} (D out), C = D J D^T: the Dirac correction (240) of the
    Hamiltonian vector field ``out = J grad H`` over k second-class constraints whose
    gradients are the rows of D (columns: n coordinates, then n momenta)."""
    C = np.empty((k, k))
    rhs = np.empty(k)
    for a in range(k):
        acc = 0.0
        for j in range(n):
            acc += D[a, j] * out[j] + D[a, n + j] * out[n + j]
        rhs[a] = acc
        for b in range(k):
            c = 0.0
            for j in range(n):
                c += D[a, j] * D[b, n + j] - D[a, n + j] * D[b, j]
            C[a, b] = c
    mu = _solve_vec(C, rhs)
    for b in range(k):
        for j in range(n):
            out[j] -= mu[b] * D[b, n + j]
            out[n + j] += mu[b] * D[b, j]


@numba.njit(cache=True)
def analysed_field(fns, z, params, n, k, out):
    """z_dot = {z, H}_D on the full phase space of a Dirac–Bergmann analysis
    (coordinates and multipliers, then their momenta; 2n variables): J grad H corrected
    over the k second-class constraints (240); C is evaluated and solved at z.
    ``fns[ANALYSED_GRADIENT]`` gives grad H (2n,), ``fns[ANALYSED_CONSTRAINTS]`` the
    constraints (k,), ``fns[ANALYSED_JACOBIAN]`` their gradients (k, 2n)."""
    N = 2 * n
    g = np.empty(N)
    fns[ANALYSED_GRADIENT](z, params, g)
    for i in range(n):
        out[i] = g[n + i]
        out[n + i] = -g[i]
    if k == 0:
        return
    flat = np.empty(k * N)
    fns[ANALYSED_JACOBIAN](z, params, flat)
    _dirac_projection(flat.reshape((k, N)), n, k, out)


@numba.njit(cache=True)
def _project_analysed(fns, z, params, N, k, tol):
    """Orthogonal projection of z onto Phi = 0 (Gauss-Newton, a few iterations):
    z <- z - D^T (D D^T)^{-1} Phi(z). Used after each midpoint step of an analysed system,
    whose later-stage constraints are not quadratic and so not kept by the midpoint rule."""
    if k == 0:
        return
    phi = np.empty(k)
    flat = np.empty(k * N)
    for _it in range(5):
        fns[ANALYSED_CONSTRAINTS](z, params, phi)
        size = 0.0
        scale = 1.0
        for a in range(k):
            size = max(size, abs(phi[a]))
        for i in range(N):
            scale = max(scale, abs(z[i]))
        if size <= tol * scale:
            return
        fns[ANALYSED_JACOBIAN](z, params, flat)
        D = flat.reshape((k, N))
        A = np.empty((k, k))
        for a in range(k):
            for b in range(k):
                acc = 0.0
                for i in range(N):
                    acc += D[a, i] * D[b, i]
                A[a, b] = acc
        y = _solve_vec(A, phi)
        for i in range(N):
            acc = 0.0
            for a in range(k):
                acc += D[a, i] * y[a]
            z[i] -= acc


@numba.njit(cache=True)
def _field(kind, fns, z, params, n, m, out):
    if kind == 0:
        dirac_field(fns, z, params, n, m, out)
    else:
        analysed_field(fns, z, params, n, m, out)


@numba.njit(cache=True)
def midpoint_run(kind, fns, z, params, n, m, dt, n_steps, tol, max_iter, info):
    """Implicit midpoint z1 = z0 + dt F((z0 + z1)/2) on a Dirac vector field F
    (kind 0: :func:`dirac_field` of a mechanical system, n coordinates and m holonomic
    constraints; kind 1: :func:`analysed_field`, 2n phase-space variables and m
    second-class constraints, projected back onto Phi = 0 after each step since the
    later-stage constraints are not quadratic); simplified Newton with a
    finite-difference Jacobian of F at z0 per step."""
    N = 2 * n
    f = np.empty(N)
    fz = np.empty(N)
    zz = np.empty(N)
    zm = np.empty(N)
    z1 = np.empty(N)
    r = np.empty(N)
    J = np.empty((N, N))
    evals = 0.0
    size = 0.0
    for step in range(n_steps):
        _field(kind, fns, z, params, n, m, f)
        evals += 1.0
        for j in range(N):
            zz[:] = z
            d = 1e-7 * (1.0 + abs(z[j]))
            zz[j] += d
            _field(kind, fns, zz, params, n, m, fz)
            for i in range(N):
                J[i, j] = -0.5 * dt * (fz[i] - f[i]) / d
            J[j, j] += 1.0
        evals += N
        for i in range(N):
            z1[i] = z[i] + dt * f[i]
        converged = False
        for _it in range(max_iter):
            for i in range(N):
                zm[i] = 0.5 * (z[i] + z1[i])
            _field(kind, fns, zm, params, n, m, fz)
            evals += 1.0
            for i in range(N):
                r[i] = z1[i] - z[i] - dt * fz[i]
            delta = _solve_vec(J, r)
            scale = 1.0
            for i in range(N):
                z1[i] -= delta[i]
                if abs(z1[i]) > scale:
                    scale = abs(z1[i])
            size = _max_abs(delta)
            if size <= tol * scale:
                converged = True
                break
            if size != size or size == np.inf:
                break
        if not converged:
            report(info, step, True, evals, size)
            return
        z[:] = z1
        if kind == 1:
            _project_analysed(fns, z, params, N, m, tol)
    report(info, n_steps, False, evals, size)
