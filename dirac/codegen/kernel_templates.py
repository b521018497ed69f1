"""Step loops of the generated kernels (:mod:`dirac.codegen.kernel_source`), as source text.

The loops call the generated expression functions of their module by name
(``grad_potential``, ``constraints``, ``jacobian``, ... for a mechanical system;
``hamiltonian_gradient``, ``second_class``, ... for an analysed one) and the solves of
:mod:`dirac.codegen.small_solves`. The sizes are written in as literals (``__N__``
coordinates, ``__M__`` constraints, ``__K__`` second-class constraints), so that numba
compiles loops of fixed length and the solves of exactly these sizes. Work arrays are
allocated once per call, before the first step. Every loop takes the start time ``t``;
the sub-step ``s`` of step ``j`` starts at ``t + j dt + dt (c_1 + ... + c_{s-1})``.

``info`` (float64, 4) reports back ``[steps_done, failed (0/1), evaluations, last_residual]``.
"""

from __future__ import annotations

from dirac.codegen.small_solves import offset_lu_source

__all__ = ["mechanical_templates", "analysed_templates", "RATTLE_NEWTON", "UNROLLED_NEWTON_MAX"]

#: the largest n whose unconstrained RATTLE loop inlines the unrolled factors and solve of its Newton
#: matrices (:func:`dirac.codegen.small_solves.offset_lu_source`); larger n call the
#: LU's own solve on the block's rows. The unrolled solve has n^2 statements and numba types
#: and lowers each: for an N-link pendulum in angles, N = 5, the kernel compiled in 2 s
#: more CPU with it (whole process 6.9 s against 4.7 s, paired runs) for a step 12 % faster
#: (2.25 against 2.53 us); at N = 2 the call on a slice costs more than the solve (a step
#: 440 ns inlined, about 1 us called)
UNROLLED_NEWTON_MAX = 3

_COMMON = '''

@numba.njit(cache=True, inline="always")
def max_abs(x):
    """max |x_i| (inf if any entry is NaN)."""
    r = 0.0
    for i in range(x.shape[0]):
        a = abs(x[i])
        if a > r or a != a:
            r = a if a == a else np.inf
    return r


@numba.njit(cache=True, inline="always")
def scale(x, count):
    """1 + sum of x_i^2 over the first count entries: the scale of Newton tolerances."""
    s = 1.0
    for i in range(count):
        s += x[i] * x[i]
    return s


@numba.njit(cache=True, inline="always")
def report(info, steps_done, failed, evals, residual):
    """info = [steps_done, failed (0/1), evaluations, last_residual]."""
    info[0] = steps_done
    info[1] = 1.0 if failed else 0.0
    info[2] = evals
    info[3] = residual


@numba.njit(cache=True)
def dirac_projection(D, e, out, C, rhs, mu, piv):
    """out <- out - J D^T C^{-1} (D out + e), C = D J D^T: the Dirac correction (240) of
    the Hamiltonian field out = J grad H over __K__ second-class constraints with gradients
    D (rows; columns: coordinates, then momenta) and explicit time derivatives e, so
    that dPhi/dt = D out + e = 0 afterwards."""
    n = out.shape[0] // 2
    for a in range(__K__):
        acc = e[a]
        for j in range(n):
            acc += D[a, j] * out[j] + D[a, n + j] * out[n + j]
        rhs[a] = acc
        for b in range(__K__):
            s = 0.0
            for j in range(n):
                s += D[a, j] * D[b, n + j] - D[a, n + j] * D[b, j]
            C[a, b] = s
    solve___K__(C, rhs, mu, piv)
    for b in range(__K__):
        for j in range(n):
            out[j] -= mu[b] * D[b, n + j]
            out[n + j] += mu[b] * D[b, j]


@numba.njit(cache=True)
def midpoint_run(z, t, c, dt, n_steps, tol, max_iter, info):
    """Implicit midpoint z1 = z0 + dt F((z0 + z1)/2, t + dt/2) on the Dirac vector field
    F of this module (Hairer, Lubich & Wanner IV.2), simplified Newton with a
    finite-difference Jacobian of F at z0 per step, factored once per step; an analysed
    system then projects onto Phi = 0 (Hairer, Lubich & Wanner IV.4)."""
    NZ = 2 * __N__  # z = (q, p): arrays of constant shape (the tape machine allocates no others)
    f = np.empty(2 * __N__)
    fz = np.empty(2 * __N__)
    zz = np.empty(2 * __N__)
    z1 = np.empty(2 * __N__)
    r = np.empty(2 * __N__)
    J = np.empty((2 * __N__, 2 * __N__))
    piv = np.empty(2 * __N__, dtype=np.int64)
    work = field_work()
    PROJECT_WORK
    evals = 0.0
    size = 0.0
    for step in range(n_steps):
        tm = t + (step + 0.5) * dt
        # one place evaluates the field (numba compiles each inlined copy anew): at e = 0
        # at z, at e = 1 .. NZ at z + d e_j (column j = e - 1 of the finite-difference
        # Jacobian, factored after the last), then at the midpoints of the Newton iterates
        converged = False
        d = 0.0
        for e in range(1 + NZ + max_iter):
            if e <= NZ:
                for i in range(NZ):
                    zz[i] = z[i]
                if e > 0:
                    d = 1e-7 * (1.0 + abs(z[e - 1]))
                    zz[e - 1] += d
            else:
                for i in range(NZ):
                    zz[i] = 0.5 * (z[i] + z1[i])
            field_into(zz, tm, c, fz, work)
            if e == 0:
                for i in range(NZ):
                    f[i] = fz[i]
                evals += 1.0
                continue
            if e <= NZ:
                for i in range(NZ):
                    J[i, e - 1] = -0.5 * dt * (fz[i] - f[i]) / d
                J[e - 1, e - 1] += 1.0
                if e == NZ:
                    evals += NZ
                    lu_factor(J, piv)
                    for i in range(NZ):
                        z1[i] = z[i] + dt * f[i]
                continue
            evals += 1.0
            for i in range(NZ):
                r[i] = z1[i] - z[i] - dt * fz[i]
            lu_solve(J, piv, r)
            scl = 1.0
            for i in range(NZ):
                z1[i] -= r[i]
                if abs(z1[i]) > scl:
                    scl = abs(z1[i])
            size = max_abs(r)
            if size <= tol * scl:
                converged = True
                break
            if size != size or size == np.inf:
                break
        if not converged:
            report(info, step, True, evals, size)
            return
        for i in range(NZ):
            z[i] = z1[i]
        PROJECT
    report(info, n_steps, False, evals, size)


@numba.njit(cache=True)
def field(z, t, c, out):
    """The Dirac vector field at (z, t) (allocates its work arrays: for single evaluations)."""
    field_into(z, t, c, out, field_work())
'''

