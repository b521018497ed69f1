"""Legendre transform of the extended Lagrangian: momenta, Hessian, primary constraints, H_c.

For ``L_ext = L(q, q_dot) - lambda_a chi_a(q)`` (the paper's (1); (78) and (228) for the
rigid body) the multipliers are coordinates with momenta ``p_lambda_a = 0`` (primary
constraints, (206)). The engine treats Lagrangians quadratic in the velocities,

    L = 1/2 q_dot^T W(q) q_dot + a(q) . q_dot - V(q),

the common mechanical case (other Lagrangians, e.g. with square roots of the velocities,
go to :mod:`dirac.analysis.legendre.velocity_elimination`). Then ``p = W q_dot + a`` ((205), (229)). With ``r = rank W``
(decided numerically at generic points), a set ``S`` of ``r`` indices with ``W_SS``
invertible is chosen; the null space of ``W`` is spanned by
``n_j = e_j - W_SS^{-1} W_Sj`` (``j`` not in ``S``), which gives the primary constraints

    phi_j = (p - a)_j - W_jS W_SS^{-1} (p - a)_S = 0      (cf. (230)),

and on the primary surface the canonical Hamiltonian is

    H_c = 1/2 (p - a)_S^T W_SS^{-1} (p - a)_S + V + lambda_a chi_a     ((207), (232)),

(any generalised inverse of ``W`` gives the same value there). When ``L`` is written
through linear combinations of velocities, ``W = A^T G A`` with ``A`` the ``k x n``
coefficient matrix of ``k`` such combinations; then ``null W = null A`` and the
primary constraints ``phi_j = (p - a)_j - (A_S^{-1} A_j)^T (p - a)_S`` avoid the
``r x r`` inverse of ``W_SS`` (whose entries are products). When ``A`` is polynomial,
:mod:`dirac.analysis.legendre.polynomial_kernel` first looks for polynomial null vectors of ``A``
and a polynomial ``B`` with ``A B = d 1`` (``G l = B^T (p - a) / d`` on the primary
surface), which avoids denominators that vanish on the physical surface — used for the
rigid-body Lagrangian (228), where the velocity combinations are the body angular
velocities (227) and this gives ``sym(p R^T) = 0`` and the paper's (232).
A Lagrangian linear in the velocities (``W = 0``, rank 0) is handled by
:mod:`dirac.analysis.legendre.first_order`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import sympy
from sympy.polys.polyerrors import BasePolynomialError

from dirac.analysis.core.algebra import tidy
from dirac.analysis.core.fast_partials import SPARSE_HESSIAN, quadratic_parts
from dirac.analysis.core.numeric import Numerics, independent_rows
from dirac.analysis.core.phase_space import PhaseSpace, derivative
from dirac.analysis.core.pythagoras import circle_polynomial
from dirac.analysis.legendre.first_order import FIRST_ORDER_METHOD, first_order_primary
from dirac.analysis.legendre.polynomial_kernel import polynomial_kernel
from dirac.codegen import array_function
from dirac.errors import AnalysisError
from dirac.model.lagrangian import Lagrangian, momentum_name, multiplier_name

__all__ = ["LegendreTransform", "legendre_transform"]


@dataclass
class LegendreTransform:
    """Result of the Legendre transform of an extended Lagrangian.

    Attributes
    ----------
    phase_space
        Coordinates ``q, lambda`` and momenta ``p_q, p_lambda``.
    hessian
        ``W = d^2 L / dq_dot dq_dot`` (of the original coordinates; the multipliers'
        rows and columns are zero).
    rank
        Rank of the full Hessian of ``L_ext`` (multipliers included).
    primary
        Primary constraints: ``p_lambda_a`` first, then those from the null space of ``W``.
    canonical_hamiltonian
        ``H_c`` on the primary surface.
    method
        How the null space was found (for the analysis report).
    """

    phase_space: PhaseSpace
    multipliers: tuple[sympy.Symbol, ...]
    hessian: sympy.Matrix
    rank: int
    primary: list[sympy.Expr]
    canonical_hamiltonian: sympy.Expr
    method: str
    velocity_solution: dict = field(default_factory=dict)


#: largest matrix of trigonometric entries inverted through its simplified determinant (:func:`_inverse`)
TRIG_INVERSE_SIZE = 4


class NotQuadraticError(AnalysisError):
    """``L`` is not quadratic in the velocities (then :mod:`dirac.analysis.legendre.velocity_elimination` is tried)."""


def _quadratic_parts(lagrangian: Lagrangian) -> tuple[sympy.Matrix, list[sympy.Expr], sympy.Expr]:
    """``W``, ``a`` and ``V`` of a Lagrangian quadratic in the velocities (else NotQuadraticError).

    A polynomial ``L`` is split in the sparse polynomial ring
    (:func:`dirac.analysis.core.fast_partials.quadratic_parts`: only the non-zero entries of
    ``W``); other Lagrangians with ``sympy.diff``.
    """
    extra = (lagrangian.time,) if lagrangian.is_time_dependent else ()
    fast = quadratic_parts(lagrangian.expression, lagrangian.coordinates, lagrangian.velocities, (*lagrangian.parameters, *extra))
    if fast is not None:
        return fast
    v = lagrangian.velocities
    L = lagrangian.expression
    first = [derivative(L, vi) for vi in v]  # sympy.diff's expressions, each shared sub-tree once
    W = sympy.Matrix(len(v), len(v), lambda i, j: derivative(first[i], v[j]))
    vset = set(v)
    for i in range(len(v)):
        for j in range(len(v)):
            if W[i, j].free_symbols & vset:
                W[i, j] = sympy.cancel(W[i, j])
                if W[i, j].free_symbols & vset:
                    raise NotQuadraticError(
                        f"the Lagrangian of {lagrangian.name!r} is not quadratic in the velocities "
                        f"(d2L/d{v[i].name}d{v[j].name} = {W[i, j]} depends on the velocities): its "
                        "primary constraints cannot be found in closed form, so the analysis is refused; "
                        "write L as 1/2 q_dot^T W(q) q_dot + a(q).q_dot - V(q)"
                    )
    zero = {vi: 0 for vi in v}
    a = [f.subs(zero) for f in first]
    V = -L.subs(zero)
    return W, a, V


def _velocity_forms(lagrangian: Lagrangian) -> tuple[sympy.Matrix, sympy.Matrix] | None:
    """Find ``L2 = 1/2 l^T G l`` with ``l = A q_dot`` linear velocity combinations, if visible.

    Looks for sub-expressions of ``L`` that are sums linear and homogeneous in the
    velocities, involving more than one velocity; replaces them by symbols and checks
    that the velocity-quadratic part of ``L`` is then a quadratic form in those symbols
    alone. Returns ``(A, G)`` or ``None``.
    """
    v = lagrangian.velocities
    vset = set(v)
    L = lagrangian.expression
    forms: list[sympy.Expr] = []

    def linear_form(e: sympy.Expr) -> bool:
        if not isinstance(e, sympy.Add) or len(e.free_symbols & vset) < 2:
            return False
        for term in e.args:
            hits = [s for s in term.free_symbols if s in vset]
            if len(hits) != 1 or sympy.degree(term, hits[0]) != 1 or not term.is_polynomial(hits[0]):
                return False
        return True

    for node in sympy.preorder_traversal(L):
        if linear_form(node) and node not in forms and -node not in forms:
            forms.append(node)
    if not forms:
        return None
    ell = sympy.symbols(f"_ell0:{len(forms)}")
    replaced = L.xreplace(dict(zip(forms, ell)))
    if replaced.free_symbols & vset:
        return None
    G = sympy.hessian(replaced, ell)
    if any(sympy.diff(G, s) != sympy.zeros(*G.shape) for s in ell):
        return None
    A = sympy.Matrix(len(forms), len(v), lambda i, j: sympy.diff(forms[i], v[j]))
    return A, G


def legendre_transform(lagrangian: Lagrangian, rng: np.random.Generator, parameter_values: dict) -> LegendreTransform:
    """Legendre transform of the extended Lagrangian (1) of ``lagrangian``.

    Parameters
    ----------
    lagrangian
        The input: coordinates, velocities, ``L``, holonomic constraints, parameters.
    rng, parameter_values
        Random generator and generic parameter values for the numerical rank decisions.

    Raises
    ------
    AnalysisError
        If ``L`` is not quadratic in the velocities and its velocities cannot be
        eliminated (:mod:`dirac.analysis.legendre.velocity_elimination`).
    """
    q = lagrangian.coordinates
    n = len(q)
    lambdas = tuple(sympy.Symbol(multiplier_name(k + 1), real=True) for k in range(len(lagrangian.constraints)))
    coords = q + lambdas
    momenta = tuple(sympy.Symbol(momentum_name(c.name), real=True) for c in coords)
    space = PhaseSpace(coords, momenta, tuple(lagrangian.parameters))
    try:
        W, a, V = _quadratic_parts(lagrangian)
    except NotQuadraticError:
        return _not_quadratic(lagrangian, space, lambdas, rng, parameter_values)
    p = sympy.Matrix(momenta[:n])
    shifted = p - sympy.Matrix(a)
    # numerical rank and pivots of W at generic configurations
    time = [lagrangian.time] if lagrangian.is_time_dependent else []  # sampled with q
    args = (*q, *time, *lagrangian.parameters)
    nonzero = W.todok()  # compiled: the non-zero entries only (W is sparse for many velocities)
    entries = sorted(nonzero)
    w_fn = array_function(args, [nonzero[e] for e in entries], cse=False) if entries else None
    rows_w = np.array([i for i, _ in entries], dtype=int)
    cols_w = np.array([j for _, j in entries], dtype=int)
    pvals = [float(parameter_values[s]) for s in lagrangian.parameters]
    samples: list = []
    for _ in range(3):
        z = rng.uniform(0.5, 1.5, n + len(time)) * rng.choice([-1.0, 1.0], n + len(time))
        values = np.zeros(len(entries))
        if w_fn is not None:
            with np.errstate(all="ignore"):
                values = np.array(w_fn(*z, *pvals), dtype=float).reshape(-1)
        if n >= SPARSE_HESSIAN:  # sparse rows: the independent ones chosen by sparse elimination
            import scipy.sparse as sp  # imported when used: many velocities only

            samples.append(sp.csr_matrix((values, (rows_w, cols_w)), shape=(n, n)))
        else:
            sample = np.zeros((n, n))
            sample[rows_w, cols_w] = values
            samples.append(sample)
    undecided: list[str] = []  # a note when sparse rows of W had to be decided densely
    pivots = independent_rows(samples, list(range(n)), notes=undecided)
    rank = len(pivots)
    others = [j for j in range(n) if j not in pivots]
    S = pivots
    potential = V + sum((lam * chi for lam, chi in zip(lambdas, lagrangian.constraints)), sympy.S.Zero)
    primary: list[sympy.Expr] = list(momenta[n:])
    tidy_hamiltonian = True  # expand H_c over one denominator (not when that only grows it)
    method = "regular Hessian" if rank == n else ""
    if rank == n:
        if W.is_diagonal():  # O(n), not the O(n^2) products of dense n x n matrices
            velocity = sympy.Matrix([shifted[i] / W[i, i] for i in range(n)])
            H_c = sympy.Add(*[shifted[i] ** 2 / (2 * W[i, i]) for i in range(n)]) + potential
        else:
            W_inv = _inverse(W)
            H_c = (shifted.T * W_inv * shifted)[0, 0] / 2 + potential
            velocity = W_inv * shifted
    elif rank == 0:
        primary.extend(first_order_primary(shifted, space.variables))
        H_c = potential
        velocity = None
        method = FIRST_ORDER_METHOD
    else:
        forms = _velocity_forms(lagrangian)
        used_forms = False
        if forms is not None:
            A, G = forms
            a_fn = array_function(args, A, cse=False)
            a_samples = []
            for _ in range(3):
                z = rng.uniform(0.5, 1.5, n + len(time)) * rng.choice([-1.0, 1.0], n + len(time))
                a_samples.append(np.array(a_fn(*z, *pvals), dtype=float).reshape(A.shape))
            col_pivots = independent_rows([m.T for m in a_samples], list(range(n)))
            kernel = (
                polynomial_kernel(A, Numerics(space, parameter_values, seed=int(rng.integers(2**31)), time=(time or [None])[0]), rank, lagrangian.constraints)
                if len(col_pivots) == rank == A.shape[0] else None
            )
            if kernel is not None:
                for vec in kernel.null_basis:
                    phi = sum((c * s for c, s in zip(vec, shifted)), sympy.S.Zero)
                    primary.append(tidy(phi, space.variables, sign=True))
                m, den = kernel.momentum_solution(shifted)
                m = m.applyfunc(lambda e: tidy(e, space.variables))
                den = tidy(den, space.variables)
                G_inv = _inverse(G)
                kinetic = (m.T * G_inv * m)[0, 0] / (2 * den**2)
                H_c = kinetic + potential
                velocity = None
                used_forms = True
                tidy_hamiltonian = False
                if kernel.unit_denominator or len(kernel.right_inverses) == 1:
                    solved = f"G l = B^T (p - a) / d with polynomial B of degree {kernel.degree[1]}, A B = d 1, d = {den}"
                    if kernel.unit_denominator:
                        solved += " (constant on the holonomic constraint surface, B tangent to it)"
                else:
                    solved = (
                        f"G l = sum_r d_r B_r^T (p - a) / sum_r d_r^2 with polynomial B_r of degree "
                        f"{kernel.degree[1]}, A B_r = d_r 1"
                    )
                method = (
                    f"singular Hessian of rank {rank}: L is a quadratic form in {A.shape[0]} linear velocity "
                    f"combinations l = A q_dot; primary constraints from polynomial null vectors of A (degree "
                    f"{kernel.degree[0]}); on the primary surface {solved}"
                )
            elif len(col_pivots) == rank == A.shape[0]:
                S = col_pivots
                others = [j for j in range(n) if j not in S]
                A_S = A[:, S]
                A_S_inv = _inverse(A_S)
                K = A_S_inv * A[:, others]  # column j: coefficients of the null vector
                for col, j in enumerate(others):
                    phi = shifted[j] - sum((K[r, col] * shifted[S[r]] for r in range(len(S))), sympy.S.Zero)
                    primary.append(sympy.together(sympy.expand(phi)))
                G_inv = _inverse(G)
                ell = G_inv * A_S_inv.T * sympy.Matrix([shifted[s] for s in S])
                H_c = (ell.T * G * ell)[0, 0] / 2 + potential
                velocity = None
                used_forms = True
                method = (
                    f"singular Hessian of rank {rank}: L is a quadratic form in {A.shape[0]} linear velocity "
                    "combinations l = A q_dot, so null(W) = null(A) (no inverse of W needed)"
                )
        if not used_forms and W[S, S].is_diagonal():
            # W_SS diagonal: phi_j = (p - a)_j - sum_s W_js (p - a)_s / W_ss, H_c = sum_s (p - a)_s^2 / (2 W_ss)
            # (only the non-zero W_js enter: O(non-zeros), not O(n^2) matrix products)
            diagonal = {s: W[s, s] for s in S}
            in_row: dict[int, list[int]] = {}
            for i, j in entries:
                if j in diagonal:
                    in_row.setdefault(i, []).append(j)
            for j in others:
                terms = [nonzero[(j, s)] * shifted[s] / diagonal[s] for s in in_row.get(j, [])]
                primary.append(shifted[j] - sympy.Add(*terms))
            H_c = sympy.Add(*[shifted[s] ** 2 / (2 * w) for s, w in diagonal.items()]) + potential
            velocity = None
            method = f"singular Hessian of rank {rank}: null space from an invertible diagonal {rank}x{rank} block of W"
            used_forms = True
        if not used_forms:
            # fraction-free: null vectors det(W_SS) e_j - adj(W_SS) W_Sj, no rational cancellation
            W_SS = W[S, S]
            variables = space.variables
            adj = W_SS.adjugate(method="berkowitz").applyfunc(lambda e: tidy(e, variables))
            det = tidy(sum((W_SS[0, k] * adj[k, 0] for k in range(len(S))), sympy.S.Zero), variables)
            p_S = sympy.Matrix([shifted[s] for s in S])
            adj_p = (adj * p_S).applyfunc(lambda e: tidy(e, variables))
            for j in others:
                primary.append(shifted[j] - (W[j, S] * adj_p)[0, 0] / det)
            H_c = (p_S.T * adj_p)[0, 0] / (2 * det) + potential
            velocity = None
            method = (
                f"singular Hessian of rank {rank}: null space from an invertible {rank}x{rank} block of W, "
                "fraction-free (adjugate)"
            )
            tidy_hamiltonian = False
    if tidy_hamiltonian:
        H_c = tidy(H_c, space.variables)
    full_rank = rank
    if undecided:
        method += f" ({undecided[0].replace('independence of rows', 'rank of the Hessian')})"
    return LegendreTransform(
        phase_space=space,
        multipliers=lambdas,
        hessian=W,
        rank=full_rank,
        primary=primary,
        canonical_hamiltonian=H_c,
        method=method,
        velocity_solution={} if velocity is None else dict(zip(lagrangian.velocities, list(velocity))),
    )


def _not_quadratic(
    lagrangian: Lagrangian, space: PhaseSpace, lambdas: tuple[sympy.Symbol, ...], rng: np.random.Generator, parameter_values: dict
) -> LegendreTransform:
    """The transform of a non-quadratic ``L`` (:func:`~dirac.analysis.legendre.velocity_elimination.eliminate_velocities`)
    with the multipliers' primary constraints ``p_lambda = 0`` and ``lambda_a chi_a`` in ``H_c`` ((206), (207))."""
    n = len(lagrangian.coordinates)
    from dirac.analysis.legendre.velocity_elimination import eliminate_velocities  # only non-quadratic L need it

    result = eliminate_velocities(lagrangian, space.momenta[:n], rng, parameter_values)
    potential = sum((lam * chi for lam, chi in zip(lambdas, lagrangian.constraints)), sympy.S.Zero)
    return LegendreTransform(
        phase_space=space,
        multipliers=lambdas,
        hessian=result.hessian,
        rank=result.rank,
        primary=[*space.momenta[n:], *result.primary],
        canonical_hamiltonian=result.energy + potential,
        method=result.method,
        velocity_solution=result.velocity_solution,
    )


