"""Comparing brackets on the same variables: agreement, Jacobi identity, Casimirs.

The paper's central claim (Sect. XI) is that the Dirac bracket (240) of the rigid body,
written in the variables ``M_k = -eps_kij (R^T p)_ij`` (233) and ``R_ij``, *is* the
Chetaev bracket (248)–(249)::

    {M_i, M_j} = -eps_ijk M_k,   {M_i, R_jk} = -eps_ikm R_jm,   {R_ij, R_ab} = 0.

This module makes such statements checkable for any analysed system. A *bracket* here
is a rule that gives the antisymmetric matrix ``J_ab = {w_a, w_b}`` of a list of
variables ``w`` at a point of phase space. Three kinds:

* :class:`DiracBracket` — the engine's Dirac bracket (240) of the variables, taken as
  phase-space functions (``analysis.dirac_bracket``);
* :class:`CanonicalBracket` — their canonical Poisson bracket ``{q_i, p_j} = delta_ij``;
* :class:`StructureBracket` — a bracket given directly in the variables by a structure
  matrix ``J(w)`` (``chetaev``: so(3) ⋉ the three rows of ``R``; ``lie_poisson_so3``:
  ``{M_i, M_j} = -eps_ijk M_k`` on ``M`` alone).

:func:`compare_brackets` evaluates two brackets at sampled points of the constraint
surface and reports where they agree; :func:`jacobi_residual` checks the Jacobi identity
numerically; :func:`casimirs` finds the polynomial Casimirs of a linear (Lie–Poisson)
structure, e.g. ``|M|^2`` for so(3).

Command line: ``dirac analyze SYSTEM --compare SPEC`` calls :func:`cli_compare`.
"""

from __future__ import annotations

import itertools
import json
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np
import sympy

from dirac.errors import AnalysisError, InputError
from dirac.analysis.noncanonical import (
    NoncanonicalVariables,
    body_angular_momentum,
    rotation_matrix_symbols,
)

__all__ = [
    "Bracket",
    "DiracBracket",
    "CanonicalBracket",
    "StructureBracket",
    "BracketComparison",
    "BRACKET_NAMES",
    "analysis_variables",
    "named_bracket",
    "chetaev_structure",
    "lie_poisson_so3_structure",
    "surface_points",
    "compare_brackets",
    "jacobi_residual",
    "casimirs",
    "cli_compare",
]

#: the built-in bracket names accepted by :func:`named_bracket` and ``--compare``
BRACKET_NAMES = ("dirac", "canonical", "chetaev", "lie_poisson_so3")

#: default number of sampled surface points of ``--compare``
DEFAULT_POINTS = 20
#: absolute agreement tolerance, relative to max(1, size of the entries)
DEFAULT_TOLERANCE = 1e-10
#: tolerance of the numerical Jacobi check (relative; central differences for Dirac)
JACOBI_TOLERANCE = 1e-6


# ============================================================================ variables
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


# ============================================================================ brackets
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
        self._grad_w = sympy.lambdify(args, sympy.Matrix(functions).jacobian(self.x), "numpy", cse=True)
        self._grad_phi = None
        if constraints:
            self._grad_phi = sympy.lambdify(args, sympy.Matrix(list(constraints)).jacobian(self.x), "numpy", cse=True)

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