_VELOCITY_BY_ELIMINATION = '''

@numba.njit(cache=True, inline="always")
def velocity(q, p, t, c, v, work, piv):
    """v = M(q, t)^{-1} p; work (n, n) keeps the LU factors of M, piv their row exchanges."""
    mass(q, t, c, work)
    lu_factor(work, piv)
    for i in range(__N__):
        v[i] = p[i]
    lu_solve(work, piv, v)
'''

_STAGE_RESIDUAL = '''

@numba.njit(cache=True, inline="always")
def rattle_residual(x, q, p, G0, h, tau, tau1, c, r, ph, q1, v0, f0, v1, chi, work, piv, work0, piv0):
    """Residual of RATTLE's implicit stage at x = (p_half, q1, lam); G0 = G(q, tau), work0
    and piv0 the LU factors of M(q, tau) (the sub-step's start, factored once by the loop)."""
    for i in range(__N__):
        ph[i] = x[i]
        q1[i] = x[__N__ + i]
    for i in range(__N__):
        v0[i] = ph[i]
    lu_solve(work0, piv0, v0)
    force(q, v0, tau, c, f0)
    for i in range(__N__):
        acc = 0.0
        for a in range(__M__):
            acc += G0[a, i] * x[2 * __N__ + a]
        r[i] = ph[i] - p[i] + 0.5 * h * (f0[i] + acc)
    velocity(q1, ph, tau1, c, v1, work, piv)
    for i in range(__N__):
        r[__N__ + i] = q1[i] - q[i] - 0.5 * h * (v0[i] + v1[i])
    if __M__ > 0:
        constraints(q1, tau1, c, chi)
        for a in range(__M__):
            r[2 * __N__ + a] = chi[a]
'''

