"""Text, JSON (docs/file_formats.md, "Analysis JSON") and LaTeX renderings of an analysis.

The functions read an analysis through :class:`AnalysisResult`, the attributes of a
:class:`~dirac.analysis.constraint_analysis.ConstraintAnalysis` that a report shows, so
that this module does not import the engine (whose ``to_text``/``to_json``/``to_latex``
call it).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, Protocol

import sympy

from dirac.model.lagrangian import Lagrangian, latex_names

__all__ = ["AnalysisResult", "to_json", "to_text", "to_latex"]


class AnalysisResult(Protocol):
    """What a report reads of an analysis (a ``ConstraintAnalysis`` provides all of it)."""

    @property
    def name(self) -> str: ...
    @property
    def lagrangian(self) -> Lagrangian: ...
    @property
    def coordinates(self) -> Sequence[sympy.Symbol]: ...
    @property
    def phase_space(self) -> Sequence[sympy.Symbol]: ...
    @property
    def parameters(self) -> Sequence[sympy.Symbol]: ...
    @property
    def canonical_hamiltonian(self) -> sympy.Expr: ...
    @property
    def hessian_rank(self) -> int: ...
    @property
    def primary_constraints(self) -> Sequence[sympy.Expr]: ...
    @property
    def primary_multipliers(self) -> Sequence[sympy.Symbol]: ...
    @property
    def stages(self) -> Sequence[Sequence[sympy.Expr]]: ...
    @property
    def constraints(self) -> Sequence[sympy.Expr]: ...
    @property
    def multipliers(self) -> Mapping[Any, sympy.Expr]: ...
    @property
    def undetermined_multipliers(self) -> Sequence[sympy.Symbol]: ...
    @property
    def first_class(self) -> Sequence[sympy.Expr]: ...
    @property
    def second_class(self) -> Sequence[sympy.Expr]: ...
    @property
    def physical_degrees_of_freedom(self) -> int: ...
    @property
    def bracket_strategy(self) -> str: ...
    @property
    def notes(self) -> Sequence[str]: ...

#: longest expression printed in full in the text report
TEXT_LIMIT = 400

#: expressions whose unordered text is longer than this are printed without sorting
#: their terms (sympy's canonical term order costs more than the whole analysis on the
#: large multipliers of the particle rigid body)
ORDERED_LIMIT = 5000


#: expressions whose tree (shared sub-expressions counted each time) has more nodes
#: than this are printed through common sub-expressions (their full text can take
#: megabytes: block solves share sub-expressions, printing repeats them)
TREE_LIMIT = 20000

#: prefix of the names of common sub-expressions in reports
SUBEXPRESSION_PREFIX = "cse_"


def tree_size(expr: sympy.Basic) -> int:
    """Number of nodes of ``expr`` as a tree (what printing visits), counted on the DAG."""
    memo: dict = {}

    def size(e):
        hit = memo.get(e)
        if hit is None:
            hit = 1 + sum(size(a) for a in e.args)
            memo[e] = hit
        return hit

    return size(expr)


def expression_text(expr: sympy.Expr) -> str:
    """``str(expr)``, except that long expressions keep their terms in stored order.

    The text is the same expression either way (``sympy.sympify`` reads it back); only
    the order of the terms of sums differs.
    """
    text = sympy.sstr(expr, order="none")
    return str(expr) if len(text) <= ORDERED_LIMIT else text


def shared_form(exprs: dict) -> tuple[dict, dict]:
    """Texts of ``{name: expr}``; huge trees through common sub-expressions.

    Returns ``(texts, definitions)``: ``texts[name]`` is the expression's text, in which
    the names ``cse_0, cse_1, ...`` stand for ``definitions[cse_k]`` (each definition may
    use earlier ones). ``definitions`` is empty when every tree is small.
    """
    big = [k for k, e in exprs.items() if tree_size(e) > TREE_LIMIT]
    texts = {k: expression_text(e) for k, e in exprs.items() if k not in big}
    definitions: dict = {}
    if big:
        names = sympy.numbered_symbols(SUBEXPRESSION_PREFIX)
        replacements, reduced = sympy.cse([exprs[k] for k in big], symbols=names, optimizations=None, order="none")
        definitions = {str(s): expression_text(e) for s, e in replacements}
        texts.update({k: expression_text(r) for k, r in zip(big, reduced)})
    return {k: texts[k] for k in exprs}, definitions


def _latex(expr: sympy.Expr) -> str:
    if tree_size(expr) > TREE_LIMIT:
        return rf"\text{{(an expression of {tree_size(expr)} tree nodes; see --json)}}"
    names = latex_names(expr)
    if len(sympy.sstr(expr, order="none")) <= ORDERED_LIMIT:
        return sympy.latex(expr, symbol_names=names)
    return sympy.latex(expr, order="none", symbol_names=names)


def _short(expr: sympy.Expr, limit: int = TEXT_LIMIT) -> str:
    if tree_size(expr) > TREE_LIMIT:
        return f"(an expression of {tree_size(expr)} tree nodes; see --json)"
    text = expression_text(expr)
    if len(text) <= limit:
        return text
    return f"{text[: limit - 40]} ... ({len(text)} characters; full form in --json)"


def to_json(analysis: AnalysisResult) -> dict:
    """The analysis JSON object of docs/file_formats.md; constraints are ``str()`` of sympy expressions.

    Extra keys: ``phase_space``, ``parameters``, ``canonical_hamiltonian``,
    ``primary_multipliers``, ``undetermined_multipliers``, ``hessian_rank``,
    ``bracket_strategy``, ``notes``, ``time_dependent`` (``L`` or a constraint depends
    explicitly on the time ``t``); ``multiplier_subexpressions`` (name -> text) when a
    multiplier is too large to print as one tree: its text then uses those names
    (see :func:`shared_form`).
    """
    multipliers, definitions = shared_form(dict(analysis.multipliers))
    out = {
        "system": analysis.name,
        "coordinates": [s.name for s in analysis.coordinates],
        "phase_space_dimension": len(analysis.phase_space),
        "stages": [
            {"stage": k, "constraints": [expression_text(c) for c in stage]} for k, stage in enumerate(analysis.stages, start=1)
        ],
        "first_class": [expression_text(c) for c in analysis.first_class],
        "second_class": [expression_text(c) for c in analysis.second_class],
        "multipliers": multipliers,
        "physical_degrees_of_freedom": analysis.physical_degrees_of_freedom,
        "phase_space": [s.name for s in analysis.phase_space],
        "parameters": [p.name for p in analysis.parameters],
        "canonical_hamiltonian": expression_text(analysis.canonical_hamiltonian),
        "primary_multipliers": [u.name for u in analysis.primary_multipliers],
        "undetermined_multipliers": [u.name for u in analysis.undetermined_multipliers],
        "hessian_rank": analysis.hessian_rank,
        "bracket_strategy": analysis.bracket_strategy,
        "notes": list(analysis.notes),
        "time_dependent": analysis.lagrangian.is_time_dependent,
    }
    if definitions:
        out["multiplier_subexpressions"] = definitions
    return out


def to_text(analysis: AnalysisResult) -> str:
    """Readable report: the chain stage by stage with counts, classes, multipliers."""
    a = analysis
    n = len(a.coordinates)
    lines = [f"Dirac-Bergmann analysis of {a.name!r}"]
    if a.lagrangian.description:
        lines.append(f"  {a.lagrangian.description}")
    lines.append(f"  L = {_short(a.lagrangian.expression)}")
    for k, chi in enumerate(a.lagrangian.constraints, start=1):
        lines.append(f"  constraint {k}: {chi} = 0   (multiplier lambda_{k})")
    if a.lagrangian.is_time_dependent:
        lines.append("time-dependent: t occurs explicitly; consistency is d Phi/dt = {Phi, H_T} + d_t Phi = 0")
    lines.append(
        f"phase space: {2 * n} dimensions ({', '.join(s.name for s in a.coordinates)} and their momenta)"
    )
    if a.parameters:
        lines.append(f"parameters (symbolic): {', '.join(p.name for p in a.parameters)}")
    lines.append(f"Hessian d2L/dq_dot2: rank {a.hessian_rank} of {len(a.lagrangian.coordinates)}")
    lines.append(f"canonical Hamiltonian H_c = {_short(a.canonical_hamiltonian)}")
    if a.primary_multipliers:
        terms = " + ".join(f"{u}*({_short(phi, 80)})" for u, phi in zip(a.primary_multipliers, a.primary_constraints))
        lines.append(f"total Hamiltonian H_T = H_c + {terms}")
    else:
        lines.append("total Hamiltonian H_T = H_c")
    lines.append("")
    lines.append(f"constraint chain: {len(a.stages)} stage(s), {len(a.constraints)} constraint(s)")
    for k, stage in enumerate(a.stages, start=1):
        label = " (primary)" if k == 1 else ""
        lines.append(f"  stage {k}{label}: {len(stage)} constraint(s)")
        for c in stage:
            lines.append(f"    {_short(c)} = 0")
    lines.append("")
    lines.append("multipliers of the primary constraints:")
    if not a.primary_multipliers:
        lines.append("  (none)")
    for u in a.primary_multipliers:
        if u.name in a.multipliers:
            lines.append(f"  {u} = {_short(a.multipliers[u.name])}")
        else:
            lines.append(f"  {u}: undetermined (gauge freedom)")
    lines.append("")
    lines.append(f"first class: {len(a.first_class)}")
    for c in a.first_class:
        lines.append(f"    {_short(c)}")
    lines.append(f"second class: {len(a.second_class)} (rank of C_ab = {{Phi_a, Phi_b}} on the surface)")
    if len(a.second_class) <= 12:
        for c in a.second_class:
            lines.append(f"    {_short(c)}")
    else:
        lines.append("    (all constraints of the chain above)" if len(a.second_class) == len(a.constraints) else "    (see --json)")
    lines.append(
        f"physical degrees of freedom: ({2 * n} - 2*{len(a.first_class)} - {len(a.second_class)})/2 = "
        f"{a.physical_degrees_of_freedom}"
    )
    lines.append(f"Dirac bracket: {a.bracket_strategy}")
    for note in a.notes:
        lines.append(f"note: {note}")
    return "\n".join(lines)


def to_latex(analysis: AnalysisResult, display: bool = False) -> str:
    """LaTeX rendering: one ``align*`` environment (``display=True``: ``$$ aligned $$`` for Jupyter)."""
    a = analysis
    lx = _latex
    name = a.name.replace("_", r"\_")
    rows = [rf"&\text{{Dirac--Bergmann analysis of {name}}}"]
    rows.append(rf"L &= {lx(a.lagrangian.expression)}")
    for k, chi in enumerate(a.lagrangian.constraints, start=1):
        rows.append(rf"\chi_{{{k}}} &= {lx(chi)} = 0")
    if a.lagrangian.is_time_dependent:
        rows.append(r"&\text{time-dependent: } \frac{d\Phi}{dt} = \{\Phi, H_T\} + \partial_t \Phi")
    rows.append(rf"H_c &= {lx(a.canonical_hamiltonian)}")
    for k, stage in enumerate(a.stages, start=1):
        title = "primary constraints" if k == 1 else f"stage {k}"
        rows.append(rf"&\text{{{title} ({len(stage)})}}")
        rows.extend(rf"&{lx(c)} = 0" for c in stage)
    if a.primary_multipliers:
        rows.append(r"&\text{multipliers}")
        for u in a.primary_multipliers:
            if u.name in a.multipliers:
                rows.append(rf"{lx(u)} &= {lx(a.multipliers[u.name])}")
            else:
                rows.append(rf"{lx(u)} &\;\text{{undetermined (gauge)}}")
    rows.append(
        rf"&\text{{first class: {len(a.first_class)}, second class: {len(a.second_class)}, "
        rf"physical degrees of freedom: {a.physical_degrees_of_freedom}}}"
    )
    body = " \\\\\n".join(rows)
    if display:
        return "$$\\begin{aligned}\n" + body + "\n\\end{aligned}$$"
    return "\\begin{align*}\n" + body + "\n\\end{align*}"
