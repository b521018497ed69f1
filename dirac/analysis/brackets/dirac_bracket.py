"""The Dirac bracket over the second-class constraints, exact or at a numeric point.

    {A, B}_D = {A, B} - {A, Phi_a} (C^{-1})^{ab} {Phi_b, B},    C_ab = {Phi_a, Phi_b}   (240)

Exact brackets never invert ``C`` densely: the terms ``{A, Phi_a}``, ``{Phi_b, B}`` and
the entries of ``C`` that vanish weakly are dropped, and ``C x = {Phi, B}`` is solved by
the block triangular method of :mod:`dirac.analysis.core.linear_solve` — the automatic form of
the paper's block inversion (245)-(246). The result is equal to the true bracket on the
constraint surface (weakly).

Numeric brackets (``at=point``) never compile a bracket per pair of functions. With
``z`` the phase-space variables (coordinates, then momenta), ``J = [[0, 1], [-1, 0]]``
and ``A = d Phi / d z`` (the sparse Jacobian of the second-class constraints, compiled
once over its non-zero entries),

    {f, Phi_a} = (grad f)^T J grad Phi_a,   C = A J A^T,
    {f, g}_D = (grad f)^T J grad g - (grad f)^T J A^T C^{-1} A J grad g,          (240)

so a point costs one evaluation of ``A`` and one factorisation of ``C`` (sparse LU for
more than ``SPARSE_C`` constraints, dense LU below), kept for the last few points; each
bracket at that point is then two sparse products and one triangular solve. The
gradient of a phase-space variable is a unit vector (no compilation at all); that of
an expression is compiled once. The motion ``z_dot = {z, H}_D`` at a point
(:meth:`DiracBracket.field_at`) is the whole vector
``J grad H - J A^T C^{-1} (A J grad H + d_t Phi)`` from one solve.
"""

from __future__ import annotations

import warnings
from collections import OrderedDict
from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np
import sympy

from dirac.analysis.core.linear_solve import weak_solve
from dirac.analysis.core.numeric import Numerics
from dirac.analysis.core.phase_space import PhaseSpace
from dirac.codegen import scalar_function
from dirac.errors import InputError

if TYPE_CHECKING:  # scipy.sparse is imported when a numeric bracket is first taken
    from scipy.sparse import csc_matrix, csr_matrix

__all__ = ["DiracBracket"]

#: second-class sets larger than this factor C by sparse LU at a point (dense LU up to this size)
SPARSE_C = 32
#: factorisations of C kept (the most recent points)
POINTS_KEPT = 8


class _PointSolve:
    """What a numeric point needs once: ``A = d Phi/d z`` (sparse), the factorised ``C = A J A^T``."""

    __slots__ = ("A", "solve")

    def __init__(self, A: csr_matrix, solve) -> None:
        self.A = A
        self.solve = solve