#: the Newton solve of one RATTLE sub-step on ``rattle_residual``, shared by the general
#: and the forced RATTLE loops (pasted at the same place in both: the same statements,
#: so the same numbers)
RATTLE_NEWTON = '''            jacobian(q, tau, c, G0)
            # one place evaluates the residual (numba compiles each inlined copy anew): at
            # e = 0 at x, at e = 1 .. NX at x + d e_j (column j = e - 1 of the finite-difference
            # Jacobian, factored after the last), then at the Newton iterates
            converged = False
            d = 0.0
            for e in range(1 + __NX__ + max_iter):
                for i in range(__NX__):
                    xx[i] = x[i]
                if 0 < e <= __NX__:
                    d = 1e-7 * (1.0 + abs(x[e - 1]))
                    xx[e - 1] += d
                elif e > __NX__:
                    lu_solve(J, pivx, r)
                    for i in range(__NX__):
                        x[i] -= r[i]
                        xx[i] = x[i]
                rattle_residual(xx, q, p, G0, h, tau, tau1, c, rr, ph, q1, v0, f0, v1, chi, work, pivn, work0, piv0)
                if 0 < e <= __NX__:
                    for i in range(__NX__):
                        J[i, e - 1] = (rr[i] - r[i]) / d
                    if e == __NX__:
                        evals += __NX__
                        lu_factor(J, pivx)
                    continue
                for i in range(__NX__):
                    r[i] = rr[i]
                evals += 1.0
                if e == 0:
                    continue
                residual = max_abs(r)
                if residual <= tol * scale(x, 2 * __N__):
                    converged = True
                    break
                if residual != residual:
                    break
'''


_MECHANICAL = '''


@numba.njit(cache=True, inline="always")
def project_momentum(G, W, u, chi_t, p, h, S, rhs, mu, piv):
    """RATTLE's closing projection onto the hidden constraints G M^{-1} p + d chi/dt = 0:
    with G at the new position, W = M^{-1} G^T and u = M^{-1} p, solve
    (h/2) G W mu = G u + d chi/dt and set p <- p - (h/2) G^T mu (Hairer, Lubich & Wanner
    VII.1.4)."""
    for a in range(__M__):
        acc = chi_t[a]
        for i in range(__N__):
            acc += G[a, i] * u[i]
        rhs[a] = acc
        for b in range(__M__):
            acc = 0.0
            for i in range(__N__):
                acc += G[a, i] * W[i, b]
            S[a, b] = 0.5 * h * acc
    solve___M__(S, rhs, mu, piv)
    for i in range(__N__):
        acc = 0.0
        for a in range(__M__):
            acc += G[a, i] * mu[a]
        p[i] -= 0.5 * h * acc


@numba.njit(cache=True)
def rattle_general(q, p, t, c, fractions, dt, n_steps, tol, max_iter, info):
    """RATTLE for H = 1/2 p^T M(q, t)^{-1} p + V(q, t) (Jay 1996; Hairer, Lubich & Wanner
    VII.1.4, eq. (1.26)), composed with the sub-steps h = dt fractions[s]:

    p_half = p - h/2 (H_q(q, p_half, t) + G(q, t)^T lam)
    q1 = q + h/2 (H_p(q, p_half, t) + H_p(q1, p_half, t + h)),  chi(q1, t + h) = 0
    p1 = p_half - h/2 (H_q(q1, p_half, t + h) + G(q1, t + h)^T mu),
    G(q1, t + h) H_p(q1, p1, t + h) + d chi/dt (q1, t + h) = 0.

    Simplified Newton on (p_half, q1, lam) with a finite-difference Jacobian formed and
    factored once per sub-step; mu from an m x m solve."""
    q_save = np.empty(__N__)
    p_save = np.empty(__N__)
    x = np.empty(__NX__)
    xx = np.empty(__NX__)
    r = np.empty(__NX__)
    rr = np.empty(__NX__)
    J = np.empty((__NX__, __NX__))
    pivx = np.empty(__NX__, dtype=np.int64)
    v = np.empty(__N__)
    f = np.empty(__N__)
    ph = np.empty(__N__)
    q1 = np.empty(__N__)
    v0 = np.empty(__N__)
    f0 = np.empty(__N__)
    v1 = np.empty(__N__)
    col = np.empty(__N__)
    u = np.empty(__N__)
    work = np.empty((__N__, __N__))
    pivn = np.empty(__N__, dtype=np.int64)
    work0 = np.empty((__N__, __N__))
    piv0 = np.empty(__N__, dtype=np.int64)
    # every entry is written before it is read; np.empty only: each allocation form
    # (np.zeros among them) is a numba implementation compiled once per process
    chi = np.empty(__M__)
    G0 = np.empty((__M__, __N__))
    G1 = np.empty((__M__, __N__))
    W = np.empty((__N__, __M__))
    S = np.empty((__M__, __M__))
    rhs = np.empty(__M__)
    mu = np.empty(__M__)
    pivm = np.empty(__M__, dtype=np.int64)
    evals = 0.0
    residual = 0.0
    for step in range(n_steps):
        for i in range(__N__):
            q_save[i] = q[i]
            p_save[i] = p[i]
        tau = t + step * dt
        for s in range(fractions.shape[0]):
            h = dt * fractions[s]
            tau1 = tau + h
            velocity(q, p, tau, c, v, work0, piv0)  # M(q, tau) factored once per sub-step
            for i in range(__N__):
                x[i] = p[i]
                x[__N__ + i] = q[i] + h * v[i]
            for a in range(__M__):
                x[2 * __N__ + a] = 0.0
''' + RATTLE_NEWTON + '''            if not converged:
                for i in range(__N__):
                    q[i] = q_save[i]
                    p[i] = p_save[i]
                report(info, step, True, evals, residual)
                return
            for i in range(__N__):
                ph[i] = x[i]
                q[i] = x[__N__ + i]
            velocity(q, ph, tau1, c, v, work, pivn)
            force(q, v, tau1, c, f)
            evals += 1.0
            for i in range(__N__):
                p[i] = ph[i] - 0.5 * h * f[i]
            if __M__ > 0:
                jacobian(q, tau1, c, G1)
                velocity(q, p, tau1, c, u, work, pivn)
                for a in range(__M__):
                    for i in range(__N__):
                        col[i] = G1[a, i]
                    velocity(q, col, tau1, c, v, work, pivn)
                    for i in range(__N__):
                        W[i, a] = v[i]
                constraints_dt(q, tau1, c, chi)
                project_momentum(G1, W, u, chi, p, h, S, rhs, mu, pivm)
            tau = tau1
    report(info, n_steps, False, evals, residual)

'''