class DiracBracket(Bracket):
    """The engine's Dirac bracket (240) of the variables (phase-space functions).

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
        return sympy.lambdify(self.w, self.structure, "numpy")

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
        return sympy.lambdify(self.w, entries, "numpy")

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


def _eps(i: int, j: int, k: int) -> int:
    return int(sympy.LeviCivita(i, j, k))


def chetaev_structure(M: Sequence[sympy.Symbol], R: sympy.Matrix) -> sympy.Matrix:
    """Chetaev bracket (248)–(249) on ``(M_1, M_2, M_3, R_11, …, R_33)``::

        {M_i, M_j} = -eps_ijk M_k,  {M_i, R_jk} = -eps_ikm R_jm,  {R_ij, R_ab} = 0.

    The Lie–Poisson bracket of so(3) ⋉ (R^3)^3: ``M`` acts on each row of ``R``.
    """
    J = sympy.zeros(12, 12)
    for i in range(3):
        for j in range(3):
            J[i, j] = -sum(_eps(i, j, k) * M[k] for k in range(3))
        for j in range(3):
            for k in range(3):
                column = 3 + 3 * j + k
                J[i, column] = -sum(_eps(i, k, m) * R[j, m] for m in range(3))
                J[column, i] = -J[i, column]
    return J


def lie_poisson_so3_structure(M: Sequence[sympy.Symbol]) -> sympy.Matrix:
    """Lie–Poisson bracket of so(3) on ``M``: ``{M_i, M_j} = -eps_ijk M_k`` (248)."""
    return sympy.Matrix(3, 3, lambda i, j: -sum(_eps(i, j, k) * M[k] for k in range(3)))


def named_bracket(name: str, analysis: Any, variables: NoncanonicalVariables | None = None) -> Bracket:
    """One of the built-in brackets :data:`BRACKET_NAMES` on the variables of ``analysis``.

    ``dirac`` (the engine's (240)), ``canonical``, ``chetaev`` ((248)–(249), on
    ``M, R``), ``lie_poisson_so3`` ((248), on ``M`` only).

    Raises
    ------
    InputError
        For an unknown name, or ``chetaev``/``lie_poisson_so3`` on a system without
        coordinates ``R_11 … R_33``.
    """
    variables = variables if variables is not None else analysis_variables(analysis)
    if name == "dirac":
        return DiracBracket(analysis, variables)
    if name == "canonical":
        return CanonicalBracket(variables)
    if name in ("chetaev", "lie_poisson_so3"):
        if not all(f"M_{k}" in variables.names for k in (1, 2, 3)):
            raise InputError(
                f"bracket {name!r} acts on the body angular momentum M: it needs a rigid-body "
                "system with coordinates R_11 … R_33 (rigid_body_matrix, rigid_body_momentum)"
            )
        M = [variables.symbols[f"M_{k}"] for k in (1, 2, 3)]
        if name == "lie_poisson_so3":
            return StructureBracket(
                name, "Lie-Poisson bracket of so(3): {M_i, M_j} = -eps_ijk M_k (248)",
                variables, [f"M_{k}" for k in (1, 2, 3)], lie_poisson_so3_structure(M),
            )
        R = sympy.Matrix(3, 3, lambda i, j: variables.symbols[f"R_{i + 1}{j + 1}"])
        names = [*(f"M_{k}" for k in (1, 2, 3)), *(f"R_{i}{j}" for i in (1, 2, 3) for j in (1, 2, 3))]
        return StructureBracket(
            name, "Chetaev bracket (248)-(249): so(3) acting on the rows of R",
            variables, names, chetaev_structure(M, R),
        )
    raise InputError(f"unknown bracket {name!r}: choose from {', '.join(BRACKET_NAMES)}")


# ============================================================================ sampling
def surface_points(analysis: Any, count: int, seed: int = 0) -> list[dict[str, float]]:
    """``count`` numeric points of the constraint surface of ``analysis``.

    Uses ``analysis.surface_point(seed=…)`` (Gauss–Newton projection of random points);
    parameters that are still symbolic take their default values, which the brackets
    then use too.
    """
    if count < 1:
        raise InputError(f"number of points = {count}: give at least 1")
    return [dict(analysis.surface_point(seed=seed + k)) for k in range(count)]


# ============================================================================ comparing
@dataclass
class BracketComparison:
    """Where two brackets agree, entry by entry, at sampled points.

    Attributes
    ----------
    first, second
        The brackets' names.
    variables
        The variables both act on (the comparison is on these).
    points
        Number of points compared.
    tolerance
        Entries agree when ``|J1 - J2| <= tolerance * max(1, |J1|, |J2|)`` at every point.
    entries
        One dict per pair ``a < b``: ``a``, ``b``, ``max_difference``, ``agree`` and,
        if a symbolic comparison was asked for, ``symbolic`` (``"identical"`` or
        ``"different expressions"``).
    jacobi
        Bracket name -> largest Jacobi residual over triples and points (or a message).
    casimirs
        Bracket name -> Casimirs (strings) for linear structures.
    """

    first: str
    second: str
    variables: tuple[str, ...]
    points: int
    tolerance: float
    entries: list[dict[str, Any]]
    jacobi: dict[str, Any] = field(default_factory=dict)
    casimirs: dict[str, list[str]] = field(default_factory=dict)

    @property
    def agree(self) -> bool:
        """True when every entry agrees at every point."""
        return all(entry["agree"] for entry in self.entries)

    @property
    def differing(self) -> list[tuple[str, str]]:
        """The pairs ``(a, b)`` where the brackets differ."""
        return [(e["a"], e["b"]) for e in self.entries if not e["agree"]]

    @property
    def max_difference(self) -> float:
        """Largest difference over all entries and points."""
        return max((e["max_difference"] for e in self.entries), default=0.0)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary."""
        return {
            "first": self.first,
            "second": self.second,
            "variables": list(self.variables),
            "points": self.points,
            "tolerance": self.tolerance,
            "agree": self.agree,
            "max_difference": self.max_difference,
            "differ": [list(pair) for pair in self.differing],
            "jacobi": self.jacobi,
            "casimirs": self.casimirs,
        }

    def to_text(self) -> str:
        """Readable report."""
        lines = [
            f"Bracket comparison: {self.first} vs {self.second}",
            f"  variables ({len(self.variables)}): {', '.join(self.variables)}",
            f"  points of the constraint surface: {self.points}, tolerance {self.tolerance:g}",
        ]
        if self.agree:
            lines.append(f"  agree on all {len(self.entries)} pairs (max difference {self.max_difference:.3e})")
        else:
            differing = self.differing
            lines.append(f"  differ on {len(differing)} of {len(self.entries)} pairs (max difference {self.max_difference:.3e}):")
            for entry in self.entries:
                if not entry["agree"]:
                    lines.append(f"    {{{entry['a']}, {entry['b']}}}: max difference {entry['max_difference']:.3e}")
        symbolic = [e for e in self.entries if "symbolic" in e]
        if symbolic:
            identical = sum(e["symbolic"] == "identical" for e in symbolic)
            lines.append(f"  symbolically identical expressions: {identical} of {len(symbolic)} pairs")
        for name, value in self.jacobi.items():
            if isinstance(value, float):
                verdict = "holds" if value <= JACOBI_TOLERANCE else "FAILS"
                lines.append(f"  Jacobi identity of {name}: {verdict} (max residual {value:.2e})")
            else:
                lines.append(f"  Jacobi identity of {name}: {value}")
        for name, found in self.casimirs.items():
            lines.append(f"  Casimirs of {name} (polynomials of degree <= 2): " + (", ".join(found) or "none"))
        return "\n".join(lines)


