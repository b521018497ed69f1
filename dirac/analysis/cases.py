"""Parameter cases: the generic analysis and one analysis per special parameter set, as a tree.

The analysis keeps its parameters symbolic and decides ranks at generic values; at a
special parameter set (:mod:`dirac.analysis.chain.special_values`) the structure changes.
:func:`parameter_cases` analyses each special set again with the parameter substituted
(``b -> a**2`` on the curve ``b - a**2 = 0``, ``M -> 0``), and recurses: on a special set
a rank can drop further (special cases of special cases).

Two kinds of candidates are followed at every node of the tree:

* the special parameter values the node's analysis found (a rank of the Hessian, of the
  consistency block ``A_PQ = {Phi_P, phi_Q}`` (213)-(215) or of the second-class block of
  ``C_ab = {Phi_a, Phi_b}`` (240) drops there);
* the zeros of the parameter-only factors of a constraint's content (the gcd of its
  coefficients as a polynomial in the phase-space variables): there the constraint
  vanishes identically and the chain beyond it changes. Such a candidate is kept only
  where the analysis there has another structure (stage sizes, numbers of first- and
  second-class constraints) than the node it comes from.

Example (Rothe & Rothe, *Classical and Quantum Dynamics of Constrained Hamiltonian
Systems*, 2010): ``L = q1_dot**2/2 + q2 q1_dot + (1 - a) q1 q2_dot + (b/2)(q1 - q2)**2``
has the generic case ``b - a**2 != 0``, the curve ``b = a**2`` (with ``a != 0``) and, on
the curve, ``a = 0`` where the secondary constraint ``a (p1 - q2 - a (q1 - q2))`` vanishes
identically: ``a = b = 0``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import sympy

from dirac.analysis.report import structure_json, structure_summary
from dirac.errors import DiracError
from dirac.model.lagrangian import Lagrangian

__all__ = ["ParameterCase", "parameter_cases", "MAX_CASE_DEPTH"]

#: how many special sets deep the tree is followed (generic = depth 0)
MAX_CASE_DEPTH = 3


@dataclass
class ParameterCase:
    """One node of the case tree.

    Attributes
    ----------
    condition
        The parameter set, e.g. ``"b - a**2 != 0"`` (generic), ``"b = a**2, a != 0"``,
        ``"b = 0, a = 0"``.
    depth
        0 for the generic case, 1 for a special set, 2 for a special set of that, ...
    analysis
        The analysis there, or ``None`` when it was refused (``error`` says why).
    error
        The refusal's message, else ``None``.
    """

    condition: str
    depth: int
    analysis: Any
    error: str | None = None

    def to_json(self) -> dict:
        """``{"condition", "stages", "first_class", "second_class", "physical_degrees_of_freedom"}`` (docs/file_formats.md).

        A refused case has ``"condition"``, ``"depth"`` and ``"error"`` instead of the counts.
        """
        if self.analysis is None:
            return {"condition": self.condition, "depth": self.depth, "error": self.error}
        return {"condition": self.condition, "depth": self.depth, **structure_json(self.analysis)}

    def summary(self) -> str:
        """``"2 first class, 0 second class, 0 degrees of freedom"`` (or the refusal)."""
        if self.analysis is None:
            return f"refused: {self.error}"
        return structure_summary(self.analysis)


def _substitute(lagrangian: Lagrangian, parameter: sympy.Symbol, value: sympy.Expr) -> Lagrangian:
    """``lagrangian`` with ``parameter -> value`` (a number or an expression in the other parameters)."""
    remaining = {p: v for p, v in lagrangian.parameters.items() if p != parameter}
    fixed = dict(lagrangian.fixed_values)
    if not value.free_symbols:
        fixed[parameter.name] = float(value)
    return Lagrangian(
        lagrangian.name,
        lagrangian.coordinates,
        lagrangian.velocities,
        lagrangian.expression.subs(parameter, value),
        tuple(c.subs(parameter, value) for c in lagrangian.constraints),
        remaining,
        lagrangian.description,
        None,  # the validator checks numbers; a parameter replaced by an expression has none
        fixed,
    )


def _content_zeros(analysis: Any) -> list[tuple[sympy.Symbol, sympy.Expr, str]]:
    """``(parameter, value, equation)`` where a constraint's parameter-only factor vanishes.

    The content of a constraint ``c`` is the gcd of its coefficients as a polynomial in the
    phase-space variables; ``c = content * primitive``, so ``c`` vanishes identically where
    a factor of the content does.
    """
    params = set(analysis.parameters)
    out: list[tuple[sympy.Symbol, sympy.Expr, str]] = []
    seen: set[str] = set()
    for c in [*analysis.constraints, *analysis.reducible_constraints]:
        if not c.free_symbols & params:
            continue
        numerator = sympy.fraction(sympy.together(c))[0]
        variables = sorted(numerator.free_symbols - params, key=lambda s: s.name)
        if not variables:
            continue
        try:
            content = sympy.gcd_list(sympy.Poly(numerator, *variables).coeffs())
            factors = sympy.factor_list(content)[1]
        except (sympy.PolynomialError, sympy.CoercionFailed, NotImplementedError):
            continue
        for factor, _ in factors:
            if not factor.free_symbols or not factor.free_symbols <= params:
                continue
            names = sorted(factor.free_symbols, key=lambda s: s.name)
            linear = [p for p in names if sympy.degree(factor, p) == 1 and not sympy.diff(factor, p).free_symbols]
            for p in linear[-1:] or names[:1]:
                for value in sympy.solve(factor, p):
                    equation = f"{p} = {value}"
                    if value.is_real is not False and equation not in seen:
                        seen.add(equation)
                        out.append((p, value, equation))
    return out


def _structure(analysis: Any) -> tuple:
    """Stage sizes and class counts: two analyses with the same structure are one case."""
    return (tuple(len(s) for s in analysis.stages), len(analysis.first_class), len(analysis.second_class))


def parameter_cases(
    analysis: Any, progress: Callable[[str], None] | None = None, max_depth: int = MAX_CASE_DEPTH
) -> list[ParameterCase]:
    """The generic case and every special parameter case below it, depth first (generic first).

    Parameters
    ----------
    analysis
        The generic analysis (:class:`~dirac.analysis.constraint_analysis.ConstraintAnalysis`
        with its parameters symbolic).
    progress
        Called with one line per case analysed.
    max_depth
        How many special sets deep to follow.

    Returns
    -------
    list of ParameterCase
        The generic case first; each special case follows the case it specialises. The
        condition of a case names the substitutions that lead to it and excludes the
        special sets below it (``"b = a**2, a != 0"``).
    """
    analysis = getattr(analysis, "_generic_analysis", None) or analysis  # the analysis with the parameters symbolic
    cases: list[ParameterCase] = []
    seen: set[tuple] = set()

    def key(lagrangian: Lagrangian) -> tuple:
        return (sympy.srepr(sympy.expand(lagrangian.expression)), tuple(sympy.srepr(sympy.expand(c)) for c in lagrangian.constraints))

    def children(node: Any) -> list[tuple[sympy.Symbol, sympy.Expr, str, str]]:
        """(parameter, value, equation, its negation) of every candidate below ``node``."""
        symbols = {p.name: p for p in node.parameters}
        found = []
        for s in node.special_parameter_values:
            if s.parameter in symbols:
                equation = s.equation
                found.append((symbols[s.parameter], s.value, equation, equation.replace(" = ", " != ", 1)))
        known = {(p, sympy.simplify(v)) for p, v, _, _ in found}
        for p, value, equation in _content_zeros(node):
            if (p, sympy.simplify(value)) not in known:
                found.append((p, value, equation, equation.replace(" = ", " != ", 1)))
        return found

    def visit(lagrangian: Lagrangian, node: Any, error: str | None, path: list[str], depth: int) -> None:
        index = len(cases)
        case = ParameterCase("", depth, node, error)
        cases.append(case)
        kept: list[str] = []
        if node is not None and depth < max_depth:
            for p, value, equation, negation in children(node):
                child = _substitute(lagrangian, p, value)
                if key(child) in seen:
                    continue
                seen.add(key(child))
                try:
                    sub: Any = type(analysis)(child)
                    why = None
                except DiracError as exc:
                    sub, why = None, str(exc)
                if sub is not None and _structure(sub) == _structure(node):
                    continue  # not a case of its own: the same structure as the node
                if progress is not None:
                    progress(f"case {', '.join([*path, equation])}: {ParameterCase('', 0, sub, why).summary()}")
                kept.append(negation)
                visit(child, sub, why, [*path, equation], depth + 1)
        conditions = [*path, *kept]
        cases[index].condition = ", ".join(conditions) if conditions else "all parameter values"

    seen.add(key(analysis.lagrangian))
    visit(analysis.lagrangian, analysis, None, [], 0)
    return cases


def cases_text(cases: list[ParameterCase]) -> str:
    """The case tree as indented text (the generic case at the root)."""
    lines = ["parameter cases:"]
    for case in cases:
        lines.append(f"{'  ' * (case.depth + 1)}- {case.condition}: {case.summary()}")
    return "\n".join(lines)