#: RATTLE without constraints, as two blocks (replaces the joint ``rattle_general`` when m = 0)
_UNCONSTRAINED = """


@numba.njit(cache=True)
def rattle_general(q, p, t, c, fractions, dt, n_steps, tol, max_iter, info):
    ""\"RATTLE for H = 1/2 p^T M(q, t)^{-1} p + V(q, t) without constraints (Jay 1996; Hairer,
    Lubich & Wanner VII.1.4, eq. (1.26): the Stoermer-Verlet scheme (VI.3.4) of a
    non-separable H), composed with the sub-steps h = dt fractions[s]:

    p_half = p - h/2 H_q(q, p_half, t)                              (1)
    q1 = q + h/2 (H_p(q, p_half, t) + H_p(q1, p_half, t + h))       (2)
    p1 = p_half - h/2 H_q(q1, p_half, t + h).

    The implicit system is block triangular: (1) involves p_half alone and, p_half known,
    (2) involves q1 alone; two simplified Newton iterations of size n replace one of size
    2n on (p_half, q1). With M = M(q, t) formed once per sub-step, B = [(dM/dq_k) u]_ki
    at u = M^{-1} p and the force f = dV/dq - 1/2 v^T (dM/dq_k) v:

    (1) for v0 = M^{-1} p_half: r1 = M v0 - p + h/2 f(q, v0, t), Jacobian M - h/2 B
        (df_k/dv_j = -[(dM/dq_k) v]_j, here at v = u);
    (2) for q1 from q1 = q: r2 = q1 - q - h/2 (v0 + M(q1, t + h)^{-1} p_half), Jacobian
        I + h/2 M^{-1} B^T (d/dq_k M(q)^{-1} p_half = -M^{-1} (dM/dq_k) v0 at q1 = q, with u
        for v0), applied as x -= (M + h/2 B^T)^{-1} M r2,

    both Newton matrices in closed form, factored once per sub-step (simplified Newton:
    they set the speed, the residuals decide). Converged when |r1| <= tol (1 + |p_half|^2)
    and then |r2| <= tol (1 + |p_half|^2 + min(|q1|, |q1|^2)): both within the joint
    iteration's tol (1 + |p_half|^2 + |q1|^2), and |r2|, whose rounding floor grows like
    |q1|, not allowed to grow faster (an angle that winds up, a top's precession angle,
    would otherwise loosen the tolerance with its square).""\"
    q_save = np.empty(__N__)
    p_save = np.empty(__N__)
    x = np.empty(__N__)
    r = np.empty(__N__)
    J = np.empty((2 * __N__, __N__))  # rows 0 .. n-1: (1)'s Jacobian, n .. 2n-1: (2)'s
    pivx = np.empty(2 * __N__, dtype=np.int64)
    DINV_WORK
    HOIST_WORK
    f = np.empty(__N__)
    ph = np.empty(__N__)
    v0 = np.empty(__N__)
    v1 = np.empty(__N__)
    col = np.empty(__N__)
    M0 = np.empty((__N__, __N__))
    B = np.empty((__N__, __N__))
    work = np.empty((__N__, __N__))
    pivn = np.empty(__N__, dtype=np.int64)
    evals = 0.0
    residual = 0.0
    for step in range(n_steps):
        for i in range(__N__):
            q_save[i] = q[i]
            p_save[i] = p[i]
        tau = t + step * dt
        for s in range(fractions.shape[0]):
            h = dt * fractions[s]
            tau1 = tau + h
            # every expression of the system has one place in this loop (numba types and lowers
            # each inlined copy anew: the copies were most of the kernel's compile time): a
            # sub-step is a sequence of stages run by one loop, 0: u = M(q, t)^{-1} p and the
            # Newton matrices, 1: the iterates of (1), 2: those of (2), 3: the closing force at
            # (q1, v1); v = M^{-1} p is evaluated at one place (stages 0 and 2), the force at
            # one place (stages 1 and 3). Stage 0 evaluates v1 = M(x, ta)^{-1} ph at x = q,
            # ph = p, ta = tau: u
            for i in range(__N__):
                x[i] = q[i]
                ph[i] = p[i]
            ta = tau
            stage = 0
            first = True  # the iterate is the stage's starting point
            updates = 0  # Newton corrections in this stage
            extra = 0.0
            o = 0
            converged = False
            for _k in range(3 + 2 * max_iter):
                if stage == 2 or (stage == 1 and not first):
                    # (1): x -= (M - h/2 B)^{-1} r; (2): x -= (M + h/2 B^T)^{-1} M r
                    for i in range(__N__):
                        acc = r[i]
                        if stage == 2:
                            acc = 0.0
                            for j in range(__N__):
                                acc += M0[i, j] * r[j]
                        col[i] = acc
                    NEWTON_SOLVE
                    for i in range(__N__):
                        x[i] -= col[i]
                    updates += 1
                if stage == 1 or stage == 3:
                    # stage 1: f(q, v0, tau) at the iterate x = v0; stage 3: f(q1, v1, tau1) with
                    # q = q1 and x = v1
                    force(q, x, ta, c, f)
                    evals += 1.0
                    if stage == 3:
                        for i in range(__N__):
                            p[i] = ph[i] - 0.5 * h * f[i]
                        converged = True
                        break
                    for i in range(__N__):
                        acc = 0.0
                        for j in range(__N__):
                            acc += M0[i, j] * x[j]
                        ph[i] = acc
                        r[i] = acc - p[i] + 0.5 * h * f[i]
                else:
                    VELOCITY
                    evals += 1.0
                    if stage == 0:
                        # (1) starts at u; M = M(q, tau) and B = [(dM/dq_k) u]_ki give (1)'s
                        # Jacobian M - h/2 B and M times (2)'s, M + h/2 B^T
                        MASS0
                        mass_dq_v(q, v1, tau, c, B)
                        for i in range(__N__):
                            x[i] = v1[i]
                            for j in range(__N__):
                                J[i, j] = M0[i, j] - 0.5 * h * B[i, j]
                                J[__N__ + i, j] = M0[i, j] + 0.5 * h * B[j, i]
                        NEWTON_FACTOR
                        stage = 1
                        continue
                    for i in range(__N__):
                        r[i] = x[i] - q[i] - 0.5 * h * (v0[i] + v1[i])
                if first and stage == 1:
                    first = False
                else:
                    residual = 0.0  # max |r_i| (inf if any is NaN)
                    bound = 1.0  # 1 + |p_half|^2, or 1 + |q1|^2
                    for i in range(__N__):
                        a = abs(r[i])
                        if a > residual or a != a:
                            residual = a if a == a else np.inf
                        bound += ph[i] * ph[i] if stage == 1 else x[i] * x[i]
                    if stage == 2:
                        size = bound - 1.0
                        root = math.sqrt(size)  # min(size, root) as min takes it (numba compiles min apart)
                        bound = 1.0 + extra + (root if root < size else size)
                    if residual <= tol * bound:
                        if stage == 1:
                            # ph = M v0 at the converged v0; (2) with its Jacobian from x = q (its
                            # residual there is -h v0: M(q)^{-1} p_half = v0)
                            o = __N__
                            for i in range(__N__):
                                v0[i] = x[i]
                                extra += ph[i] * ph[i]
                                x[i] = q[i]
                                r[i] = -h * v0[i]
                            stage = 2
                            ta = tau1
                            updates = 0
                        else:
                            # v1 = M(q1, tau1)^{-1} p_half at the converged q1 = x
                            for i in range(__N__):
                                q[i] = x[i]
                                x[i] = v1[i]
                            stage = 3
                        continue
                    if residual != residual:
                        break
                if updates >= max_iter:
                    break
            if not converged:
                for i in range(__N__):
                    q[i] = q_save[i]
                    p[i] = p_save[i]
                report(info, step, True, evals, residual)
                return
            tau = tau1
    report(info, n_steps, False, evals, residual)
"""

