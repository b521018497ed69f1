"""The Dirac bracket over the second-class constraints, exact or at a numeric point.

    {A, B}_D = {A, B} - {A, Phi_a} (C^{-1})^{ab} {Phi_b, B},    C_ab = {Phi_a, Phi_b}   (240)

Exact brackets never invert ``C`` densely: the terms ``{A, Phi_a}``, ``{Phi_b, B}`` and
the entries of ``C`` that vanish weakly are dropped, and ``C x = {Phi, B}`` is solved by
the block triangular method of :mod:`dirac.analysis.core.linear_solve` — the automatic form of
the paper's block inversion (245)-(246). The result is equal to the true bracket on the
constraint surface (weakly). Numeric brackets (``at=point``) evaluate compiled
``{A, Phi}``, ``{Phi, B}`` and ``C`` at the point and solve the linear system with numpy
(for more than ``SPARSE_C`` second-class constraints: ``C`` over its non-zero entries,
solved by sparse LU).
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping

import numpy as np
import sympy
from scipy.sparse import csc_matrix
from scipy.sparse.linalg import MatrixRankWarning, splu

from dirac.analysis.core.linear_solve import weak_solve
from dirac.analysis.core.numeric import Numerics
from dirac.analysis.core.phase_space import PhaseSpace
from dirac.codegen import scalar_function
from dirac.errors import InputError

__all__ = ["DiracBracket"]

#: second-class sets larger than this evaluate C over its non-zero entries and solve by sparse LU at a point
SPARSE_C = 32


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
        self._c_pattern: tuple[list[tuple[int, int]], np.ndarray, np.ndarray] | None = None
        self.time = numerics.time  # a time-dependent system's t: an argument, not a variable
        self._args = (*phase_space.variables, *([self.time] if self.time is not None else []), *phase_space.parameters)

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
        pb = self.space.poisson_bracket
        plain_fn, plain_needed = self._compiled_once(("plain", f, g), lambda: [pb(f, g)])
        # {f, Phi_a} is compiled once per function and reused for every partner:
        # {Phi_a, g} = -{g, Phi_a}
        f_fn, f_needed = self._compiled_once(("row", f), lambda: [pb(f, c) for c in self.constraints])
        g_fn, g_needed = self._compiled_once(("row", g), lambda: [pb(g, c) for c in self.constraints])
        m = len(self.constraints)
        sparse = m > SPARSE_C
        if sparse:  # only the non-zero entries of C are compiled, and C x = beta is solved by sparse LU
            if self._c_pattern is None:
                entries = sorted(self.C.todok())
                self._c_pattern = (entries, np.array([i for i, _ in entries], dtype=int), np.array([j for _, j in entries], dtype=int))
            entries, rows, cols = self._c_pattern
            c_fn, c_needed = self._compiled_once("C-sparse", lambda: [self.C[i, j] for i, j in entries])
        else:
            c_fn, c_needed = self._compiled_once("C", lambda: list(self.C))
        args = self._arguments(point, plain_needed | f_needed | g_needed | c_needed)
        plain = float(np.asarray(plain_fn(*args), dtype=float)[0])
        if m == 0:
            return plain
        alpha = np.asarray(f_fn(*args), dtype=float)
        beta = -np.asarray(g_fn(*args), dtype=float)
        singular = InputError(
            "the second-class bracket matrix C is singular at the given point: the Dirac bracket "
            "is not defined there (use a point on the constraint surface, e.g. from surface_point())"
        )
        if sparse:
            values = np.asarray(c_fn(*args), dtype=float)
            C_sparse = csc_matrix((values, (rows, cols)), shape=(m, m))
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("error", MatrixRankWarning)
                    x = splu(C_sparse).solve(beta)
            except (RuntimeError, MatrixRankWarning):
                raise singular from None
            if not np.all(np.isfinite(x)):
                raise singular
            return float(plain - alpha @ x)
        C = np.asarray(c_fn(*args), dtype=float).reshape(m, m)
        try:
            x = np.linalg.solve(C, beta)
        except np.linalg.LinAlgError:
            raise singular from None
        return float(plain - alpha @ x)

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
