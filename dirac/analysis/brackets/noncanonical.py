"""Brackets in chosen (noncanonical) phase-space variables.

A change of phase-space variables ``z = (q, p) -> w(z)`` that is invertible but not
canonical, such as the paper's change (235) ``(R_ij, p_ij) -> (R_ij, M_i, P_ij)``, gives
new variables whose brackets are no longer ``0`` and ``±1``. This module

* computes the canonical Poisson brackets ``{w_a, w_b}`` of the new variables from the
  canonical ones ``{q_i, p_j} = delta_ij`` (the paper's (236)–(238) for (235)),
* re-expresses them in the new variables through the inverse change,
* evaluates them, and their Dirac brackets (240) from a
  :class:`~dirac.analysis.constraint_analysis.ConstraintAnalysis`, at numeric points.

Example
-------
>>> from dirac.analysis.brackets.noncanonical import rigid_body_variables
>>> w = rigid_body_variables(inverse="transpose")
>>> w.bracket("M_1", "R_13")                    # (236) with R~ = R^T: -eps_13m R_1m
R_12
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from functools import cached_property
from typing import Any

import numpy as np
import sympy

from dirac.codegen import array_function
from dirac.errors import AnalysisError, InputError

__all__ = [
    "canonical_bracket",
    "canonical_pairs",
    "NoncanonicalVariables",
    "rigid_body_variables",
    "body_angular_momentum",
    "rotation_matrix_symbols",
    "SYMMETRIC_PAIRS",
]

#: index pairs (i, j), i <= j, of the six independent entries of a symmetric 3x3 matrix
SYMMETRIC_PAIRS: tuple[tuple[int, int], ...] = ((1, 1), (1, 2), (1, 3), (2, 2), (2, 3), (3, 3))


def canonical_bracket(
    f: sympy.Expr, g: sympy.Expr, pairs: Sequence[tuple[sympy.Symbol, sympy.Symbol]]
) -> sympy.Expr:
    """Canonical Poisson bracket ``{f, g} = sum_i (df/dq_i dg/dp_i - df/dp_i dg/dq_i)``.

    This is the bracket with ``{q_i, p_j} = delta_ij`` that the paper uses throughout
    Sects. X–XI (e.g. ``{R_ij, p_ij} = 1``, below (207)).

    Parameters
    ----------
    f, g
        Phase-space functions.
    pairs
        The canonical pairs ``(q_i, p_i)``.
    """
    f, g = sympy.sympify(f), sympy.sympify(g)
    free_f, free_g = f.free_symbols, g.free_symbols
    total = sympy.Integer(0)
    for q, p in pairs:
        if q in free_f and p in free_g:
            total += sympy.diff(f, q) * sympy.diff(g, p)
        if p in free_f and q in free_g:
            total -= sympy.diff(f, p) * sympy.diff(g, q)
    return total


def canonical_pairs(symbols: Mapping[str, sympy.Symbol], coordinates: Sequence[str]) -> list[tuple[sympy.Symbol, sympy.Symbol]]:
    """The pairs ``(q, p_q)`` of the named coordinates, taking symbols from ``symbols``.

    Momentum names follow docs/conventions.md: the momentum of ``x`` is ``p_x``.

    Raises
    ------
    InputError
        If a coordinate or its momentum is not in ``symbols``.
    """
    result = []
    for name in coordinates:
        momentum = f"p_{name}"
        if name not in symbols or momentum not in symbols:
            raise InputError(f"phase-space variable {name!r} or its momentum {momentum!r} is unknown")
        result.append((symbols[name], symbols[momentum]))
    return result


def rotation_matrix_symbols(symbols: Mapping[str, sympy.Symbol] | None = None) -> tuple[sympy.Matrix, sympy.Matrix]:
    """The matrices ``R`` (``R_11 … R_33``) and ``p`` (``p_R_11 … p_R_33``).

    Symbols are taken from ``symbols`` (e.g. ``analysis.symbols``) when given, so that
    expressions built here are the engine's; otherwise real symbols are created.
    """
    def get(name: str) -> sympy.Symbol:
        if symbols is None:
            return sympy.Symbol(name, real=True)
        if name not in symbols:
            raise InputError(f"phase-space variable {name!r} is unknown: the system must have coordinates R_11 … R_33")
        return symbols[name]

    R = sympy.Matrix(3, 3, lambda i, j: get(f"R_{i + 1}{j + 1}"))
    p = sympy.Matrix(3, 3, lambda i, j: get(f"p_R_{i + 1}{j + 1}"))
    return R, p


def body_angular_momentum(R: sympy.Matrix, p: sympy.Matrix, inverse: str = "transpose") -> list[sympy.Expr]:
    """Body angular momentum on phase space, ``M_k = -eps_kij (R~ p)_ij`` (233).

    Parameters
    ----------
    R, p
        The matrices of coordinates and momenta.
    inverse
        ``"transpose"``: ``R~ = R^T`` (equal to ``R^{-1}`` on the surface ``R^T R = 1``; a
        polynomial, the form used to compare brackets on the constraint surface);
        ``"inverse"``: ``R~ = R^{-1}`` exactly as in (229)–(233), which is what makes the
        brackets (236)–(238) hold for an arbitrary invertible ``R``.
    """
    N, D = _reduced_momentum(R, p, inverse)
    return [
        sympy.expand(-sum(sympy.LeviCivita(k, i, j) * N[i, j] for i in range(3) for j in range(3))) / D
        for k in range(3)
    ]


def _reduced_momentum(R: sympy.Matrix, p: sympy.Matrix, inverse: str) -> tuple[sympy.Matrix, sympy.Expr]:
    """``R~ p = N / D`` with polynomial ``N`` and ``D`` (``D = 1`` for ``R^T``, ``det R``
    for ``R^{-1} = adj(R)/det(R)``): one division per function keeps derivatives small."""
    if inverse == "transpose":
        return (R.T * p).applyfunc(sympy.expand), sympy.Integer(1)
    if inverse == "inverse":
        return (R.adjugate() * p).applyfunc(sympy.expand), sympy.expand(R.det())
    raise InputError(f"inverse = {inverse!r}: use 'transpose' or 'inverse'")


class NoncanonicalVariables:
    """A set of phase-space functions ``w_a(q, p)`` used as new variables.

    Parameters
    ----------
    functions
        New variable name -> expression in the canonical variables. A canonical
        coordinate kept as a new variable is given as its own symbol (e.g.
        ``{"R_11": R_11, …}``), and then keeps its name and symbol.
    pairs
        The canonical pairs ``(q_i, p_i)`` of the phase space.
    inverse
        Optional: each canonical momentum (and any other canonical variable that is not
        kept) as an expression in the new variables (and the kept ones). Without it the
        inverse is found by solving ``w = w(q, p)`` for the momenta, which works when the
        new variables are linear in the momenta.

    Notes
    -----
    The brackets of the new variables are the canonical brackets of the functions,
    ``{w_a, w_b} = sum_i (dw_a/dq_i dw_b/dp_i - dw_a/dp_i dw_b/dq_i)``; the paper does
    this for (235) in (236)–(238). They need not close on the new variables in general;
    :meth:`bracket` with ``express=True`` substitutes the inverse change and reports
    through :class:`~dirac.errors.AnalysisError` when the result still contains
    canonical momenta.
    """

    def __init__(
        self,
        functions: Mapping[str, sympy.Expr],
        pairs: Sequence[tuple[sympy.Symbol, sympy.Symbol]],
        inverse: Mapping[sympy.Symbol, sympy.Expr] | None = None,
    ) -> None:
        if not functions:
            raise InputError("no new variables given: pass a mapping name -> phase-space expression")
        self.pairs = [(q, p) for q, p in pairs]
        canonical = {s for pair in self.pairs for s in pair}
        by_name = {s.name: s for s in canonical}
        self.names: tuple[str, ...] = tuple(functions)
        self.functions: dict[str, sympy.Expr] = {}
        self.symbols: dict[str, sympy.Symbol] = {}
        for name, expression in functions.items():
            expression = sympy.sympify(expression)
            if not expression.free_symbols & canonical:
                raise InputError(f"new variable {name!r} = {expression} does not depend on the phase-space variables")
            self.functions[name] = expression
            if name in by_name:
                if expression != by_name[name]:
                    raise InputError(
                        f"new variable {name!r} has the name of a canonical variable but is {expression}: rename it"
                    )
                self.symbols[name] = by_name[name]
            else:
                self.symbols[name] = sympy.Symbol(name, real=True)
        self._inverse = dict(inverse) if inverse is not None else None

    # ------------------------------------------------------------------ symbolic
    @cached_property
    def inverse(self) -> dict[sympy.Symbol, sympy.Expr]:
        """Canonical variables not kept as new variables -> expressions in the new ones."""
        if self._inverse is not None:
            return self._inverse
        kept = {self.symbols[n] for n in self.names if self.functions[n] == self.symbols[n]}
        unknowns = [s for pair in self.pairs for s in pair if s not in kept]
        equations = [
            self.symbols[n] - self.functions[n] for n in self.names if self.functions[n] != self.symbols[n]
        ]
        solutions = sympy.solve(equations, unknowns, dict=True)
        if len(solutions) != 1 or set(solutions[0]) != set(unknowns):
            raise AnalysisError(
                "the change of variables could not be inverted in closed form: pass inverse= "
                "(each canonical variable that is not kept, in terms of the new variables)"
            )
        return solutions[0]

    def bracket(self, a: str, b: str, express: bool = False) -> sympy.Expr:
        """The canonical bracket ``{w_a, w_b}`` of two new variables.

        Parameters
        ----------
        a, b
            Names of new variables.
        express
            ``False``: the bracket in the canonical variables. ``True``: rewritten in the
            new variables through :attr:`inverse` and simplified.
        """
        result = canonical_bracket(self._function(a), self._function(b), self.pairs)
        if not express:
            return result
        return self.express(result)

    def express(self, expression: sympy.Expr) -> sympy.Expr:
        """Rewrite a phase-space expression in the new variables (substitute :attr:`inverse`).

        Raises
        ------
        AnalysisError
            If the result still depends on canonical variables that were not kept.
        """
        result = sympy.sympify(expression).xreplace(self.inverse)
        result = sympy.factor_terms(sympy.cancel(sympy.together(result)))
        leftover = result.free_symbols & set(self.inverse)
        if leftover:
            names = ", ".join(sorted(s.name for s in leftover))
            raise AnalysisError(f"the bracket does not close on the new variables (still contains {names})")
        return result

    def bracket_matrix(self, express: bool = False) -> sympy.Matrix:
        """The antisymmetric matrix ``J_ab = {w_a, w_b}`` of all new variables."""
        n = len(self.names)
        J = sympy.zeros(n, n)
        for i in range(n):
            for j in range(i + 1, n):
                J[i, j] = self.bracket(self.names[i], self.names[j], express=express)
                J[j, i] = -J[i, j]
        return J

    def _function(self, name: str) -> sympy.Expr:
        if name not in self.functions:
            known = ", ".join(self.names)
            raise InputError(f"{name!r} is not one of the new variables ({known})")
        return self.functions[name]

    # ------------------------------------------------------------------ numeric
    @cached_property
    def _canonical_symbols(self) -> list[sympy.Symbol]:
        return [s for pair in self.pairs for s in pair]

    @cached_property
    def _values_function(self) -> Any:
        return array_function(self._canonical_symbols, [self.functions[n] for n in self.names], cse=False)

    @cached_property
    def _gradient_function(self) -> Any:
        jacobian = sympy.Matrix([self.functions[n] for n in self.names]).jacobian(self._canonical_symbols)
        return array_function(self._canonical_symbols, jacobian)

    def _arguments(self, point: Mapping[str, float]) -> list[float]:
        missing = [s.name for s in self._canonical_symbols if s.name not in point]
        if missing:
            raise InputError(f"the point lacks values for {', '.join(missing[:5])}")
        return [float(point[s.name]) for s in self._canonical_symbols]

    def values(self, point: Mapping[str, float]) -> dict[str, float]:
        """The new variables at a phase-space point ``{name: value}``."""
        return dict(zip(self.names, map(float, self._values_function(*self._arguments(point)))))

    def numeric_bracket_matrix(self, point: Mapping[str, float]) -> np.ndarray:
        """``{w_a, w_b}`` (canonical Poisson bracket) at a phase-space point, as an array.

        Computed as ``W Pi W^T`` with ``W = dw/dz`` and the canonical tensor ``Pi``.
        """
        W = np.asarray(self._gradient_function(*self._arguments(point)), dtype=float)
        dq, dp = W[:, 0::2], W[:, 1::2]  # canonical symbols are ordered q_1, p_1, q_2, p_2, ...
        return dq @ dp.T - dp @ dq.T

    def dirac_bracket_matrix(self, analysis: Any, point: Mapping[str, float]) -> np.ndarray:
        """``{w_a, w_b}_D`` (240) at a point, from the engine's Dirac bracket.

        Parameters
        ----------
        analysis
            A :class:`~dirac.analysis.constraint_analysis.ConstraintAnalysis` whose phase space
            contains the canonical variables of this change.
        point
            Phase-space point ``{name: value}`` (on its constraint surface).
        """
        n = len(self.names)
        J = np.zeros((n, n))
        for i in range(n):
            for j in range(i + 1, n):
                value = analysis.dirac_bracket(
                    self.functions[self.names[i]], self.functions[self.names[j]], at=dict(point)
                )
                J[i, j], J[j, i] = float(value), -float(value)
        return J


def rigid_body_variables(
    symbols: Mapping[str, sympy.Symbol] | None = None, inverse: str = "inverse"
) -> NoncanonicalVariables:
    """The paper's change of variables (235): ``(R_ij, p_ij) -> (R_ij, M_i, P_ij)``.

    ``M_k = -eps_kij (R~ p)_ij`` (233) and ``P_ij = [R~ p + (R~ p)^T]_ij`` (230), ``i <= j``,
    with ``R~ = R^{-1}`` (``inverse="inverse"``, the paper's definition, valid for any
    invertible ``R``) or ``R~ = R^T`` (``inverse="transpose"``). The inverse change is
    ``p = R [P/2 - 1/2 eps·M]``, i.e. ``(R~ p)_ij = P_ij/2 - 1/2 eps_ijk M_k``; with
    ``R~ = R^T`` this inverse is used as if ``R^T R = 1`` (exact on the surface only).

    New variable names: ``R_11 … R_33``, ``M_1, M_2, M_3``, ``P_11, P_12, P_13, P_22,
    P_23, P_33``.

    Parameters
    ----------
    symbols
        Name -> symbol of the phase space (``analysis.symbols``); if omitted, real
        symbols ``R_ij``, ``p_R_ij`` are created.
    inverse
        ``"inverse"`` or ``"transpose"`` (see above).
    """
    R, p = rotation_matrix_symbols(symbols)
    N, D = _reduced_momentum(R, p, inverse)
    M = body_angular_momentum(R, p, inverse)
    functions: dict[str, sympy.Expr] = {R[i, j].name: R[i, j] for i in range(3) for j in range(3)}
    functions.update({f"M_{k + 1}": M[k] for k in range(3)})
    for i, j in SYMMETRIC_PAIRS:
        functions[f"P_{i}{j}"] = sympy.expand(N[i - 1, j - 1] + N[j - 1, i - 1]) / D
    new_M = [sympy.Symbol(f"M_{k}", real=True) for k in (1, 2, 3)]
    new_P = sympy.Matrix(
        3, 3, lambda i, j: sympy.Symbol(f"P_{min(i, j) + 1}{max(i, j) + 1}", real=True)
    )
    eps_M = sympy.Matrix(3, 3, lambda i, j: sum(sympy.LeviCivita(i, j, k) * new_M[k] for k in range(3)))
    p_of_new = R * (new_P / 2 - eps_M / 2)
    inverse_map = {p[i, j]: sympy.expand(p_of_new[i, j]) for i in range(3) for j in range(3)}
    pairs = list(zip(R, p))
    return NoncanonicalVariables(functions, pairs, inverse=inverse_map)