#: v1 = M(x, ta)^{-1} ph by elimination (at stage 0 also M0 = M(q, tau)), at the
#: indentation of its place in _UNCONSTRAINED; the solve is the LU's own (a function of its
#: own: the unrolled lu_solve_n, n^2 statements, would be a second copy in the loop, whose
#: compile time grows with its statements)
_VELOCITY_ELIMINATED = """mass(x, ta, c, work)
                    if stage == 0:
                        for i in range(__N__):
                            for j in range(__N__):
                                M0[i, j] = work[i, j]
                    lu_factor(work, pivn)
                    for i in range(__N__):
                        v1[i] = ph[i]
                    lu_solve(work, pivn, v1)
"""

_FIELD = '''

@numba.njit(cache=True)
def field_work():
    """Work arrays of field_into."""
    return (np.empty(__N__), np.empty(__N__), np.zeros((__M__, __N__)), np.empty((__N__, __N__)),
            np.empty(__N__, dtype=np.int64), np.zeros((__N__, __M__)), np.zeros((__M__, __N__)),
            np.empty((__N__, __N__)), np.zeros((__K__, 2 * __N__)), np.empty((__K__, __K__)), np.empty(__K__),
            np.empty(__K__), np.empty(__K__, dtype=np.int64), np.empty(__N__), np.zeros(__K__), np.empty(__M__),
            np.empty(__N__))


@numba.njit(cache=True)
def field_into(z, t, c, out, work):
    """Called, not inlined, at the three places of midpoint_run (one compiled copy).

    z_dot = J grad H - J grad Phi^T C^{-1} (grad Phi J grad H + dPhi/dt) on z = (q, p),
    C = grad Phi J grad Phi^T, over the second-class constraints
    Phi = (chi(q, t), G(q, t) M^{-1} p + d chi/dt) (the second and third stages; Dirac
    bracket (240)); C is evaluated and solved at z."""
    v, f, G, Mw, pivn, W, Hq, dMv, D, C, rhs, mu, pivk, col, e, hdt, mtv = work
    q = z[:__N__]
    p = z[__N__:]
    velocity(q, p, t, c, v, Mw, pivn)
    force(q, v, t, c, f)
    for i in range(__N__):
        out[i] = v[i]
        out[__N__ + i] = -f[i]
    if __M__ == 0:
        return
    jacobian(q, t, c, G)
    for a in range(__M__):
        for i in range(__N__):
            col[i] = G[a, i]
        velocity(q, col, t, c, f, Mw, pivn)
        for i in range(__N__):
            W[i, a] = f[i]
    hidden_dq(q, v, t, c, Hq)
    mass_dq_v(q, v, t, c, dMv)
    for a in range(__M__):
        for k in range(__N__):
            D[a, k] = G[a, k]
            acc = 0.0
            for i in range(__N__):
                acc += W[i, a] * dMv[k, i]
            D[__M__ + a, k] = Hq[a, k] - acc
            D[__M__ + a, __N__ + k] = W[k, a]
    constraints_dt(q, t, c, e)
    hidden_dt(q, v, t, c, hdt)
    mass_dt_v(q, v, t, c, mtv)
    for a in range(__M__):
        acc = 0.0
        for i in range(__N__):
            acc += W[i, a] * mtv[i]
        e[__M__ + a] = hdt[a] - acc
    dirac_projection(D, e, out, C, rhs, mu, pivk)


@numba.njit(cache=True)
def energy(q, p, t, c):
    """H = 1/2 p^T M(q, t)^{-1} p + V(q, t)."""
    v = np.empty(__N__)
    velocity(q, p, t, c, v, np.empty((__N__, __N__)), np.empty(__N__, dtype=np.int64))
    s = 0.0
    for i in range(__N__):
        s += p[i] * v[i]
    return 0.5 * s + potential(q, t, c)


@numba.njit(cache=True)
def residuals(q, p, t, c, out):
    """out = (chi(q, t), G(q, t) M^{-1} p + d chi/dt): the second- and third-stage
    constraints (positions and velocities), (2m,)."""
    v = np.empty(__N__)
    velocity(q, p, t, c, v, np.empty((__N__, __N__)), np.empty(__N__, dtype=np.int64))
    chi = np.empty(__M__)
    G = np.empty((__M__, __N__))
    constraints(q, t, c, chi)
    jacobian(q, t, c, G)
    constraints_dt(q, t, c, out[__M__:])
    for a in range(__M__):
        out[a] = chi[a]
        acc = out[__M__ + a]
        for i in range(__N__):
            acc += G[a, i] * v[i]
        out[__M__ + a] = acc
'''

