"""Brackets of named variables, evaluated at phase-space points.

A *bracket* here is a rule that gives the antisymmetric matrix ``J_ab = {w_a, w_b}`` of a
list of variables ``w`` at a point of phase space. Three kinds:

* :class:`AnalysisBracket` — the Dirac bracket (240) of an analysed system, of the
  variables taken as phase-space functions (``ConstraintAnalysis.dirac_bracket``);
* :class:`CanonicalBracket` — their canonical Poisson bracket ``{q_i, p_j} = delta_ij``;
* :class:`StructureBracket` — a bracket given directly in the variables by a structure
  matrix ``J(w)`` (the built-in ones are in :mod:`dirac.analysis.brackets.structures`).

:func:`analysis_variables` chooses the variables of an analysed system: ``M`` (233) and
``R`` for the rigid body, the canonical ones otherwise.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Mapping, Sequence
from functools import cached_property
from typing import Any

import numpy as np
import sympy

from dirac.analysis.brackets.noncanonical import (
    NoncanonicalVariables,
    body_angular_momentum,
    rotation_matrix_symbols,
)
from dirac.codegen import array_function
from dirac.errors import AnalysisError, InputError

__all__ = [
    "Bracket",
    "AnalysisBracket",
    "CanonicalBracket",
    "StructureBracket",
    "analysis_variables",
]


def _has_rotation_matrix(symbols: Mapping[str, sympy.Symbol]) -> bool:
    return all(f"R_{i}{j}" in symbols and f"p_R_{i}{j}" in symbols for i in (1, 2, 3) for j in (1, 2, 3))


def _phase_space(analysis: Any) -> tuple[list[sympy.Symbol], list[sympy.Symbol]]:
    """(coordinates, momenta) of an analysis as symbol lists."""
    symbols = analysis.symbols

    def as_symbol(item: Any) -> sympy.Symbol:
        return item if isinstance(item, sympy.Symbol) else symbols[str(item)]

    return [as_symbol(q) for q in analysis.coordinates], [as_symbol(p) for p in analysis.momenta]


def analysis_variables(analysis: Any) -> NoncanonicalVariables:
    """The variables in which brackets of an analysed system are compared.

    For a system with coordinates ``R_11 … R_33`` (the rigid body): ``M_1, M_2, M_3``
    with ``M_k = -eps_kij (R^T p)_ij`` (233), then ``R_11 … R_33``. Otherwise: the
    Lagrangian's coordinates and their momenta (the multipliers are left out).
    """
    coordinates, momenta = _phase_space(analysis)
    pairs = list(zip(coordinates, momenta))
    symbols = analysis.symbols
    if _has_rotation_matrix(symbols):
        R, p = rotation_matrix_symbols(symbols)
        M = body_angular_momentum(R, p, "transpose")
        functions: dict[str, sympy.Expr] = {f"M_{k + 1}": M[k] for k in range(3)}
        functions.update({R[i, j].name: R[i, j] for i in range(3) for j in range(3)})
        return NoncanonicalVariables(functions, pairs, inverse={})
    names = [q.name for q in analysis.lagrangian.coordinates]
    functions = {name: symbols[name] for name in names}
    functions.update({f"p_{name}": symbols[f"p_{name}"] for name in names})
    return NoncanonicalVariables(functions, pairs, inverse={})


class Bracket:
    """A bracket of named variables, evaluated at phase-space points.

    Subclasses provide :meth:`matrix`; :meth:`symbolic` (an entry as a phase-space
    expression) when they can, and :meth:`jacobiator` for the Jacobi check.
    """

    name: str
    description: str
    variables: NoncanonicalVariables
    names: tuple[str, ...]

    def matrix(self, point: Mapping[str, float]) -> np.ndarray:  # pragma: no cover - abstract
        """``J_ab = {w_a, w_b}`` at a phase-space point, rows and columns in :attr:`names`."""
        raise NotImplementedError

    def symbolic(self, a: str, b: str) -> sympy.Expr | None:
        """``{w_a, w_b}`` as a phase-space expression, or ``None`` if not available."""
        return None

    def jacobiator(self, point: Mapping[str, float]) -> np.ndarray:  # pragma: no cover - abstract
        """``{w_a, {w_b, w_c}} + cyclic`` for all ``a < b < c`` at a point (flat array)."""
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.name!r} on {', '.join(self.names)}>"


class _PhaseSpaceTensor:
    """Numeric Poisson tensor ``Pi(x)`` on the full phase space and the variables' gradients.

    ``Pi`` is the canonical tensor, or the Dirac tensor (240)
    ``Pi_D = Pi - Pi G^T C^{-1} G Pi``, ``G = dPhi/dx``, ``C = G Pi G^T`` over
    second-class constraints ``Phi``. Used for the Jacobi check by central differences
    (the Dirac bracket obeys the Jacobi identity strongly, wherever ``C`` is invertible).
    """

    def __init__(
        self,
        variables: NoncanonicalVariables,
        coordinates: Sequence[sympy.Symbol],
        momenta: Sequence[sympy.Symbol],
        constraints: Sequence[sympy.Expr] = (),
        defaults: Mapping[str, float | None] | None = None,
    ) -> None:
        self.x = [*coordinates, *momenta]
        self.defaults = {k: v for k, v in (defaults or {}).items() if v is not None}
        n = len(coordinates)
        self.canonical = np.block([[np.zeros((n, n)), np.eye(n)], [-np.eye(n), np.zeros((n, n))]])
        functions = [variables.functions[name] for name in variables.names]
        extra = set().union(*(sympy.sympify(f).free_symbols for f in [*functions, *constraints])) - set(self.x)
        self.parameters = sorted(extra, key=lambda s: s.name)
        args = [*self.x, *self.parameters]
        self._grad_w = array_function(args, sympy.Matrix(functions).jacobian(self.x))
        self._grad_phi = None
        if constraints:
            self._grad_phi = array_function(args, sympy.Matrix(list(constraints)).jacobian(self.x))

    def vector(self, point: Mapping[str, float]) -> tuple[np.ndarray, list[float]]:
        """Phase-space vector and parameter values of a point (parameters default)."""
        point = {**self.defaults, **point}
        missing = [s.name for s in [*self.x, *self.parameters] if s.name not in point]
        if missing:
            raise InputError(f"the point lacks values for {', '.join(missing[:6])}")
        return np.array([float(point[s.name]) for s in self.x]), [float(point[s.name]) for s in self.parameters]

    def tensor(self, x: np.ndarray, params: list[float]) -> np.ndarray:
        if self._grad_phi is None:
            return self.canonical
        G = np.asarray(self._grad_phi(*x, *params), dtype=float)
        PG = self.canonical @ G.T
        C = G @ PG
        # Pi_D = Pi - Pi G^T C^-1 G Pi, and G Pi = -(Pi G^T)^T since Pi is antisymmetric
        return self.canonical + PG @ np.linalg.solve(C, PG.T)

    def brackets(self, x: np.ndarray, params: list[float]) -> np.ndarray:
        W = np.asarray(self._grad_w(*x, *params), dtype=float)
        return W @ self.tensor(x, params) @ W.T

    def jacobiator(self, point: Mapping[str, float], step: float = 1e-5) -> np.ndarray:
        x, params = self.vector(point)
        W = np.asarray(self._grad_w(*x, *params), dtype=float)
        Pi = self.tensor(x, params)
        m = W.shape[0]
        # dF/dx_l of F_bc = {w_b, w_c} by central differences, shape (m, m, dim)
        dF = np.empty((m, m, x.size))
        for index in range(x.size):
            h = step * max(1.0, abs(x[index]))
            up, down = x.copy(), x.copy()
            up[index] += h
            down[index] -= h
            dF[:, :, index] = (self.brackets(up, params) - self.brackets(down, params)) / (2 * h)
        WPi = W @ Pi  # row a: the Hamiltonian vector field of w_a, contracted later
        # {w_a, F_bc} = (W Pi)_a . dF_bc
        outer = np.einsum("al,bcl->abc", WPi, dF)
        result = []
        for a, b, c in itertools.combinations(range(m), 3):
            result.append(outer[a, b, c] + outer[b, c, a] + outer[c, a, b])
        return np.array(result)


class AnalysisBracket(Bracket):
    """The Dirac bracket (240) of an analysed system, taken of the variables (phase-space functions).

    :meth:`matrix` calls ``analysis.dirac_bracket(w_a, w_b, at=point)`` for every pair;
    :meth:`symbolic` returns ``analysis.dirac_bracket(w_a, w_b)`` (weakly simplified).
    The Jacobi check assembles the Dirac tensor from ``analysis.second_class``.
    """

    def __init__(self, analysis: Any, variables: NoncanonicalVariables | None = None) -> None:
        self.analysis = analysis
        self.variables = variables if variables is not None else analysis_variables(analysis)
        self.names = self.variables.names
        self.name = "dirac"
        self.description = f"Dirac bracket (240) of {analysis.name}, {len(analysis.second_class)} second-class constraints"

    def matrix(self, point: Mapping[str, float]) -> np.ndarray:
        return self.variables.dirac_bracket_matrix(self.analysis, point)

    def symbolic(self, a: str, b: str) -> sympy.Expr:
        return sympy.sympify(
            self.analysis.dirac_bracket(self.variables.functions[a], self.variables.functions[b])
        )

    @cached_property
    def _tensor(self) -> _PhaseSpaceTensor:
        coordinates, momenta = _phase_space(self.analysis)
        if self.analysis.first_class:
            raise AnalysisError(
                f"{self.analysis.name} has first-class constraints: the Dirac bracket over the "
                "second-class ones alone is not checked for the Jacobi identity here"
            )
        defaults = {p.name: v for p, v in self.analysis.lagrangian.parameters.items()}
        return _PhaseSpaceTensor(self.variables, coordinates, momenta, list(self.analysis.second_class), defaults)

    def jacobiator(self, point: Mapping[str, float]) -> np.ndarray:
        return self._tensor.jacobiator(point)


class CanonicalBracket(Bracket):
    """The canonical Poisson bracket ``{q_i, p_j} = delta_ij`` of the variables."""

    def __init__(self, variables: NoncanonicalVariables) -> None:
        self.variables = variables
        self.names = variables.names
        self.name = "canonical"
        self.description = "canonical Poisson bracket {q_i, p_j} = delta_ij"

    def matrix(self, point: Mapping[str, float]) -> np.ndarray:
        return self.variables.numeric_bracket_matrix(point)

    def symbolic(self, a: str, b: str) -> sympy.Expr:
        return self.variables.bracket(a, b)

    @cached_property
    def _tensor(self) -> _PhaseSpaceTensor:
        coordinates = [q for q, _ in self.variables.pairs]
        momenta = [p for _, p in self.variables.pairs]
        return _PhaseSpaceTensor(self.variables, coordinates, momenta)

    def jacobiator(self, point: Mapping[str, float]) -> np.ndarray:
        return self._tensor.jacobiator(point)


class StructureBracket(Bracket):
    """A bracket given by a structure matrix ``J(w)`` in the variables themselves.

    Parameters
    ----------
    name, description
        Label and one line of explanation.
    variables
        The variables; their phase-space expressions give their values at a point.
    names
        The variables the structure acts on (a subset of ``variables.names``, in the
        order of the rows of ``structure``).
    structure
        Antisymmetric sympy matrix ``J_ab = {w_a, w_b}`` in the symbols
        ``variables.symbols[name]``.
    """

    def __init__(
        self,
        name: str,
        description: str,
        variables: NoncanonicalVariables,
        names: Sequence[str],
        structure: sympy.Matrix,
    ) -> None:
        unknown = [n for n in names if n not in variables.names]
        if unknown:
            raise InputError(f"bracket {name!r} needs the variables {', '.join(unknown)}, which this system lacks")
        if structure.shape != (len(names), len(names)) or (structure + structure.T).applyfunc(sympy.expand) != sympy.zeros(len(names)):
            raise InputError(f"the structure matrix of bracket {name!r} must be antisymmetric of size {len(names)}")
        self.name = name
        self.description = description
        self.variables = variables
        self.names = tuple(names)
        self.structure = structure
        self.w = [variables.symbols[n] for n in self.names]
        allowed = set(self.w)
        extra = set().union(*(e.free_symbols for e in structure)) - allowed
        if extra:
            raise InputError(f"the structure of {name!r} uses {', '.join(sorted(s.name for s in extra))}, not variables")

    @cached_property
    def _matrix_function(self) -> Callable[..., Any]:
        return array_function(self.w, self.structure, cse=False)

    @cached_property
    def _jacobi_function(self) -> Callable[..., Any]:
        m = len(self.w)
        J = self.structure
        entries = []
        for a, b, c in itertools.combinations(range(m), 3):
            total = sympy.Integer(0)
            for x, y, z in ((a, b, c), (b, c, a), (c, a, b)):
                total += sum(J[x, d] * sympy.diff(J[y, z], self.w[d]) for d in range(m))
            entries.append(sympy.expand(total))
        return array_function(self.w, entries, cse=False)

    def _values(self, point: Mapping[str, float]) -> list[float]:
        if all(n in point for n in self.names):
            return [float(point[n]) for n in self.names]
        values = self.variables.values(point)
        return [values[n] for n in self.names]

    def matrix(self, point: Mapping[str, float]) -> np.ndarray:
        return np.asarray(self._matrix_function(*self._values(point)), dtype=float)

    def symbolic(self, a: str, b: str) -> sympy.Expr:
        i, j = self.names.index(a), self.names.index(b)
        substitution = {self.variables.symbols[n]: self.variables.functions[n] for n in self.names}
        return sympy.expand(self.structure[i, j].xreplace(substitution))

    def jacobiator(self, point: Mapping[str, float]) -> np.ndarray:
        return np.asarray(self._jacobi_function(*self._values(point)), dtype=float).ravel()

    @property
    def is_linear(self) -> bool:
        """True if every entry of ``J`` is a homogeneous linear form in the variables."""
        for entry in self.structure:
            poly = sympy.Poly(entry, *self.w) if entry != 0 else None
            if poly is not None and any(sum(monomial) != 1 for monomial in poly.monoms()):
                return False
        return True
