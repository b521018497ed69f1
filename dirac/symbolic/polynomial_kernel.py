"""Polynomial null vectors and scaled right inverses of a polynomial matrix, by ansatz.

A Lagrangian written through ``k`` velocity combinations ``l = A(q) q_dot`` (the body
angular velocities (227) of the rigid body) has momenta ``p - a = A^T G l`` (229): the
primary constraints are ``n^T (p - a) = 0`` for the null vectors ``n`` of ``A``, and the
canonical Hamiltonian needs ``G l`` from ``p`` on the primary surface. Inverting a
``k x k`` block of ``A`` does both but puts a minor of ``A`` in every denominator, and
that minor vanishes on part of the physical configuration space (for (228) it is a
cofactor of ``R``, zero at ``R = 1``).

Here both are found as *polynomials* by undetermined coefficients, degree by degree
(exact linear algebra over ``QQ`` or ``QQ(parameters)``):

* null vectors ``n(q)`` with ``A n = 0`` of the lowest degree; for (228) these are of
  degree one and give ``sym(p R^T) = 0``, equivalent to (230) ``sym(R^{-1} p) = 0``
  (``R^{-1} p = R^{-1} (p R^T) R^{-T}``) without any denominator;
* pairs ``(B_r(q), d_r(q))`` with ``A B_r = d_r 1``. On the primary surface
  ``G l = B_r^T (p - a) / d_r`` for each ``r``, hence

      G l = sum_r d_r B_r^T (p - a) / sum_r d_r^2,

  valid wherever one ``d_r`` is non-zero (for (228) the ``d_r`` are the nine
  cofactors of ``R``, so wherever ``rank R >= 2``); a single ``d`` that is a non-zero
  constant is used alone.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import numpy as np
import sympy
from sympy.polys.matrices import DomainMatrix
from sympy.polys.matrices.sdm import SDM
from sympy.polys.rings import PolyRing

__all__ = ["PolynomialKernel", "polynomial_kernel"]

MAX_UNKNOWNS = 4000


class PolynomialKernel:
    """Polynomial null basis and scaled right inverses of ``A(q)`` (see the module text).

    Attributes
    ----------
    null_basis
        ``n - rank`` polynomial null vectors (columns), independent over ``K(q)``.
    right_inverses
        Pairs ``(B_r, d_r)`` with ``A B_r = d_r 1`` of the lowest degree found.
    degree
        Degrees of the null vectors and of the ``B_r``.
    """

    def __init__(
        self,
        null_basis: list[list[sympy.Expr]],
        right_inverses: list[tuple[sympy.Matrix, sympy.Expr]],
        degree: tuple[int, int],
        unit_denominator: bool = False,
    ):
        self.null_basis = null_basis
        self.right_inverses = right_inverses
        self.degree = degree
        self.unit_denominator = unit_denominator

    def momentum_solution(self, shifted: sympy.Matrix) -> tuple[sympy.Matrix, sympy.Expr]:
        """``(m, den)`` with ``G l = m / den`` on the primary surface for ``shifted = p - a``."""
        constant = [(B, d) for B, d in self.right_inverses if not d.free_symbols]
        if constant or self.unit_denominator:
            B, d = (constant or self.right_inverses)[0]
            return B.T * shifted, d
        m = sum((d * (B.T * shifted) for B, d in self.right_inverses), sympy.zeros(self.right_inverses[0][0].shape[1], 1))
        den = sum((d**2 for _, d in self.right_inverses), sympy.S.Zero)
        return m, den


def _monomials(nvars: int, degree: int) -> list[tuple[int, ...]]:
    out = []
    for d in range(degree + 1):
        for combo in itertools.combinations_with_replacement(range(nvars), d):
            e = [0] * nvars
            for i in combo:
                e[i] += 1
            out.append(tuple(e))
    return out


def _solve_ansatz(columns: dict[int, dict], neqs: int, nunknowns: int, domain) -> list[dict[int, object]]:
    """Null space of the sparse equation matrix given column-wise -> list of sparse vectors."""
    rows: dict[int, dict[int, object]] = {}
    for u, col in columns.items():
        for r, c in col.items():
            if c:
                rows.setdefault(r, {})[u] = c
    M = DomainMatrix.from_rep(SDM(rows, (neqs, nunknowns), domain))
    ns = M.nullspace().to_sdm()
    return [dict(ns.get(i, {})) for i in range(ns.shape[0])]


def polynomial_kernel(
    A: sympy.Matrix,
    variables: Sequence[sympy.Symbol],
    parameter_values: dict,
    rng: np.random.Generator,
    rank: int,
    max_degree: int = 3,
    holonomic: Sequence[sympy.Expr] = (),
) -> PolynomialKernel | None:
    """Polynomial null basis and scaled right inverses of ``A`` (``k x n``, entries polynomial in ``variables``).

    Parameters
    ----------
    A
        The velocity-combination matrix ``l = A q_dot``.
    variables
        The coordinates ``q``; every other symbol of ``A`` is a parameter (coefficient field).
    parameter_values, rng
        Generic values and a generator for the numerical independence test over ``K(q)``.
    rank
        ``rank A`` (decided numerically by the caller); ``n - rank`` null vectors are sought.
    max_degree
        Highest degree tried.
    holonomic
        The holonomic constraints ``chi(q)``: a right inverse whose ``d`` is constant on
        ``chi = 0`` is preferred (searched at the lowest degree and the next).

    Returns
    -------
    PolynomialKernel or None
        ``None`` when ``A`` is not polynomial, the ansatz grows past :data:`MAX_UNKNOWNS`
        unknowns, or no solution exists up to ``max_degree`` (the caller then inverts a block).
    """
    k, n = A.shape
    q = list(variables)
    params = sorted(set().union(*[e.free_symbols for e in A]) - set(q), key=lambda s: s.name)
    domain = sympy.QQ.frac_field(*params) if params else sympy.QQ
    ring = PolyRing(q, domain)
    try:
        entries = [[ring(sympy.sympify(A[i, j])) for j in range(n)] for i in range(k)]
    except (sympy.CoercionFailed, sympy.PolynomialError, TypeError, ValueError):
        return None
    args = [*q, *params]
    pvals = [float(parameter_values[s]) for s in params]
    points = [np.concatenate([rng.uniform(0.5, 1.5, len(q)) * rng.choice([-1.0, 1.0], len(q)), pvals]) for _ in range(3)]

    null_basis = None
    null_degree = -1
    for degree in range(max_degree + 1):
        monos = _monomials(len(q), degree)
        nunk = n * len(monos)
        if nunk > MAX_UNKNOWNS:
            return None
        eqs: dict = {}
        columns: dict[int, dict] = {}
        for j in range(n):
            for mi, mono in enumerate(monos):
                u = j * len(monos) + mi
                col = columns.setdefault(u, {})
                for i in range(k):
                    for mon, c in entries[i][j].terms():
                        key = (i, tuple(a + b for a, b in zip(mon, mono)))
                        r = eqs.setdefault(key, len(eqs))
                        col[r] = col.get(r, domain.zero) + c
        solutions = _solve_ansatz(columns, len(eqs), nunk, domain)
        if len(solutions) < n - rank:
            continue
        vectors = []
        for sol in solutions:
            vec = [sympy.S.Zero] * n
            for u, c in sol.items():
                j, mi = divmod(u, len(monos))
                vec[j] += domain.to_sympy(c) * sympy.Mul(*[s**e for s, e in zip(q, monos[mi])])
            vectors.append(vec)
        vectors.sort(key=lambda v: (max(sympy.Poly(e, *q).total_degree() for e in v if e != 0), sum(len(sympy.Add.make_args(e)) for e in v)))
        fn = sympy.lambdify(args, sympy.Matrix(vectors).T, modules="numpy")
        values = [np.array(fn(*pt), dtype=float).reshape(n, len(vectors)) for pt in points]
        chosen: list[int] = []
        for idx in range(len(vectors)):
            trial = chosen + [idx]
            if all(np.linalg.matrix_rank(v[:, trial], tol=1e-9 * max(1.0, np.abs(v).max())) == len(trial) for v in values):
                chosen = trial
                if len(chosen) == n - rank:
                    break
        if len(chosen) == n - rank:
            null_basis = [vectors[i] for i in chosen]
            null_degree = degree
            break
    if null_basis is None:
        return None

    lowest = None
    for degree in range(max_degree + 1):
        solutions = _right_inverse_solutions(A, entries, q, domain, degree)
        if solutions is None:
            return None
        if any(d != 0 for _, d in solutions) and lowest is None:
            lowest = (degree, [(B, d) for B, d in solutions if d != 0])
        if lowest is not None and holonomic:
            unit = _unit_denominator(solutions, q, params, pvals, holonomic, rng) or _unit_denominator(
                solutions, q, params, pvals, holonomic, rng, tangent=False
            )
            if unit is not None:
                return PolynomialKernel(null_basis, [unit], (null_degree, degree), unit_denominator=True)
        if lowest is not None and degree >= lowest[0] + 1:
            break
    if lowest is None:
        return None
    return PolynomialKernel(null_basis, lowest[1], (null_degree, lowest[0]))


def _right_inverse_solutions(A, entries, q, domain, degree) -> list[tuple[sympy.Matrix, sympy.Expr]] | None:
    """A basis of the solutions ``(B, d)`` of ``A B = d 1`` with ``B`` of degree ``<= degree`` (``d`` may be 0)."""
    k, n = A.shape
    monos = _monomials(len(q), degree)
    nunk = n * k * len(monos)
    if nunk > MAX_UNKNOWNS:
        return None
    eqs: dict = {}
    columns: dict[int, dict] = {}
    # unknown u <-> monomial mi of B[j, c]; equations (AB)_ic = 0 (i != c) and (AB)_ii = (AB)_00
    for j in range(n):
        for c_ in range(k):
            for mi, mono in enumerate(monos):
                u = (j * k + c_) * len(monos) + mi
                col = columns.setdefault(u, {})
                for i in range(k):
                    for mon, c in entries[i][j].terms():
                        shifted_mon = tuple(a + b for a, b in zip(mon, mono))
                        if i != c_:
                            keys = [(("off", i, c_, shifted_mon), c)]
                        elif i > 0:
                            keys = [(("diag", i, shifted_mon), c)]
                        else:
                            keys = [(("diag", i2, shifted_mon), -c) for i2 in range(1, k)]
                        for key, value in keys:
                            r = eqs.setdefault(key, len(eqs))
                            col[r] = col.get(r, domain.zero) + value
    out = []
    for sol in _solve_ansatz(columns, len(eqs), nunk, domain):
        B = sympy.zeros(n, k)
        for u, c in sol.items():
            jc, mi = divmod(u, len(monos))
            j, c_ = divmod(jc, k)
            B[j, c_] += domain.to_sympy(c) * sympy.Mul(*[s**e for s, e in zip(q, monos[mi])])
        out.append((B, sympy.expand((A[0, :] * B[:, 0])[0, 0])))
    return out


def _holonomic_samples(q, params, pvals, holonomic, rng, count: int) -> np.ndarray | None:
    """Points of ``chi(q) = 0`` along a random walk (small steps keep one connected component)."""
    chi = sympy.Matrix(list(holonomic))
    args = [*q, *params]
    f = sympy.lambdify(args, chi, modules="numpy")
    jac = sympy.lambdify(args, chi.jacobian(q), modules="numpy")

    def project(x):
        for _ in range(50):
            r = np.array(f(*x, *pvals), dtype=float).ravel()
            if np.max(np.abs(r)) < 1e-13:
                return x
            J = np.array(jac(*x, *pvals), dtype=float).reshape(len(r), len(q))
            x = x - np.linalg.lstsq(J, r, rcond=None)[0]
        return None

    x = project(rng.normal(size=len(q)))
    if x is None:
        return None
    points = []
    failures = 0
    while len(points) < count:
        y = project(x + 0.1 * rng.normal(size=len(q)))
        if y is None or np.linalg.norm(y - x) > 1.0:  # a long jump may change component: refuse it
            failures += 1
            if failures > 10 * count:
                return None
            continue
        points.append(y)
        x = y
    return np.array(points)


def _unit_denominator(solutions, q, params, pvals, holonomic, rng, tangent: bool = True) -> tuple[sympy.Matrix, sympy.Expr] | None:
    """A sparse rational combination of ``solutions`` whose ``d`` is a non-zero constant on ``chi = 0``.

    Such a ``d`` (``det R`` for (228), which is 1 on SO(3)) never vanishes on the
    configurations the motion can reach. With ``tangent`` the columns of ``B`` must also be
    tangent to ``chi = 0`` (``J_chi B = 0`` there), which removes multiples of the null
    vectors that would otherwise hide in ``H_c`` (for (228) it gives the paper's
    ``M = -eps (R^{-1} p)`` (233) and ``d(R^T R)/dt = 0`` without multipliers). Found by basis pursuit (least ``l1`` norm, which
    favours sparse combinations) on the values at points of ``chi = 0``; the coefficients
    are made rational and the constancy is checked again at fresh points. ``None`` when
    there is no such combination.
    """
    from fractions import Fraction

    from scipy.optimize import linprog

    if not tangent:
        solutions = [(B, d) for B, d in solutions if d != 0]
    m = len(solutions)
    args = [*q, *params]
    d_fn = sympy.lambdify(args, [d for _, d in solutions], modules="numpy")
    points = _holonomic_samples(q, params, pvals, holonomic, rng, min(2 * m + 10, 400))
    if points is None:
        return None
    D = np.array([np.broadcast_to(np.array(d_fn(*x, *pvals), dtype=float), (m,)) for x in points])
    scale = np.max(np.abs(D)) or 1.0
    target = np.ones(len(points))
    if tangent:
        # columns of B tangent to chi = 0: J_chi B = 0 there, so the flow of H_c keeps chi = 0
        # and no multiple of the primary constraints is hidden in H_c
        chi = sympy.Matrix(list(holonomic))
        J_fn = sympy.lambdify(args, chi.jacobian(q), modules="numpy")
        B_fn = sympy.lambdify(args, [B for B, _ in solutions], modules="numpy")
        rows = []
        for x in points:
            J = np.array(J_fn(*x, *pvals), dtype=float).reshape(len(holonomic), len(q))
            Bs = [np.broadcast_to(np.array(B, dtype=float), solutions[0][0].shape) for B in B_fn(*x, *pvals)]
            rows.append(np.stack([(J @ B).ravel() for B in Bs], axis=1))
        T = np.vstack(rows)
        T *= scale / (np.max(np.abs(T)) or 1.0)
        D = np.vstack([D, T])
        target = np.concatenate([target, np.zeros(len(T))])
    U, S, _ = np.linalg.svd(D, full_matrices=False)
    r = int(np.sum(S > 1e-10 * S[0])) if S.size and S[0] > 0 else 0
    if r == 0:
        return None
    A_eq = U[:, :r].T @ D
    b_eq = U[:, :r].T @ target
    if np.max(np.abs(D @ np.linalg.lstsq(D, target, rcond=None)[0] - target)) > 1e-9:
        return None  # no combination is constant on chi = 0
    lp = linprog(np.ones(2 * m), A_eq=np.hstack([A_eq, -A_eq]), b_eq=b_eq, bounds=(0, None), method="highs")
    if lp.status != 0:
        return None
    full = lp.x[:m] - lp.x[m:]
    support = [int(i) for i in np.nonzero(np.abs(full) > 1e-9 * max(1.0, np.max(np.abs(full))))[0]]
    coeff = np.linalg.lstsq(D[:, support], target, rcond=None)[0]
    big = np.max(np.abs(coeff))
    rational = [sympy.Rational(Fraction(float(c / big)).limit_denominator(1000)) for c in coeff]
    if any(abs(float(r) - c / big) > 1e-9 for r, c in zip(rational, coeff)) or not any(rational):
        return None
    B = sum((r * solutions[i][0] for r, i in zip(rational, support)), sympy.zeros(*solutions[0][0].shape))
    d = sympy.expand(sum((r * solutions[i][1] for r, i in zip(rational, support)), sympy.S.Zero))
    check = _holonomic_samples(q, params, pvals, holonomic, rng, 8)
    if check is None or d == 0:
        return None
    values = np.array([float(d.subs(dict(zip([*q, *params], [*x, *pvals])))) for x in check])
    if np.max(np.abs(values - values[0])) > 1e-9 * max(1.0, abs(values[0]) * scale) or abs(values[0]) < 1e-9:
        return None
    return B, d