_ANALYSED = '''

@numba.njit(cache=True)
def project_work():
    """Work arrays of project."""
    return (np.empty(__K__), np.empty(__K__), np.empty((__K__, 2 * __N__)), np.empty((__K__, __K__)),
            np.empty(__K__, dtype=np.int64))


@numba.njit(cache=True, inline="always")
def project(z, t, c, tol, work):
    """Orthogonal projection of z onto Phi = 0 (Gauss-Newton, at most 5 iterations):
    z <- z - D^T (D D^T)^{-1} Phi(z) (Hairer, Lubich & Wanner IV.4)."""
    if __K__ == 0:
        return
    phi, y, D, A, piv = work
    for _it in range(5):
        second_class(z, t, c, phi)
        size = 0.0
        scl = 1.0
        for a in range(__K__):
            size = max(size, abs(phi[a]))
        for i in range(2 * __N__):
            scl = max(scl, abs(z[i]))
        if size <= tol * scl:
            return
        second_class_jacobian(z, t, c, D)
        for a in range(__K__):
            for b in range(__K__):
                acc = 0.0
                for i in range(2 * __N__):
                    acc += D[a, i] * D[b, i]
                A[a, b] = acc
        solve___K__(A, phi, y, piv)
        for i in range(2 * __N__):
            acc = 0.0
            for a in range(__K__):
                acc += D[a, i] * y[a]
            z[i] -= acc


@numba.njit(cache=True)
def energy(z, t, c):
    """The canonical Hamiltonian H_c(z, t)."""
    return hamiltonian(z, t, c)


@numba.njit(cache=True)
def residuals(z, t, c, out):
    """The second-class constraints Phi(z, t), (k,)."""
    second_class(z, t, c, out)
'''


