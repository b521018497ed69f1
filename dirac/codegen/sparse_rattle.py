"""RATTLE of large systems with a constant diagonal mass: loops over repeated structure, a banded solve.

The unrolled kernel of :mod:`dirac.codegen.rattle_scalar` writes every product of the
``m x m`` multiplier matrix ``G M^{-1} G^T`` and every step of its elimination as scalar
code: its source grows like ``m^2 n`` and numba's compile time faster still (minutes at
16 rods of a chain). Large systems are built of few kinds of pieces (the rods of a chain
are one constraint with shifted indices), so this module writes

* **families**: constraints that are the same expression of their own coordinates (in
  the order of the coordinate list) share one generated function of placeholders
  ``u_0, u_1, ...`` giving ``chi``, ``d chi/du_k`` and ``d chi/dt``, called in a loop over
  an index table (which coordinates each member reads); the components of ``grad V``
  likewise. Source size and compile time grow with the number of *kinds* of pieces, the
  tables (data) linearly with the system;
* the Jacobian ``G`` as a **sparse** table (each row its few columns);
* ``J = G(q1) M^{-1} G(q0)^T`` (RATTLE's Newton matrix) from a static list of the pairs of
  rows that share a column, stored as a **band** (bandwidths from the pattern), and
  solved by banded Gaussian elimination with partial pivoting (Golub & Van Loan,
  Algorithm 4.3.1 with row exchanges, as LAPACK's ``gbtrf``): ``O(m b^2)`` per solve for
  bandwidth ``b`` (tridiagonal for a chain: ``b = 1``).

The algorithm is that of :mod:`dirac.codegen.rattle_scalar` (Andersen 1983; Hairer,
Lubich & Wanner VII.1.4), one sub-step of size ``h`` from ``(q, p)`` at time ``tau``:

    p_half = p - h/2 (grad V(q, tau) + G(q, tau)^T lam),   q1 = q + h M^{-1} p_half,
    chi(q1, tau + h) = 0  (Newton on lam, matrix -h^2/2 G(q1) M^{-1} G(q)^T),
    p1 = p_half - h/2 (grad V(q1, tau + h) + G(q1, tau + h)^T mu),
    G(q1) M^{-1} p1 + d chi/dt = 0  (an m x m banded solve for mu).

The module also defines the evaluations the flows call from Python (``potential``,
``grad_potential``, ``constraints``, ``constraints_dt``, ``jacobian``, ``mass``,
``velocity``, ``energy``, ``residuals``) with the signatures of
:mod:`dirac.codegen.kernel_templates`. It has no Dirac field and no midpoint rule: those
need second derivatives that are dense in general (:func:`has_rattle_only`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import sympy

from dirac.codegen.printer import straight_line

__all__ = ["sparse_rattle_source", "group_families", "termwise_gradient", "Family", "RATTLE_ONLY"]

#: marker in the module source of a system whose module holds RATTLE only
RATTLE_ONLY = "RATTLE_ONLY = True"


@dataclass
class Family:
    """Expressions that are one template of their own coordinates.

    Attributes
    ----------
    template : sympy.Expr
        The expression in the placeholders ``u_0 .. u_{k-1}``.
    placeholders : tuple of sympy.Symbol
    members : list of int
        Positions of the expressions of this family in the grouped list.
    columns : list of tuple of int
        For each member, the coordinate index each placeholder stands for.
    """

    template: sympy.Expr
    placeholders: tuple[sympy.Symbol, ...]
    members: list[int] = field(default_factory=list)
    columns: list[tuple[int, ...]] = field(default_factory=list)


def group_families(expressions: Sequence[sympy.Expr], coordinates: Sequence[sympy.Symbol]) -> list[Family]:
    """Group ``expressions`` into :class:`Family` objects: two expressions are in one family
    when replacing the coordinates each contains (in the order of ``coordinates``) by
    ``u_0, u_1, ...`` gives the same expression."""
    position = {symbol: i for i, symbol in enumerate(coordinates)}
    families: dict[sympy.Expr, Family] = {}
    ordered: list[Family] = []
    for index, expression in enumerate(expressions):
        expression = sympy.sympify(expression)
        used = sorted((s for s in expression.free_symbols if s in position), key=position.__getitem__)
        placeholders = tuple(sympy.Symbol(f"_u{k}", real=True) for k in range(len(used)))
        template = expression.xreplace(dict(zip(used, placeholders)))
        family = families.get(template)
        if family is None:
            family = families[template] = Family(template, placeholders)
            ordered.append(family)
        family.members.append(index)
        family.columns.append(tuple(position[s] for s in used))
    return ordered


def _table(name: str, rows: Sequence[Sequence[int]], width: int) -> str:
    """A module-level int32 table ``name`` (len(rows), width); short rows padded with 0.

    int32 halves the tables' share of the cache next to int64: the tables are read on
    every step and grow with the system (numba freezes them into the machine code)."""
    body = ", ".join("[" + ", ".join(str(v) for v in [*row, *[0] * (width - len(row))]) + "]" for row in rows)
    if not rows:
        return f"{name} = np.zeros((0, {max(width, 1)}), dtype=np.int32)\n"
    if width == 0:
        return f"{name} = np.zeros(({len(rows)}, 1), dtype=np.int32)\n"
    return f"{name} = np.array([{body}], dtype=np.int32)\n"


def _vector(name: str, values: Sequence[int]) -> str:
    """A module-level int32 vector ``name``."""
    return f"{name} = np.array([{', '.join(map(str, values))}], dtype=np.int32)\n" if values else \
        f"{name} = np.zeros(0, dtype=np.int32)\n"


def _family_loop(family: Family, table: str, rows: str, outputs: Sequence[sympy.Expr], targets: Sequence[str],
                 parameters: Sequence[sympy.Symbol], time: sympy.Symbol | None, label: str) -> str:
    """Source of a loop over the members ``r`` of ``family``: its coordinates read through
    ``table[r, k]``, ``targets[j] = outputs[j]`` as straight-line code (``a`` is the member's
    position, ``rows[r]``). Parameters are read from ``c`` and the time from ``t``."""
    inputs: dict[sympy.Symbol, str] = {}
    lines = [f"    for r in range({len(family.members)}):", f"        a = {rows}[r]"]
    for k, symbol in enumerate(family.placeholders):
        inputs[symbol] = f"u{k}_"
        lines.append(f"        u{k}_ = q[{table}[r, {k}]]")
    for k, symbol in enumerate(parameters):
        inputs[symbol] = f"c[{k}]"
    if time is not None:
        inputs[time] = "t"
    code = straight_line(inputs, list(outputs), "math", "cse", label)
    lines.extend(code.body("        "))
    lines.extend(f"        {target} = {value}" for target, value in zip(targets, code.outputs))
    return "\n".join(lines) + "\n"


def termwise_gradient(expression: sympy.Expr, symbols: Sequence[sympy.Symbol]) -> list[sympy.Expr]:
    """``[d expression / d s for s in symbols]``, each term of the sum differentiated only by the symbols it has.

    The same expressions as ``sympy.diff`` (the derivative of a sum is the sum of its terms' derivatives,
    :meth:`sympy.Add._eval_derivative`), in ``O(terms)`` derivatives of single terms instead of ``n``
    derivatives of the whole sum: a lattice of ``n`` sites has ``O(n)`` terms, and ``n`` whole derivatives
    took 58 s of a 200-site lattice's 158 s (CPU under cProfile).
    """
    position = {s: k for k, s in enumerate(symbols)}
    parts: list[list[sympy.Expr]] = [[] for _ in symbols]
    for term in sympy.Add.make_args(expression):
        for s in term.free_symbols & position.keys():
            parts[position[s]].append(sympy.diff(term, s))
    return [sympy.Add(*p) for p in parts]


def sparse_rattle_source(
    coordinates: Sequence[sympy.Symbol],
    parameters: Sequence[sympy.Symbol],
    inverse_mass_diagonal: Sequence[sympy.Expr],
    potential: sympy.Expr,
    constraints: Sequence[sympy.Expr],
    time: sympy.Symbol | None = None,
) -> str:
    """Module body (after the header of :mod:`dirac.codegen.kernel_source`) of a system with
    a constant diagonal mass ``M = diag(1 / inverse_mass_diagonal)``: ``rattle_constant_mass``
    with the signature of the unrolled kernel, and the Python-side evaluations.

    Parameters
    ----------
    coordinates, parameters
        The symbols read from ``q`` and from ``c``, in order.
    inverse_mass_diagonal
        The entries of ``M^{-1}`` (expressions in the parameters only).
    potential, constraints, time
        ``V(q, t)``, ``chi(q, t)`` and the time symbol (or None).
    """
    q = list(coordinates)
    n, m = len(q), len(constraints)
    out: list[str] = [RATTLE_ONLY + "\n", f"N = {n}\n", f"M = {m}\n"]
    # ------------------------------------------------------------ families of constraints
    families = group_families(list(constraints), q)
    width = max([len(f.placeholders) for f in families] + [1])
    columns: list[tuple[int, ...]] = [(0,)] * m
    for f in families:
        for member, cols in zip(f.members, f.columns):
            columns[member] = cols
    out.append(_table("GC", columns, width))
    out.append(_vector("GW", [len(cols) for cols in columns]))
    calls = []
    for j, f in enumerate(families):
        k = len(f.placeholders)
        outputs = [f.template, *[sympy.diff(f.template, u) for u in f.placeholders],
                   sympy.diff(f.template, time) if time is not None else sympy.S.Zero]
        out.append(_table(f"CHI_COLS_{j}", f.columns, k))
        out.append(_vector(f"CHI_ROWS_{j}", f.members))
        targets = ["chi[a]", *[f"Gv[a, {i}]" for i in range(k)], "ct[a]"]
        calls.append(_family_loop(f, f"CHI_COLS_{j}", f"CHI_ROWS_{j}", outputs, targets, parameters, time,
                                  f"constraint family {j}"))
    out.append(f"""