class DiracBracket:
    """Dirac bracket (240) of a phase space with a set of second-class constraints.

    Parameters
    ----------
    phase_space
        The canonical phase space.
    second_class
        The second-class constraints ``Phi_a``.
    C
        Their bracket matrix ``C_ab = {Phi_a, Phi_b}`` (exact).
    numerics
        Evaluator with generic parameter values and ``points`` on the constraint surface,
        for the weak simplifications of exact brackets.
    points
        Points of the full constraint surface.
    defaults
        Parameter values used by numeric brackets unless the point gives them.
    """

    def __init__(
        self,
        phase_space: PhaseSpace,
        second_class: list[sympy.Expr],
        C: sympy.Matrix,
        numerics: Numerics,
        points: list[np.ndarray],
        defaults: Mapping[sympy.Symbol, float | None],
    ) -> None:
        self.space = phase_space
        self.constraints = list(second_class)
        self.C = C
        self.numerics = numerics
        self.points = points
        self.defaults = dict(defaults)
        self._compiled: dict = {}
        self._c_values: np.ndarray | None = None
        self._points: OrderedDict[tuple[float, ...], _PointSolve] = OrderedDict()
        self._gradients: dict[object, tuple] = {}
        self._index: dict[str, int] = {s.name: k for k, s in enumerate(phase_space.variables)}
        #: phase-space variable -> its position in a numeric vector
        self.positions: dict[sympy.Symbol, int] = {s: k for k, s in enumerate(phase_space.variables)}
        self._names = ([s.name for s in phase_space.variables], [t.name for t in ([numerics.time] if numerics.time is not None else [])],
                       [p.name for p in phase_space.parameters])
        self.time = numerics.time  # a time-dependent system's t: an argument, not a variable
        self._args = (*phase_space.variables, *([self.time] if self.time is not None else []), *phase_space.parameters)
        self._arg_set = set(self._args)

    # ------------------------------------------------------------------ exact
    def exact(self, f: sympy.Expr, g: sympy.Expr, time_limit: float | None = None) -> sympy.Expr:
        """``{f, g}_D`` as an exact expression, equal to (240) on the constraint surface.

        Parameters
        ----------
        f, g
            Phase-space functions.
        time_limit
            Seconds allowed for the block solve of ``C x = {Phi, g}`` (``None``: no limit).

        Raises
        ------
        SolveTooLarge
            If the solve needs a block above the size limit or runs over ``time_limit``.
        """
        f, g = sympy.sympify(f), sympy.sympify(g)
        pb = self.space.poisson_bracket
        plain = pb(f, g)
        m = len(self.constraints)
        if m == 0:
            return plain
        alpha = [pb(f, c) for c in self.constraints]
        beta = [pb(c, g) for c in self.constraints]
        ab = self.numerics.weakly_zero(alpha + beta, self.points)
        alpha = [sympy.S.Zero if z else a for a, z in zip(alpha, ab[:m])]
        beta = [sympy.S.Zero if z else b for b, z in zip(beta, ab[m:])]
        if all(a == 0 for a in alpha) or all(b == 0 for b in beta):
            return plain
        c_vals = self._c_at_points()
        b_vals = self.numerics.evaluate(beta, self.points)
        a_vals = self.numerics.evaluate(alpha, self.points)
        x_vals = np.array([np.linalg.solve(c, b) for c, b in zip(c_vals, b_vals)])
        contribution = np.einsum("ki,ki->k", a_vals, x_vals)
        if np.all(np.abs(contribution) <= 1e-9 * (1 + np.abs(a_vals).sum(1) * np.abs(x_vals).max(1))):
            return plain  # the correction vanishes weakly, e.g. (246) with (239)
        x = weak_solve(self.C, sympy.Matrix(beta), list(c_vals), [b.reshape(-1, 1) for b in b_vals], variables=self.space.variables, time_limit=time_limit)
        correction = sum((alpha[a] * x[a, 0] for a in range(m) if alpha[a] != 0 and x[a, 0] != 0), sympy.S.Zero)
        result = plain - correction
        if len(str(result)) < 3000 and sympy.count_ops(result) < 600:
            result = sympy.cancel(result)
        return result

    def explicit_time_term(
        self, f: sympy.Expr, at: Mapping[str, float] | None = None, time_limit: float | None = None
    ) -> sympy.Expr | float:
        """``-{f, Phi_a} (C^{-1})^{ab} d_t Phi_b``: the part of ``df/dt`` from second-class constraints
        that depend explicitly on the time ``t`` (Gitman–Tyutin; Dirac's "Lectures").

        With ``E`` conjugate to ``t`` in the phase space extended by ``(t, E)``, the
        motion is generated by ``H + E`` and ``f_dot = {f, H}_D + {f, E}_D``; since
        ``{f, E} = 0`` and ``{Phi_b, E} = d_t Phi_b``, the second term is this one. Zero when
        no constraint depends on ``t``. Exact (weakly, as :meth:`exact`) or, with ``at``,
        its value at a numeric point.
        """
        f = self._sympify(f)
        t = self.time
        m = len(self.constraints)
        if t is None or m == 0 or not any(t in c.free_symbols for c in self.constraints):
            return 0.0 if at is not None else sympy.S.Zero
        pb = self.space.poisson_bracket
        alpha = [pb(f, c) for c in self.constraints]
        beta = [sympy.diff(c, t) for c in self.constraints]
        if at is not None:
            fn, needed = self._compiled_once(("time", f), lambda: [*alpha, *beta, *self.C])
            values = np.asarray(fn(*self._arguments(at, needed)), dtype=float)
            a_val, b_val, c_val = values[:m], values[m : 2 * m], values[2 * m :].reshape(m, m)
            try:
                return float(-a_val @ np.linalg.solve(c_val, b_val))
            except np.linalg.LinAlgError:
                raise InputError(
                    "the second-class bracket matrix C is singular at the given point: the time derivative "
                    "is not defined there (use a point on the constraint surface, e.g. from surface_point())"
                ) from None
        ab = self.numerics.weakly_zero(alpha + beta, self.points)
        alpha = [sympy.S.Zero if z else a for a, z in zip(alpha, ab[:m])]
        beta = [sympy.S.Zero if z else b for b, z in zip(beta, ab[m:])]
        if all(a == 0 for a in alpha) or all(b == 0 for b in beta):
            return sympy.S.Zero
        c_vals = self._c_at_points()
        b_vals = self.numerics.evaluate(beta, self.points)
        x = weak_solve(self.C, sympy.Matrix(beta), list(c_vals), [b.reshape(-1, 1) for b in b_vals], variables=self.space.variables, time_limit=time_limit)
        term = -sum((alpha[a] * x[a, 0] for a in range(m) if alpha[a] != 0 and x[a, 0] != 0), sympy.S.Zero)
        if len(str(term)) < 3000 and sympy.count_ops(term) < 600:
            term = sympy.cancel(term)
        return term

    def _c_at_points(self) -> np.ndarray:
        if self._c_values is None:
            m = len(self.constraints)
            self._c_values = self.numerics.evaluate(list(self.C), self.points).reshape(len(self.points), m, m)
        return self._c_values

    # ------------------------------------------------------------------ numeric
    def at(self, f: sympy.Expr, g: sympy.Expr, point: Mapping[str, float]) -> float:
        """``{f, g}_D`` at a numeric phase-space point (no symbolic inverse of ``C``).

        ``C`` is evaluated and factorised once per point (the last :data:`POINTS_KEPT`
        points are kept), so further brackets at the same point cost a solve each.

        Parameters
        ----------
        f, g
            Phase-space functions (sympy expressions, or names of variables).
        point
            Name -> value for the phase-space variables the bracket needs (and the time
            ``t`` when the constraints depend on it); parameter values may be given too
            (else their defaults are used).
        """
        f, g = self._sympify(f), self._sympify(g)
        grad_f, f_needed = self._gradient_of(f)
        grad_g, g_needed = self._gradient_of(g)
        foreign = sorted(s.name for s in (f_needed | g_needed) - self._arg_set)
        if foreign:
            raise InputError(f"{', '.join(foreign)} are neither phase-space variables nor parameters: a bracket "
                             "at a point needs functions of the variables (and parameters) only")
        m = len(self.constraints)
        c_needed = self._constraint_gradient()[2] if m else set()
        args = self._arguments(point, f_needed | g_needed | c_needed)
        gf, gg = grad_f(args), grad_g(args)
        j_gg = self._J(gg)
        plain = float(gf @ j_gg)
        if m == 0:
            return plain
        solved = self._point_solve(args)
        beta = solved.A @ j_gg  # {Phi_b, g}
        if not np.any(beta):
            return plain
        alpha = -(solved.A @ self._J(gf))  # {f, Phi_a}
        return float(plain - alpha @ solved.solve(beta))

    def field_at(self, H: sympy.Expr, point: Mapping[str, float]) -> tuple[np.ndarray, list[float]] | None:
        """The motion ``z_dot = {z, H}_D - {z, Phi_a} (C^{-1})^{ab} d_t Phi_b`` of every phase-space
        variable at ``point`` (the vector ``J grad H - J A^T C^{-1} (A J grad H + d_t Phi)``), and
        the argument list of the point; None when ``H`` has symbols that are not arguments (free
        multipliers left symbolic)."""
        grad_H, h_needed = self._gradient_of(sympy.sympify(H))
        if not h_needed <= self._arg_set:
            return None
        m = len(self.constraints)
        c_needed = self._constraint_gradient()[2] if m else set()
        t_fn, t_needed = self._time_derivatives()
        args = self._arguments(point, h_needed | c_needed | t_needed)
        j_gh = self._J(grad_H(args))
        if m == 0:
            return j_gh, args
        solved = self._point_solve(args)
        rhs = solved.A @ j_gh
        if t_fn is not None:
            rhs = rhs + np.asarray(t_fn(*args), dtype=float)
        if not np.any(rhs):
            return j_gh, args
        return j_gh - self._J(solved.A.T @ solved.solve(rhs)), args

    def gradient_at(self, f: sympy.Expr, args: list[float]) -> np.ndarray:
        """``grad f`` (over the phase-space variables) at the arguments ``args`` of a point."""
        return self._gradient_of(self._sympify(f))[0](args)

    # ------------------------------------------------------------------ numeric pieces
    def _J(self, v: np.ndarray) -> np.ndarray:
        """``J v`` with ``J = [[0, 1], [-1, 0]]`` over (coordinates, momenta)."""
        n = v.shape[0] // 2
        return np.concatenate([v[n:], -v[:n]])

    def _gradient_of(self, f: sympy.Expr) -> tuple:
        """``(args -> grad f as a dense vector, free symbols)``: a unit vector for a variable,
        else the non-zero partial derivatives compiled once."""
        entry = self._gradients.get(f)
        if entry is not None:
            return entry
        size = len(self.space.variables)
        if isinstance(f, sympy.Symbol) and f.name in self._index and self.space.symbols.get(f.name) == f:
            unit = np.zeros(size)
            unit[self._index[f.name]] = 1.0
            entry = (lambda args, _u=unit: _u, {f})
        else:
            _, cols, derivatives = self.space.gradient_entries([f])
            needed = set(f.free_symbols)
            if not cols:
                zero = np.zeros(size)
                entry = (lambda args, _z=zero: _z, needed)
            elif not needed <= self._arg_set:  # symbols that are no arguments (field_at declines it)
                entry = (None, needed)
            else:
                fn = scalar_function(self._args, derivatives)
                columns = np.array(cols, dtype=int)

                def gradient(args: list[float], _fn=fn, _cols=columns) -> np.ndarray:
                    out = np.zeros(size)
                    np.add.at(out, _cols, np.asarray(_fn(*args), dtype=float))
                    return out

                entry = (gradient, needed)
        self._gradients[f] = entry
        return entry

    def _constraint_gradient(self) -> tuple:
        """``(compiled non-zero entries of A = d Phi/d z, pattern, free symbols)``, built once;
        the pattern (:class:`_Pattern`) assembles ``A`` and ``C = A J A^T`` from the entries."""
        entry = self._gradients.get("constraints")
        if entry is None:
            rows, cols, derivatives = self.space.gradient_entries(self.constraints)
            needed = set().union(*[d.free_symbols for d in derivatives]) if derivatives else set()
            fn = scalar_function(self._args, derivatives) if derivatives else (lambda *a: [])
            entry = (fn, _Pattern(rows, cols, len(self.constraints), len(self.space.variables)), needed)
            self._gradients["constraints"] = entry
        return entry

    def _time_derivatives(self) -> tuple:
        """``(compiled d_t Phi or None, free symbols)``: None unless a constraint depends on the time."""
        entry = self._gradients.get("time")
        if entry is None:
            t = self.time
            if t is None or not any(t in c.free_symbols for c in self.constraints):
                entry = (None, set())
            else:
                derivatives = [sympy.diff(c, t) for c in self.constraints]
                entry = (scalar_function(self._args, derivatives),
                         set().union(*[d.free_symbols for d in derivatives]))
            self._gradients["time"] = entry
        return entry

    def _point_solve(self, args: list[float]) -> _PointSolve:
        """``A`` and the factorised ``C = A J A^T`` at the point ``args`` (cached per point)."""
        key = tuple(args)
        cached = self._points.get(key)
        if cached is not None:
            self._points.move_to_end(key)
            return cached
        singular = InputError(
            "the second-class bracket matrix C is singular at the given point: the Dirac bracket "
            "is not defined there (use a point on the constraint surface, e.g. from surface_point())"
        )
        from scipy.linalg import LinAlgWarning, lu_factor, lu_solve  # imported when used (0.1-0.2 s)
        from scipy.sparse.linalg import MatrixRankWarning, splu

        fn, pattern, _ = self._constraint_gradient()
        m = len(self.constraints)
        values = np.asarray(fn(*args), dtype=float)
        if not np.all(np.isfinite(values)):
            raise singular
        A, C = pattern.assemble(values)
        if m > SPARSE_C:
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("error", MatrixRankWarning)
                    lu = splu(C)
            except (RuntimeError, MatrixRankWarning):
                raise singular from None

            def solve(b: np.ndarray, _lu=lu) -> np.ndarray:
                x = _lu.solve(b)
                if not np.all(np.isfinite(x)):
                    raise singular
                return x
        else:
            dense = C.toarray()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", LinAlgWarning)
                factors = lu_factor(dense, check_finite=False)
            if not np.all(np.diag(factors[0])) or not np.all(np.isfinite(factors[0])):
                raise singular

            def solve(b: np.ndarray, _lu=factors) -> np.ndarray:
                x = lu_solve(_lu, b, check_finite=False)
                if not np.all(np.isfinite(x)):
                    raise singular
                return x
        solved = _PointSolve(A, solve)
        self._points[key] = solved
        if len(self._points) > POINTS_KEPT:
            self._points.popitem(last=False)
        return solved

    def _compiled_once(self, key: object, build) -> tuple:
        """``(compiled function, free symbols)`` of the expressions ``build()``, compiled on first use."""
        entry = self._compiled.get(key)
        if entry is None:
            exprs = build()
            needed = set().union(*[e.free_symbols for e in exprs]) if exprs else set()
            entry = (scalar_function(self._args, exprs) if exprs else (lambda *a: []), needed)
            self._compiled[key] = entry
        return entry

    def _sympify(self, f: object) -> sympy.Expr:
        if isinstance(f, str):
            symbols = self.space.symbols
            if f in symbols:
                return symbols[f]
            raise InputError(f"{f!r} is not a phase-space variable; known: {', '.join(symbols)}")
        return sympy.sympify(f)

    def _arguments(self, point: Mapping[str, float], needed: set) -> list[float]:
        variables, times, parameters = self._names
        try:  # the usual case: every variable (and the time) given, parameters at their defaults or given
            args = [float(point[name]) for name in variables] + [float(point[name]) for name in times]
        except KeyError:
            args = None
        if args is not None and len(point) == len(variables) + len(times):
            for p in self.space.parameters:
                value = self.defaults.get(p)
                if value is None:
                    if p in needed:
                        raise InputError(f"parameter {p.name!r} has no default value: give it in the point or fix it")
                    value = 0.0
                args.append(float(value))
            return args
        return self._arguments_checked(point, needed)

    def _arguments_checked(self, point: Mapping[str, float], needed: set) -> list[float]:
        symbols = self.space.symbols
        params = {p.name: p for p in self.space.parameters}
        timed = [self.time] if self.time is not None else []
        unknown = sorted(set(point) - set(symbols) - set(params) - {t.name for t in timed})
        if unknown:
            raise InputError(f"point has unknown name(s) {', '.join(unknown)}; the phase-space variables are {', '.join(symbols)}")
        args = []
        for s in self.space.variables:
            if s.name in point:
                args.append(float(point[s.name]))
            elif s in needed:
                raise InputError(f"point lacks a value for {s.name!r}, which the bracket needs")
            else:
                args.append(0.0)
        for t in timed:
            if t.name in point:
                args.append(float(point[t.name]))
            elif t in needed:
                raise InputError(f"point lacks a value for the time {t.name!r}, which the bracket needs")
            else:
                args.append(0.0)
        for p in self.space.parameters:
            if p.name in point:
                args.append(float(point[p.name]))
            elif self.defaults.get(p) is not None:
                args.append(float(self.defaults[p]))
            elif p in needed:
                raise InputError(f"parameter {p.name!r} has no default value: give it in the point or fix it")
            else:
                args.append(0.0)
        return args