#: the calls of the unconstrained loop that read the transcendental functions of q from ``w``
#: (``transcendentals``) instead of evaluating them: each configuration the loop visits is
#: evaluated once, where ``M(x, ta)^{-1} ph`` is (stage 0 at x = q, ta = tau; stage 2 at each
#: iterate of q1, ta = tau1), and the calls after it at the same configuration read it: stage
#: 0's ``M`` and ``(dM/dq_k) u`` at (q, tau), stage 1's forces at (q, tau) (stage 1 evaluates no
#: velocity), and stage 3's force at (q1, tau1), whose q1 is the iterate stage 2 evaluated last
#: (it converged there, and the loop set q = x without changing x)
_HOISTED = (
    ("mass(x, ta, c, work)", "transcendentals(x, ta, c, w)\n                    mass_w(x, w, ta, c, work)"),
    ("velocity(x, ph, ta, c, v1, work, pivn)",
     "transcendentals(x, ta, c, w)\n                    velocity_w(x, ph, w, ta, c, v1, work, pivn)"),
    ("mass(q, tau, c, M0)", "mass_w(q, w, tau, c, M0)"),
    ("mass_dq_v(q, v1, tau, c, B)", "mass_dq_v_w(q, v1, w, tau, c, B)"),
    ("force(q, x, ta, c, f)", "force_w(q, x, w, ta, c, f)"),
)


def _hoisted(text: str, count: int) -> str:
    """The unconstrained loop ``text`` reading the ``count`` transcendental functions of q from ``w``."""
    for old, new in _HOISTED:
        text = text.replace(old, new)
    return text.replace("    HOIST_WORK\n", f"    w = np.empty({count})  # transcendentals(q, t) at the last configuration evaluated\n")