@numba.njit(cache=True)
def constraint_parts(q, t, c, chi, Gv, ct):
    \"\"\"chi(q, t), the sparse G (values Gv on the columns GC) and d chi/dt.\"\"\"
{''.join(calls) or '    return'}
""")
    # ------------------------------------------------------------ families of grad V
    gradient = termwise_gradient(potential, q)
    gfamilies = group_families(gradient, q)
    gcalls = []
    for j, f in enumerate(gfamilies):
        out.append(_table(f"GV_COLS_{j}", f.columns, len(f.placeholders)))
        out.append(_vector(f"GV_ROWS_{j}", f.members))
        gcalls.append(_family_loop(f, f"GV_COLS_{j}", f"GV_ROWS_{j}", [f.template], ["out[a]"], parameters, time,
                                   f"dV/dq family {j}"))
    out.append(f"""
@numba.njit(cache=True)
def grad_potential(q, t, c, out):
    \"\"\"dV/dq, (n,).\"\"\"
{''.join(gcalls) or '    return'}
""")
    inputs = {s: f"q[{i}]" for i, s in enumerate(q)}
    inputs.update({s: f"c[{k}]" for k, s in enumerate(parameters)})
    if time is not None:
        inputs[time] = "t"
    # two codes: inverse_mass has no q, so it cannot run the potential's shared sub-expressions
    code = straight_line(inputs, [potential], "math", "cse", "potential")
    out.append("\n@numba.njit(cache=True)\ndef potential(q, t, c):\n    \"\"\"V(q, t).\"\"\"\n"
               + "\n".join(code.body()) + f"\n    return {code.outputs[0]}\n")
    code = straight_line(inputs, list(inverse_mass_diagonal), "math", "cse", "the inverse mass")
    out.append("\n@numba.njit(cache=True)\ndef inverse_mass(c, out):\n    \"\"\"The diagonal of M^{-1}, (n,).\"\"\"\n"
               + "\n".join(code.body()) + "\n"
               + "\n".join(f"    out[{i}] = {value}" for i, value in enumerate(code.outputs)) + "\n")
    # ------------------------------------------------------------ pairs of rows sharing a column: J's pattern
    rows_of: dict[int, list[tuple[int, int]]] = {}
    for a, cols in enumerate(columns[:m]):
        for k, col in enumerate(cols):
            rows_of.setdefault(col, []).append((a, k))
    pairs = [(a, ka, b, kb) for entries in rows_of.values() for (a, ka) in entries for (b, kb) in entries]
    kl = max([a - b for a, _, b, _ in pairs] + [0])
    ku = max([b - a for a, _, b, _ in pairs] + [0])
    bw = 2 * kl + ku + 1
    # each pair as three flat positions: in B (band storage), in G's values, in A's values
    out.append(_vector("PAIR_B", [a * bw + b - a + kl for a, _, b, _ in pairs]))
    out.append(_vector("PAIR_G", [a * width + ka for a, ka, _, _ in pairs]))
    out.append(_vector("PAIR_A", [b * width + kb for _, _, b, kb in pairs]))
    out.append(f"KL = {kl}\nKU = {ku}\nBW = {bw}\nNPAIRS = {len(pairs)}\n")
    out.append(_SPARSE_TEMPLATES.replace("__W__", str(width)))
    return "".join(out)


_SPARSE_TEMPLATES = '''

@numba.njit(cache=True)
def band_assemble(Gv, Av, scale, B):
    """B <- scale * G A^T in band storage (B[a, b - a + KL]; columns beyond KU left for fill-in),
    over the flat positions of the pairs of rows that share a column."""
    Bf = B.ravel()
    Gf = Gv.ravel()
    Af = Av.ravel()
    for j in range(M * BW):
        Bf[j] = 0.0
    for s in range(NPAIRS):
        Bf[PAIR_B[s]] += scale * Gf[PAIR_G[s]] * Af[PAIR_A[s]]


@numba.njit(cache=True)
def band_solve(B, x, piv):
    """x <- B^{-1} x: banded Gaussian elimination with partial pivoting in place
    (bandwidths KL below, KU above the diagonal; fill-in up to KL + KU above, as LAPACK
    gbtrf); the diagonal of B ends holding the reciprocal pivots. A zero pivot gives an
    infinite reciprocal (a singular Newton matrix: the next residual is not finite)."""
    for col in range(M):
        last = min(M - 1, col + KL)
        best = abs(B[col, KL])
        r_best = col
        for r in range(col + 1, last + 1):
            v = abs(B[r, col - r + KL])
            if v > best:
                best = v
                r_best = r
        piv[col] = r_best
        right = min(M - 1, col + KL + KU)
        if r_best != col:
            for j in range(col, right + 1):
                tmp = B[col, j - col + KL]
                B[col, j - col + KL] = B[r_best, j - r_best + KL]
                B[r_best, j - r_best + KL] = tmp
            tmp = x[col]
            x[col] = x[r_best]
            x[r_best] = tmp
        inverse = 1.0 / B[col, KL]  # one division per column, kept for the back substitution
        B[col, KL] = inverse
        for r in range(col + 1, last + 1):
            f = B[r, col - r + KL] * inverse
            if f != 0.0:
                for j in range(col + 1, right + 1):
                    B[r, j - r + KL] -= f * B[col, j - col + KL]
                x[r] -= f * x[col]
    for col in range(M - 1, -1, -1):
        acc = x[col]
        right = min(M - 1, col + KL + KU)
        for j in range(col + 1, right + 1):
            acc -= B[col, j - col + KL] * x[j]
        x[col] = acc * B[col, KL]


@numba.njit(cache=True)
def band_factor(B, piv):
    """B <- its LU factors with partial pivoting (as LAPACK gbtf2: the multipliers below the
    diagonal in place, the row exchanges in piv, the diagonal holding reciprocal pivots), for
    band_lu_solve: the elimination of band_solve without a right-hand side."""
    for col in range(M):
        last = min(M - 1, col + KL)
        best = abs(B[col, KL])
        r_best = col
        for r in range(col + 1, last + 1):
            v = abs(B[r, col - r + KL])
            if v > best:
                best = v
                r_best = r
        piv[col] = r_best
        right = min(M - 1, col + KL + KU)
        if r_best != col:
            for j in range(col, right + 1):
                tmp = B[col, j - col + KL]
                B[col, j - col + KL] = B[r_best, j - r_best + KL]
                B[r_best, j - r_best + KL] = tmp
        inverse = 1.0 / B[col, KL]
        B[col, KL] = inverse
        for r in range(col + 1, last + 1):
            f = B[r, col - r + KL] * inverse
            B[r, col - r + KL] = f
            if f != 0.0:
                for j in range(col + 1, right + 1):
                    B[r, j - r + KL] -= f * B[col, j - col + KL]


@numba.njit(cache=True)
def band_lu_solve(B, piv, x):
    """x <- A^{-1} x from the factors of band_factor (the row exchanges and multipliers in
    order, then the back substitution)."""
    for col in range(M):
        r_best = piv[col]
        if r_best != col:
            tmp = x[col]
            x[col] = x[r_best]
            x[r_best] = tmp
        xc = x[col]
        last = min(M - 1, col + KL)
        for r in range(col + 1, last + 1):
            x[r] -= B[r, col - r + KL] * xc
    for col in range(M - 1, -1, -1):
        acc = x[col]
        right = min(M - 1, col + KL + KU)
        for j in range(col + 1, right + 1):
            acc -= B[col, j - col + KL] * x[j]
        x[col] = acc * B[col, KL]


@numba.njit(cache=True)
def rattle_constant_mass(q, p, t, c, fractions, dt, n_steps, tol, max_iter, info):
    """RATTLE, constant diagonal mass, families in loops and a banded Newton solve
    (see dirac.codegen.sparse_rattle)."""
    minv = np.empty(N)
    inverse_mass(c, minv)
    qs = np.empty(N)
    ps = np.empty(N)
    gv = np.empty(N)
    ph = np.empty(N)
    qp = np.empty(N)
    q1 = np.empty(N)
    chi = np.empty(M)
    ct = np.empty(M)
    lam = np.empty(M)
    d = np.empty(M)
    scale = np.empty(M)
    G0 = np.zeros((M, __W__))
    A0 = np.zeros((M, __W__))
    G1 = np.zeros((M, __W__))
    A1 = np.zeros((M, __W__))
    B = np.zeros((M, BW))
    piv = np.empty(M, dtype=np.int64)
    # the multipliers of each sub-step at the last three steps: the next one starts from their
    # quadratic extrapolation (a guess within O(h^3); fewer points at the start of a call)
    S = fractions.shape[0]
    lam_last = np.zeros((S, M))
    lam_before = np.zeros((S, M))
    lam_third = np.zeros((S, M))
    known = 0
    evals = 0.0
    residual = 0.0
    for step in range(n_steps):
        for i in range(N):
            qs[i] = q[i]
            ps[i] = p[i]
        tau = t + step * dt
        for s in range(fractions.shape[0]):
            h = dt * fractions[s]
            tau1 = tau + h
            grad_potential(q, tau, c, gv)
            evals += 1.0
            for i in range(N):
                ph[i] = p[i] - 0.5 * h * gv[i]
                qp[i] = q[i] + h * minv[i] * ph[i]
            if M > 0:
                constraint_parts(q, tau, c, chi, G0, ct)
                for a in range(M):
                    g2 = 1.0
                    for k in range(GW[a]):
                        A0[a, k] = minv[GC[a, k]] * G0[a, k]
                        g2 += G0[a, k] * G0[a, k]
                    scale[a] = 1.0 / g2
                for i in range(N):
                    q1[i] = qp[i]
                for a in range(M):
                    if known >= 3:
                        lam[a] = 3.0 * (lam_last[s, a] - lam_before[s, a]) + lam_third[s, a]
                    elif known == 2:
                        lam[a] = 2.0 * lam_last[s, a] - lam_before[s, a]
                    elif known == 1:
                        lam[a] = lam_last[s, a]
                    else:
                        lam[a] = 0.0
                    for k in range(GW[a]):
                        q1[GC[a, k]] -= 0.5 * h * h * A0[a, k] * lam[a]
                converged = False
                factored = False  # Newton's matrix of this step factorised (kept while it contracts fast)
                previous = np.inf
                for _it in range(max_iter):
                    constraint_parts(q1, tau1, c, chi, G1, ct)
                    evals += 1.0
                    # each constraint against its own scale tol (1 + |grad chi_a(q)|^2): round-off in
                    # chi_a is of the order of its terms, not of |q|^2, so a long chain far from the
                    # origin keeps its rods as well as a short one
                    residual = 0.0
                    for a in range(M):
                        v = abs(chi[a]) * scale[a]
                        if v > residual or v != v:
                            residual = v if v == v else np.inf
                    if residual <= tol:
                        converged = True
                        break
                    if residual != residual or residual == np.inf:
                        break
                    if not factored or residual > 0.01 * previous:
                        # the matrix at this iterate; later iterates reuse it while the residual
                        # falls a hundredfold an iteration (the iterates move by O(residual))
                        band_assemble(G1, A0, -0.5 * h * h, B)
                        band_factor(B, piv)
                        factored = True
                    previous = residual
                    for a in range(M):
                        d[a] = chi[a]
                    band_lu_solve(B, piv, d)
                    for a in range(M):
                        lam[a] -= d[a]
                    for i in range(N):
                        q1[i] = qp[i]
                    for a in range(M):
                        for k in range(GW[a]):
                            q1[GC[a, k]] -= 0.5 * h * h * A0[a, k] * lam[a]
                if not converged:
                    for i in range(N):
                        q[i] = qs[i]
                        p[i] = ps[i]
                    report(info, step, True, evals, residual)
                    return
                for a in range(M):
                    lam_third[s, a] = lam_before[s, a]
                    lam_before[s, a] = lam_last[s, a]
                    lam_last[s, a] = lam[a]
                    for k in range(GW[a]):
                        ph[GC[a, k]] -= 0.5 * h * G0[a, k] * lam[a]
                for i in range(N):
                    q[i] = q1[i]
            else:
                for i in range(N):
                    q[i] = qp[i]
            grad_potential(q, tau1, c, gv)
            evals += 1.0
            for i in range(N):
                p[i] = ph[i] - 0.5 * h * gv[i]
            if M > 0:  # G1 and ct are those of the converged iterate q1 = q at tau1
                for a in range(M):
                    acc = ct[a]
                    for k in range(GW[a]):
                        A1[a, k] = minv[GC[a, k]] * G1[a, k]
                        acc += G1[a, k] * minv[GC[a, k]] * p[GC[a, k]]
                    d[a] = acc
                band_assemble(G1, A1, 0.5 * h, B)
                band_solve(B, d, piv)
                for a in range(M):
                    for k in range(GW[a]):
                        p[GC[a, k]] -= 0.5 * h * G1[a, k] * d[a]
            tau = tau1
        known += 1
    report(info, n_steps, False, evals, residual)


@numba.njit(cache=True)
def report(info, steps_done, failed, evals, residual):
    """info = [steps_done, failed (0/1), evaluations, last_residual]."""
    info[0] = steps_done
    info[1] = 1.0 if failed else 0.0
    info[2] = evals
    info[3] = residual


@numba.njit(cache=True)
def constraints(q, t, c, out):
    """chi(q, t), (m,)."""
    Gv = np.zeros((M, __W__))
    ct = np.empty(M)
    constraint_parts(q, t, c, out, Gv, ct)


@numba.njit(cache=True)
def constraints_dt(q, t, c, out):
    """d chi/dt, (m,)."""
    Gv = np.zeros((M, __W__))
    chi = np.empty(M)
    constraint_parts(q, t, c, chi, Gv, out)


@numba.njit(cache=True)
def jacobian(q, t, c, out):
    """G = d chi/dq, (m, n) (dense, from the sparse rows)."""
    Gv = np.zeros((M, __W__))
    chi = np.empty(M)
    ct = np.empty(M)
    constraint_parts(q, t, c, chi, Gv, ct)
    for a in range(M):
        for i in range(N):
            out[a, i] = 0.0
        for k in range(GW[a]):
            out[a, GC[a, k]] += Gv[a, k]


@numba.njit(cache=True)
def mass(q, t, c, out):
    """M (constant, diagonal), (n, n)."""
    minv = np.empty(N)
    inverse_mass(c, minv)
    for i in range(N):
        for j in range(N):
            out[i, j] = 0.0
        out[i, i] = 1.0 / minv[i]


@numba.njit(cache=True)
def velocity(q, p, t, c, v, work, piv):
    """v = M^{-1} p."""
    inverse_mass(c, v)
    for i in range(N):
        v[i] *= p[i]


@numba.njit(cache=True)
def energy(q, p, t, c):
    """H = 1/2 p^T M^{-1} p + V(q, t)."""
    minv = np.empty(N)
    inverse_mass(c, minv)
    s = 0.0
    for i in range(N):
        s += p[i] * minv[i] * p[i]
    return 0.5 * s + potential(q, t, c)


@numba.njit(cache=True)
def residuals(q, p, t, c, out):
    """out = (chi(q, t), G(q, t) M^{-1} p + d chi/dt), (2m,)."""
    minv = np.empty(N)
    inverse_mass(c, minv)
    Gv = np.zeros((M, __W__))
    chi = np.empty(M)
    ct = np.empty(M)
    constraint_parts(q, t, c, chi, Gv, ct)
    for a in range(M):
        out[a] = chi[a]
        acc = ct[a]
        for k in range(GW[a]):
            acc += Gv[a, k] * minv[GC[a, k]] * p[GC[a, k]]
        out[M + a] = acc
'''