def compare_brackets(
    first: Bracket,
    second: Bracket,
    points: Sequence[Mapping[str, float]],
    tolerance: float = DEFAULT_TOLERANCE,
    symbolic: bool = False,
) -> BracketComparison:
    """Compare two brackets entry by entry at phase-space points.

    Parameters
    ----------
    first, second
        The brackets; they are compared on the variables both act on.
    points
        Points of the constraint surface (``{name: value}``, parameters included if
        symbolic).
    tolerance
        Agreement threshold (see :class:`BracketComparison`).
    symbolic
        Also compare the entries as expressions (``symbolic()`` of both, expanded):
        identical expressions agree everywhere; different ones may still agree on the
        surface (weak equality), which the numerical verdict decides.

    Raises
    ------
    InputError
        If the brackets share no variables or no points are given.
    """
    common = [n for n in first.names if n in second.names]
    if not common:
        raise InputError(f"brackets {first.name!r} and {second.name!r} act on no common variables")
    if not points:
        raise InputError("no points to compare at: give at least one point of the constraint surface")
    index1 = [first.names.index(n) for n in common]
    index2 = [second.names.index(n) for n in common]
    m = len(common)
    worst = np.zeros((m, m))
    agree = np.ones((m, m), dtype=bool)
    for point in points:
        J1 = first.matrix(point)[np.ix_(index1, index1)]
        J2 = second.matrix(point)[np.ix_(index2, index2)]
        difference = np.abs(J1 - J2)
        scale = np.maximum(1.0, np.maximum(np.abs(J1), np.abs(J2)))
        worst = np.maximum(worst, difference)
        agree &= difference <= tolerance * scale
    entries = []
    for i, j in itertools.combinations(range(m), 2):
        entry: dict[str, Any] = {
            "a": common[i], "b": common[j], "max_difference": float(worst[i, j]), "agree": bool(agree[i, j]),
        }
        if symbolic:
            s1, s2 = first.symbolic(common[i], common[j]), second.symbolic(common[i], common[j])
            if s1 is not None and s2 is not None:
                same = sympy.expand(s1 - s2) == 0
                entry["symbolic"] = "identical" if same else "different expressions"
        entries.append(entry)
    return BracketComparison(first.name, second.name, tuple(common), len(points), tolerance, entries)


def jacobi_residual(bracket: Bracket, points: Sequence[Mapping[str, float]]) -> float:
    """Largest ``|{w_a, {w_b, w_c}} + cyclic|`` over all triples of variables and points.

    For a :class:`StructureBracket` the derivatives of ``J(w)`` are exact; for the
    Dirac and canonical brackets the inner bracket is differentiated by central
    differences on phase space (expect residuals of order 1e-8, not round-off).
    The residual is relative to ``max(1, |J|)`` at the point.
    """
    worst = 0.0
    for point in points:
        scale = max(1.0, float(np.max(np.abs(bracket.matrix(point)))))
        residual = bracket.jacobiator(point)
        if residual.size:
            worst = max(worst, float(np.max(np.abs(residual))) / scale)
    return worst


def _monomials(symbols: Sequence[sympy.Symbol], degree: int) -> list[sympy.Expr]:
    result: list[sympy.Expr] = []
    for d in range(1, degree + 1):
        for combo in itertools.combinations_with_replacement(symbols, d):
            result.append(sympy.Mul(*combo))
    return result