def _fill(text: str, n: int, m: int, k: int) -> str:
    return (text.replace("__NX__", str(2 * n + m)).replace("__N__", str(n)).replace("__M__", str(m))
            .replace("__K__", str(k)))


def mechanical_templates(n: int, m: int, velocity_by_elimination: bool, hoisted: int = 0) -> str:
    """Step loops of a mechanical system with ``n`` coordinates and ``m`` constraints:
    ``rattle_general``, ``field``, ``midpoint_run``, ``energy``, ``residuals`` (and
    their helpers). RATTLE with a constant mass is unrolled per system instead
    (:mod:`dirac.codegen.rattle_scalar`). ``velocity(q, p, t, c, v, work, piv)``
    (``v = M^{-1} p``) and ``rattle_residual`` (RATTLE's implicit stage) come from here,
    by elimination, when ``velocity_by_elimination``; else the module generates both in
    closed form. ``hoisted > 0`` (unconstrained only): the module defines
    ``transcendentals(q, t, c, w)`` (``hoisted`` values) and ``mass_w``, ``force_w``,
    ``mass_dq_v_w`` (and ``velocity_w`` in closed form) that read them: the loop evaluates
    them once per configuration (:data:`_HOISTED`)."""
    common = _COMMON.replace("        PROJECT\n", "").replace("    PROJECT_WORK\n", "")
    by_elimination = _VELOCITY_BY_ELIMINATION + _STAGE_RESIDUAL if velocity_by_elimination else ""
    if m > 0:
        rattle = _MECHANICAL
    else:  # v1 = M(x)^{-1} ph: in closed form (and M0 from mass), or eliminated with the inlined solve
        if velocity_by_elimination:
            unconstrained = _UNCONSTRAINED.replace("VELOCITY\n", _VELOCITY_ELIMINATED).replace("                        MASS0\n", "")
        else:
            unconstrained = (_UNCONSTRAINED.replace("VELOCITY\n", "velocity(x, ph, ta, c, v1, work, pivn)\n")
                             .replace("MASS0\n", "mass(q, tau, c, M0)\n"))
        if hoisted:
            unconstrained = _hoisted(unconstrained, hoisted)
        else:
            unconstrained = unconstrained.replace("    HOIST_WORK\n", "")
        if n <= UNROLLED_NEWTON_MAX:  # one copy of the unrolled factorization, run for both blocks
            rattle = offset_lu_source(n) + (
                unconstrained.replace("NEWTON_SOLVE\n", "lu_solve_n(J, pivx, dinv, col, o)\n")
                .replace("NEWTON_FACTOR\n", "for ob in range(0, 2 * __N__, __N__):\n"
                         "                            lu_factor_n(J, pivx, dinv, ob)\n")
                .replace("DINV_WORK\n", "dinv = np.empty(2 * __N__)  # reciprocal pivots of the unrolled factors\n")
                # the row exchanges as floats (compared with literals, never an index): no
                # allocation of integers, whose implementation numba compiles once per process
                .replace("pivx = np.empty(2 * __N__, dtype=np.int64)", "pivx = np.empty(2 * __N__)"))
        else:
            rattle = (unconstrained.replace("NEWTON_SOLVE\n", "lu_solve(J[o:o + __N__], pivx[o:o + __N__], col)\n")
                      .replace("NEWTON_FACTOR\n", "lu_factor(J[:__N__], pivx[:__N__])\n"
                               "                        lu_factor(J[__N__:], pivx[__N__:])\n")
                      .replace("    DINV_WORK\n", ""))
    return _fill(by_elimination + rattle + _FIELD + common, n, m, 2 * m)


def analysed_templates(n: int, k: int) -> str:
    """Step loops of an analysed system (``2n`` phase-space variables, ``k`` second-class
    constraints): ``field``, ``midpoint_run`` (projected), ``project``, ``energy``,
    ``residuals``. The module defines ``field_into(z, t, c, out, work)`` and
    ``field_work()`` itself (:func:`dirac.codegen.field_body.dirac_field_body`)."""
    if k == 0:  # nothing to project onto: neither the projection nor its work arrays are compiled
        common = _COMMON.replace("        PROJECT\n", "").replace("    PROJECT_WORK\n", "")
    else:
        common = (_COMMON.replace("        PROJECT\n", "        project(z, t + (step + 1) * dt, c, tol, project_buffers)\n")
                  .replace("    PROJECT_WORK\n", "    project_buffers = project_work()\n"))
    return _fill(_ANALYSED + common, n, 0, k)