def _trig_factored(expr: sympy.Expr) -> sympy.Expr:
    """``expr``, a polynomial in sines and cosines, reduced with ``sin(u)^2 + cos(u)^2 = 1`` and factored.

    Pythagoras exactly (:func:`~dirac.analysis.core.pythagoras.circle_polynomial`), then
    ``sympy.factor`` of the polynomial in the sine and cosine symbols, written back: the same
    function of the angles. It replaces ``factor(trigsimp(.))``, which took 13 s on the mass
    matrix of a spherical double pendulum (angles ``t1, p1, t2, p2``) and decided nothing
    more. Anything that is not such a polynomial is factored as it is.
    """
    reduced = circle_polynomial(expr)
    polynomial = expr if reduced is None else reduced.polynomial
    try:
        polynomial = sympy.factor(polynomial)
    except (BasePolynomialError, NotImplementedError):  # not factored: the same function as it is
        pass
    return polynomial if reduced is None else polynomial.xreplace(reduced.back)


def _inverse(M: sympy.Matrix) -> sympy.Matrix:
    """Exact inverse, cheap for diagonal and block-diagonal matrices.

    A small matrix of trigonometric entries (Euler angles) is inverted as ``adj(M)/det M``
    with ``det M`` reduced and factored (:func:`_trig_factored`: ``2 sin(theta)^2/5`` for an asymmetric top): the rational
    normal form of its LU inverse (``cancel`` of 2000-operation entries with ``sin`` and
    ``cos`` as generators) took minutes, and its denominator hid the factor ``sin(theta)``.
    """
    if M.is_diagonal():
        return sympy.diag(*[1 / M[i, i] for i in range(M.shape[0])])
    if M.shape[0] <= TRIG_INVERSE_SIZE and M.has(sympy.sin, sympy.cos):
        det = _trig_factored(M.det(method="berkowitz"))
        return M.adjugate(method="berkowitz").applyfunc(lambda e: _trig_factored(e) / det)
    inv = M.inv(method="LU")
    return inv.applyfunc(sympy.cancel)