def casimirs(bracket: StructureBracket, degree: int = 2) -> list[sympy.Expr]:
    """Polynomial Casimirs of a linear (Lie–Poisson) structure, up to ``degree``.

    A Casimir ``C`` has ``{w_a, C} = sum_b J_ab(w) dC/dw_b = 0`` for every ``a``. With
    ``C`` a general polynomial without constant term, these are linear equations for
    its coefficients; the returned polynomials are a basis of their solutions (exact
    rational arithmetic). For so(3) the result is ``[M_1**2 + M_2**2 + M_3**2]``; for
    the Chetaev bracket, the six entries of ``R R^T`` (the rows' lengths and mutual
    scalar products).

    Raises
    ------
    InputError
        If the structure is not linear in the variables.
    """
    if not isinstance(bracket, StructureBracket) or not bracket.is_linear:
        raise InputError(f"bracket {bracket.name!r} is not a linear Poisson structure: Casimirs are found only for those")
    if degree < 1:
        raise InputError(f"degree = {degree}: give a degree >= 1")
    w = bracket.w
    monomials = _monomials(w, degree)
    coefficients = sympy.symbols(f"c_0:{len(monomials)}")
    candidate = sum(c * mono for c, mono in zip(coefficients, monomials))
    equations = []
    for a in range(len(w)):
        condition = sympy.expand(sum(bracket.structure[a, b] * sympy.diff(candidate, w[b]) for b in range(len(w))))
        if condition != 0:
            equations.extend(sympy.Poly(condition, *w).coeffs())
    if not equations:
        return list(monomials)
    A, _ = sympy.linear_eq_to_matrix(equations, coefficients)
    basis = A.nullspace()
    result = []
    for vector in basis:
        vector = vector / max((abs(v) for v in vector if v != 0), default=1)
        result.append(sympy.expand(sum(v * mono for v, mono in zip(vector, monomials))))
    return result


# ============================================================================ CLI
def _parse_spec(spec: str) -> tuple[list[str], int]:
    text = spec.strip()
    count = DEFAULT_POINTS
    if ":" in text:
        text, _, number = text.partition(":")
        try:
            count = int(number)
        except ValueError:
            raise InputError(f"--compare {spec!r}: the number of points after ':' must be an integer") from None
        if count < 1:
            raise InputError(f"--compare {spec!r}: give at least 1 point")
    names = [n.strip() for n in text.split(",") if n.strip()]
    if len(names) != 2:
        raise InputError(f"--compare {spec!r}: name two brackets, e.g. dirac,chetaev (known: {', '.join(BRACKET_NAMES)})")
    for name in names:
        if name not in BRACKET_NAMES:
            raise InputError(f"--compare {spec!r}: unknown bracket {name!r}; known: {', '.join(BRACKET_NAMES)}")
    return names, count


def cli_compare(analysis: Any, spec: str, as_json: bool) -> str:
    """Run ``dirac analyze SYSTEM --compare SPEC`` and return the report.

    SPEC is ``FIRST,SECOND`` or ``FIRST,SECOND:N``: two bracket names out of
    ``dirac``, ``canonical``, ``chetaev``, ``lie_poisson_so3``, and optionally the
    number ``N`` of sampled points of the constraint surface (default 20). Example:
    ``dirac analyze rigid_body_matrix --compare dirac,chetaev:100``.

    The report says on which pairs of variables the brackets agree (tolerance
    ``1e-10``, relative to ``max(1, |entry|)``), the largest Jacobi residual of each
    bracket on the sampled points (the first five points), and the Casimirs (degree
    <= 2) of the linear ones (``chetaev``, ``lie_poisson_so3``).

    Parameters
    ----------
    analysis
        The :class:`~dirac.analysis.constraint_analysis.ConstraintAnalysis` of the system.
    spec
        The SPEC string.
    as_json
        Return one JSON object instead of text.

    Raises
    ------
    InputError
        For a malformed SPEC or a bracket that does not apply to the system.
    """
    names, count = _parse_spec(spec)
    variables = analysis_variables(analysis)
    first = named_bracket(names[0], analysis, variables)
    second = named_bracket(names[1], analysis, variables)
    points = surface_points(analysis, count)
    comparison = compare_brackets(first, second, points)
    for bracket in (first, second):
        try:
            comparison.jacobi[bracket.name] = jacobi_residual(bracket, points[:5])
        except AnalysisError as exc:
            comparison.jacobi[bracket.name] = f"not checked ({exc})"
        if isinstance(bracket, StructureBracket) and bracket.is_linear:
            comparison.casimirs[bracket.name] = [str(c) for c in casimirs(bracket)]
    if as_json:
        return json.dumps(comparison.to_dict(), indent=2)
    return comparison.to_text()