class _Pattern:
    """The sparsity of ``A = d Phi/d z`` and of ``C = A J A^T``, found once, so that a point
    assembles both from the values of ``A``'s entries with array operations only:

        C_ab = sum_{k in row a, l in row b} s_k A_k A_l   over the pairs whose columns ``J`` joins
        (``s_k = +1`` for a coordinate column, ``-1`` for a momentum column).
    """

    def __init__(self, rows: list[int], cols: list[int], m: int, size: int) -> None:
        n = size // 2
        r, c = np.asarray(rows, dtype=np.int64), np.asarray(cols, dtype=np.int64)
        self.shape_A = (m, size)
        order = np.lexsort((c, r))  # A in CSR order
        self.order_A = order
        self.indices_A = c[order]
        self.indptr_A = np.concatenate([[0], np.cumsum(np.bincount(r, minlength=m))])
        by_column: dict[int, list[int]] = {}
        for l, col in enumerate(c.tolist()):
            by_column.setdefault(col, []).append(l)
        first: list[int] = []
        second: list[int] = []
        sign: list[float] = []
        for k, col in enumerate(c.tolist()):
            partner, s = (col + n, 1.0) if col < n else (col - n, -1.0)  # (A J)_{a, partner} = s A_{a, col}
            for l in by_column.get(partner, ()):
                first.append(k)
                second.append(l)
                sign.append(s)
        self.first = np.asarray(first, dtype=np.int64)
        self.second = np.asarray(second, dtype=np.int64)
        self.sign = np.asarray(sign)
        a, b = r[self.first], r[self.second]
        keys = b * m + a  # CSC order: by column b, then row a
        unique, target = np.unique(keys, return_inverse=True)
        self.target = target.ravel()
        self.count = len(unique)
        self.indices_C = unique % m
        self.indptr_C = np.concatenate([[0], np.cumsum(np.bincount(unique // m, minlength=m))])
        self.m = m

    def assemble(self, values: np.ndarray) -> tuple[csr_matrix, csc_matrix]:
        """``A`` (CSR) and ``C = A J A^T`` (CSC) from the values of ``A``'s entries."""
        from scipy.sparse import csc_matrix, csr_matrix  # imported when used: exact analyses never need it

        A = csr_matrix((values[self.order_A], self.indices_A, self.indptr_A), shape=self.shape_A)
        data = np.bincount(self.target, weights=self.sign * values[self.first] * values[self.second],
                           minlength=self.count)
        C = csc_matrix((data, self.indices_C, self.indptr_C), shape=(self.m, self.m))
        return A, C
