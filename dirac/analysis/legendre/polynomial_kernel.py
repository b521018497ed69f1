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
* ``B(q)``, ``d(q)`` with ``A B = d 1``, so that ``G l = B^T (p - a) / d`` on the
  primary surface. Preferred: a sparse rational combination of the solutions whose ``d``
  is constant on the holonomic surface ``chi = 0`` and whose columns are tangent to it
  (for (228): ``d ∝ det R`` and ``G l = M = -eps (R^{-1} p)``, the paper's (233)).
  Otherwise all solutions ``(B_r, d_r)`` of the lowest degree are combined,

      G l = sum_r d_r B_r^T (p - a) / sum_r d_r^2,

  valid wherever one ``d_r`` is non-zero (for (228) the ``d_r`` are the nine
  cofactors of ``R``, so wherever ``rank R >= 2``).

Numbers (independence over ``K(q)``, points of ``chi = 0``) come from the engine's
:class:`~dirac.analysis.core.numeric.Numerics`.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from fractions import Fraction
from operator import add as add_exponents

import numpy as np
import sympy
from sympy.polys.matrices import DomainMatrix
from sympy.polys.matrices.sdm import SDM
from sympy.polys.rings import PolyRing

from dirac.analysis.core.numeric import Numerics
from dirac.analysis.legendre.basis_pursuit import least_l1
from dirac.errors import AnalysisError

__all__ = ["PolynomialKernel", "polynomial_kernel"]

MAX_UNKNOWNS = 4000


class PolynomialKernel:
    """Polynomial null basis and scaled right inverses of ``A(q)`` (see the module text).

    Attributes
    ----------
    null_basis
        ``n - rank`` polynomial null vectors, independent over ``K(q)``.
    right_inverses
        Pairs ``(B_r, d_r)`` with ``A B_r = d_r 1``: one pair when ``unit_denominator``.
    degree
        Degrees of the null vectors and of the ``B_r``.
    unit_denominator
        Whether the single ``d`` is constant on the holonomic surface.
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
        single = [(B, d) for B, d in self.right_inverses if not d.free_symbols] or self.right_inverses[:1]
        if len(self.right_inverses) == 1 or not single[0][1].free_symbols:
            B, d = single[0]  # the only one, or one with a constant d: no sum needed
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


def _ansatz(
    entries, q, domain, degree: int, columns: int, scaled_identity: bool, first_columns: list | None = None
) -> list[sympy.Matrix] | None:
    """A basis of the polynomial ``n x columns`` matrices ``X`` of degree ``<= degree`` with

    ``A X = 0`` (``scaled_identity=False``) or ``A X = d 1`` for some ``d`` (``True``).
    ``None`` when the ansatz has more than :data:`MAX_UNKNOWNS` unknowns. A list given as
    ``first_columns`` receives, per matrix, the first column's entries as dictionaries
    monomial exponents -> coefficient in ``domain`` (the same coefficients and monomials
    as the sympy entries: ``ring.from_dict`` of one equals the entry converted, and
    :func:`_first_diagonal` builds only the few it multiplies).
    """
    k, n = len(entries), len(entries[0])
    monos = _monomials(len(q), degree)
    nunk = n * columns * len(monos)
    if nunk > MAX_UNKNOWNS:
        return None
    equations: dict = {}
    rows: dict[int, dict] = {}

    def add(key, u, value) -> None:
        r = equations.setdefault(key, len(equations))
        row = rows.setdefault(r, {})
        row[u] = row.get(u, domain.zero) + value

    # unknown u <-> monomial mi of X[j, c]; equation (A X)_ic = 0, or with scaled_identity
    # (A X)_ic = 0 off the diagonal and (A X)_ii - (A X)_00 = 0
    for j in range(n):
        for c in range(columns):
            for mi, mono in enumerate(monos):
                u = (j * columns + c) * len(monos) + mi
                for i in range(k):
                    for mon, value in entries[i][j].terms():
                        shifted = tuple(map(add_exponents, mon, mono))  # the product's exponents
                        if not scaled_identity or i != c:
                            add(("zero", i, c, shifted), u, value)
                        elif i > 0:
                            add(("diagonal", i, shifted), u, value)
                        else:
                            for i2 in range(1, k):
                                add(("diagonal", i2, shifted), u, -value)
    rows = {r: {u: v for u, v in row.items() if v} for r, row in rows.items()}
    null = DomainMatrix.from_rep(SDM(rows, (len(equations), nunk), domain)).nullspace().to_sdm()
    powers: dict[int, sympy.Expr] = {}  # the monomials met, built once
    out = []
    for s in range(null.shape[0]):
        # the terms of each entry gathered, then summed once: the same canonical sums as
        # adding them one by one (their monomials differ), without re-flattening a growing sum
        terms: dict[tuple[int, int], list[sympy.Expr]] = {}
        first: list[dict] = [{} for _ in range(n)]  # column 0: monomial -> coefficient, per row
        for u, value in null.get(s, {}).items():
            jc, mi = divmod(u, len(monos))
            power = powers.get(mi)
            if power is None:
                power = powers[mi] = sympy.Mul(*[v**e for v, e in zip(q, monos[mi])])
            j, c = divmod(jc, columns)
            terms.setdefault((j, c), []).append(domain.to_sympy(value) * power)
            if c == 0:
                first[j][monos[mi]] = value
        X = sympy.zeros(n, columns)
        for (j, c), parts in terms.items():
            X[j, c] = sympy.Add(*parts)
        out.append(X)
        if first_columns is not None:
            first_columns.append(first)
    return out


def polynomial_kernel(
    A: sympy.Matrix,
    numerics: Numerics,
    rank: int,
    holonomic: Sequence[sympy.Expr] = (),
    max_degree: int = 3,
) -> PolynomialKernel | None:
    """Polynomial null basis and scaled right inverse(s) of ``A`` (``k x n``, polynomial in ``q``).

    Parameters
    ----------
    A
        The velocity-combination matrix ``l = A q_dot``; ``q`` are the first ``n``
        coordinates of ``numerics.phase_space``, every other symbol is a parameter
        (coefficient field).
    numerics
        Evaluator on the phase space: random points for the independence test over
        ``K(q)`` and points of ``chi = 0``.
    rank
        ``rank A`` (decided numerically by the caller); ``n - rank`` null vectors are sought.
    holonomic
        The holonomic constraints ``chi(q)``: a right inverse whose ``d`` is constant on
        ``chi = 0`` is preferred (searched at the lowest degree and the next).
    max_degree
        Highest degree tried.

    Returns
    -------
    PolynomialKernel or None
        ``None`` when ``A`` is not polynomial, the ansatz grows past :data:`MAX_UNKNOWNS`
        unknowns, or no solution exists up to ``max_degree`` (the caller then inverts a block).
    """
    k, n = A.shape
    q = list(numerics.phase_space.coordinates[:n])
    params = sorted(set().union(*[e.free_symbols for e in A]) - set(q), key=lambda s: s.name)
    domain = sympy.QQ.frac_field(*params) if params else sympy.QQ
    ring = PolyRing(q, domain)
    try:
        entries = [[ring(sympy.sympify(A[i, j])) for j in range(n)] for i in range(k)]
    except (sympy.CoercionFailed, sympy.PolynomialError, TypeError, ValueError):
        return None

    null_basis = None
    for null_degree in range(max_degree + 1):
        solutions = _ansatz(entries, q, domain, null_degree, 1, scaled_identity=False)
        if solutions is None:
            return None
        if len(solutions) >= n - rank:
            null_basis = _independent_vectors([list(X) for X in solutions], q, numerics, n - rank)
            if null_basis is not None:
                break
    if null_basis is None:
        return None

    lowest = None
    samples = None
    for degree in range(max_degree + 1):
        columns: list = []
        matrices = _ansatz(entries, q, domain, degree, k, scaled_identity=True, first_columns=columns)
        if matrices is None:
            return None
        solutions = [(B, _first_diagonal(A, B, entries, ring, column)) for B, column in zip(matrices, columns)]
        if lowest is None and any(d != 0 for _, d in solutions):
            lowest = (degree, [(B, d) for B, d in solutions if d != 0])
        if lowest is not None and holonomic:
            if samples is None:
                samples = _holonomic_samples(numerics, holonomic, 400), _holonomic_samples(numerics, holonomic, 8)
            walk, check = samples
            if walk is not None and check is not None:
                unit = _unit_denominator(solutions, numerics, holonomic, walk, check) or _unit_denominator(
                    [(B, d) for B, d in solutions if d != 0], numerics, holonomic, walk, check, tangent=False
                )
                if unit is not None:
                    return PolynomialKernel(null_basis, [unit], (null_degree, degree), unit_denominator=True)
        if lowest is not None and degree >= lowest[0] + 1:
            break
    if lowest is None:
        return None
    return PolynomialKernel(null_basis, lowest[1], (null_degree, lowest[0]))


def _first_diagonal(A: sympy.Matrix, B: sympy.Matrix, entries, ring: PolyRing, column: list) -> sympy.Expr:
    """``d = (A B)_00``, expanded: the scale of ``A B = d 1``.

    Over ``QQ`` (no parameters in ``A``) the product is taken in the polynomial ring and
    turned back into the expanded sum, the same expression as ``sympy.expand`` of the
    symbolic product (an expanded polynomial is canonical) at a fraction of the cost, for
    the hundreds of candidates of (228); with parameters, by ``sympy.expand``. ``column``
    is ``B``'s first column as the terms :func:`_ansatz` built it from: an entry is made
    a ring element from them (``from_dict``) instead of converting its sympy expression,
    a third of this function's time on (228) (413 conversions).
    """
    if ring.domain != sympy.QQ:
        return sympy.expand((A[0, :] * B[:, 0])[0, 0])
    total = ring.zero
    for a, b in zip(entries[0], column):
        if a and b:
            total += a * ring.from_dict(b)
    return total.as_expr()


def _independent_vectors(vectors: list[list[sympy.Expr]], q, numerics: Numerics, wanted: int) -> list[list[sympy.Expr]] | None:
    """``wanted`` vectors independent over ``K(q)`` (at random points), lowest degree and fewest terms first."""
    vectors = sorted(
        vectors,
        key=lambda v: (
            max(sympy.Poly(e, *q).total_degree() for e in v if e != 0),
            sum(len(sympy.Add.make_args(e)) for e in v),
        ),
    )
    n = len(vectors[0])
    fn = numerics.function([e for v in vectors for e in v])
    values = [fn(numerics.random_point()).reshape(len(vectors), n).T for _ in range(3)]
    chosen: list[int] = []
    for idx in range(len(vectors)):
        trial = chosen + [idx]
        if all(np.linalg.matrix_rank(v[:, trial], tol=1e-9 * max(1.0, np.abs(v).max())) == len(trial) for v in values):
            chosen = trial
            if len(chosen) == wanted:
                return [vectors[i] for i in chosen]
    return None


def _holonomic_samples(numerics: Numerics, holonomic: Sequence[sympy.Expr], count: int) -> np.ndarray | None:
    """Points of ``chi(q) = 0`` along a random walk (small steps keep one connected component)."""
    try:
        z = numerics.surface_points(holonomic, 1)[0]
    except AnalysisError:
        return None
    points: list[np.ndarray] = []
    failures = 0
    while len(points) < count:
        try:
            y = numerics.surface_points(holonomic, 1, attempts=1, start=z + 0.1 * numerics.rng.normal(size=z.size))[0]
        except AnalysisError:
            y = None
        if y is None or np.linalg.norm(y - z) > 1.0:  # a long jump may change component: refuse it
            failures += 1
            if failures > 10 * count:
                return None
            continue
        points.append(y)
        z = y
    return np.array(points)


def _unit_denominator(
    solutions: list[tuple[sympy.Matrix, sympy.Expr]],
    numerics: Numerics,
    holonomic: Sequence[sympy.Expr],
    points: np.ndarray,
    check: np.ndarray,
    tangent: bool = True,
) -> tuple[sympy.Matrix, sympy.Expr] | None:
    """A sparse rational combination of ``solutions`` whose ``d`` is a non-zero constant on ``chi = 0``.

    Such a ``d`` (``det R`` for (228), which is 1 on SO(3)) never vanishes on the
    configurations the motion can reach. With ``tangent`` the columns of ``B`` must also be
    tangent to ``chi = 0`` (``J_chi B = 0`` there), which removes multiples of the null
    vectors that would otherwise hide in ``H_c`` (for (228) it gives the paper's
    ``M = -eps (R^{-1} p)`` (233) and ``d(R^T R)/dt = 0`` without multipliers). Found by
    basis pursuit (least ``l1`` norm, which favours sparse combinations;
    :func:`~dirac.analysis.legendre.basis_pursuit.least_l1`) on the values at
    ``points``; the coefficients are made rational and the constancy is checked again at
    the fresh points ``check``. ``None`` when there is no such combination.
    """
    m = len(solutions)
    if not m:
        return None
    points = points[: 2 * m + 10]  # enough equations for m unknowns
    d_fn = numerics.function([d for _, d in solutions])
    D = np.array([d_fn(z) for z in points])
    scale = np.max(np.abs(D)) or 1.0
    target = np.ones(len(points))
    if tangent:
        # columns of B tangent to chi = 0: J_chi B = 0 there, so the flow of H_c keeps chi = 0
        # and no multiple of the primary constraints is hidden in H_c
        # (J_chi B evaluated as the product of the values of J_chi and of B at each point:
        # no symbolic product of the m candidate matrices)
        n, k = solutions[0][0].shape
        gradients = [g for c in holonomic for g in numerics.phase_space.gradient(c)[:n]]
        j_fn = numerics.function(gradients)
        b_fn = numerics.function([e for B, _ in solutions for e in B])
        per_point = len(holonomic) * k or 1  # J B has this many entries: as many equations per point
        T = np.vstack([
            np.einsum("hn,mnk->mhk", j_fn(z).reshape(len(holonomic), n), b_fn(z).reshape(m, n, k)).reshape(m, -1).T
            for z in points[: (2 * m + 10) // per_point + 10]
        ])
        T *= scale / (np.max(np.abs(T)) or 1.0)
        D = np.vstack([D, T])
        target = np.concatenate([target, np.zeros(len(T))])
    U, S, _ = np.linalg.svd(D, full_matrices=False)
    r = int(np.sum(S > 1e-10 * S[0]))
    A_eq, b_eq = U[:, :r].T @ D, U[:, :r].T @ target
    if np.max(np.abs(target - U[:, :r] @ b_eq)) > 1e-9:
        return None  # target not in the range of D: no combination is constant on chi = 0
    full = least_l1(A_eq, b_eq)
    if full is None:
        return None
    support = [int(i) for i in np.nonzero(np.abs(full) > 1e-9 * max(1.0, np.max(np.abs(full))))[0]]
    coeff = np.linalg.lstsq(D[:, support], target, rcond=None)[0]
    big = np.max(np.abs(coeff))
    rational = [sympy.Rational(Fraction(float(c / big)).limit_denominator(1000)) for c in coeff]
    if any(abs(float(r) - c / big) > 1e-9 for r, c in zip(rational, coeff)) or not any(rational):
        return None
    B = sum((r * solutions[i][0] for r, i in zip(rational, support)), sympy.zeros(*solutions[0][0].shape))
    d = sympy.expand(sum((r * solutions[i][1] for r, i in zip(rational, support)), sympy.S.Zero))
    if d == 0:
        return None
    values = numerics.evaluate([d], check)[:, 0]
    if np.max(np.abs(values - values[0])) > 1e-9 * max(1.0, abs(values[0]) * scale) or abs(values[0]) < 1e-9:
        return None
    return B, d
