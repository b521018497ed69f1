"""Text, JSON (docs/file_formats.md, "Analysis JSON") and LaTeX renderings of an analysis.

The functions read an analysis through :class:`AnalysisResult`, the attributes of a
:class:`~dirac.analysis.constraint_analysis.ConstraintAnalysis` that a report shows, so
that this module does not import the engine (whose ``to_text``/``to_json``/``to_latex``
call it).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any, Protocol

import sympy

from dirac.analysis.core.algebra import printed, printed_at_most, text_of
from dirac.analysis.core.common_subexpressions import named_subexpressions
from dirac.analysis.gauge.generators import GaugeStructure
from dirac.model.lagrangian import Lagrangian, latex_names

if TYPE_CHECKING:  # the report reads a solution; it needs no solver
    from dirac.analysis.classes.multiplier_solution import MultiplierSolution

__all__ = ["AnalysisResult", "to_json", "to_text", "to_latex", "STRUCTURE_KEYS", "structure_json", "structure_summary"]


class AnalysisResult(Protocol):
    """What a report reads of an analysis (a ``ConstraintAnalysis`` provides all of it)."""

    @property
    def name(self) -> str: ...
    @property
    def lagrangian(self) -> Lagrangian: ...
    @property
    def time(self) -> sympy.Symbol | None: ...
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
    def multiplier_solution(self) -> MultiplierSolution: ...
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
    @property
    def gauge_structure(self) -> GaugeStructure: ...
    @property
    def gauge_conditions(self) -> Sequence[str]: ...
    @property
    def reducible_constraints(self) -> Sequence[sympy.Expr]: ...
    @property
    def special_parameter_values(self) -> Sequence[Any]: ...

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


#: the JSON keys that describe the structure of one case or one part of the surface (docs/file_formats.md)
STRUCTURE_KEYS = ("stages", "first_class", "second_class", "physical_degrees_of_freedom")


def structure_json(analysis: AnalysisResult) -> dict:
    """The :data:`STRUCTURE_KEYS` of :func:`to_json` alone (for a case or a part: nothing else is computed)."""
    return {
        "stages": [
            {"stage": k, "constraints": [expression_text(c) for c in stage]} for k, stage in enumerate(analysis.stages, start=1)
        ],
        "first_class": [expression_text(c) for c in analysis.first_class],
        "second_class": [expression_text(c) for c in analysis.second_class],
        "physical_degrees_of_freedom": analysis.physical_degrees_of_freedom,
    }


def structure_summary(analysis: AnalysisResult) -> str:
    """``"stages 1+1, 2 first class, 0 second class, 0 degree(s) of freedom"``: one line for a case or a part."""
    sizes = "+".join(str(len(s)) for s in analysis.stages) or "0"
    return (
        f"stages {sizes}, {len(analysis.first_class)} first class, {len(analysis.second_class)} second class, "
        f"{analysis.physical_degrees_of_freedom} degree(s) of freedom"
    )


def tree_size(expr: sympy.Basic, memo: dict | None = None) -> int:
    """Number of nodes of ``expr`` as a tree (what printing visits), counted on the DAG.

    ``memo`` (node -> its tree size) may be shared by calls on expressions that share
    sub-trees (the multipliers of one analysis): each shared node is then walked once.
    """
    memo = {} if memo is None else memo

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
    longest = printed_at_most(expr, ORDERED_LIMIT + 1)
    if longest is not None and longest <= ORDERED_LIMIT:  # short in any order: no need to measure it
        return printed(expr)
    text = text_of(expr, order="none")
    return printed(expr) if len(text) <= ORDERED_LIMIT else text


def shared_form(exprs: dict) -> tuple[dict, dict]:
    """Texts of ``{name: expr}``; huge trees through common sub-expressions.

    Returns ``(texts, definitions)``: ``texts[name]`` is the expression's text, in which
    the names ``cse_0, cse_1, ...`` stand for ``definitions[cse_k]`` (each definition may
    use earlier ones; :func:`~dirac.analysis.core.common_subexpressions.named_subexpressions`;
    the definitions keep the stored order of their terms).
    ``definitions`` is empty when every tree is small.
    """
    sizes: dict = {}  # one walk of the shared graph for all of them
    big = [k for k, e in exprs.items() if tree_size(e, sizes) > TREE_LIMIT]
    texts = {k: expression_text(e) for k, e in exprs.items() if k not in big}
    definitions: dict = {}
    if big:
        # the definitions are pieces of a graph: printed in stored order (sorting the terms of each
        # took most of the JSON of (228)); the expressions themselves as any other text
        shared, definitions = named_subexpressions(
            [exprs[k] for k in big], SUBEXPRESSION_PREFIX, expression_text, lambda e: text_of(e, order="none")
        )
        texts.update(zip(big, shared))
    return {k: texts[k] for k in exprs}, definitions


def _latex(expr: sympy.Expr) -> str:
    size = tree_size(expr)
    if size > TREE_LIMIT:
        return rf"\text{{(an expression of {size} tree nodes; see --json)}}"
    names = latex_names(expr)
    if len(text_of(expr, order="none")) <= ORDERED_LIMIT:
        return sympy.latex(expr, symbol_names=names)
    return sympy.latex(expr, order="none", symbol_names=names)


def _short(expr: sympy.Expr, limit: int = TEXT_LIMIT, sizes: dict | None = None) -> str:
    size = tree_size(expr, sizes)  # one walk of the DAG (a multiplier of (228) has tens of millions of tree nodes)
    if size > TREE_LIMIT:
        return f"(an expression of {size} tree nodes; see --json)"
    text = expression_text(expr)
    if len(text) <= limit:
        return text
    return f"{text[: limit - 40]} ... ({len(text)} characters; full form in --json)"


def to_json(analysis: AnalysisResult) -> dict:
    """The analysis JSON object of docs/file_formats.md; constraints are ``str()`` of sympy expressions.

    Extra keys: ``phase_space``, ``parameters``, ``canonical_hamiltonian``,
    ``primary_multipliers``, ``undetermined_multipliers``, ``hessian_rank``,
    ``bracket_strategy``, ``notes``, ``reducible_constraints`` (constraints that hold but
    depend on the kept independent set), ``special_parameter_values`` (list of
    ``{"parameter", "value", "equation", "where"}``; ``equation`` is the value set or
    curve as an equation such as ``"b - a**2 = 0"``), ``time_dependent`` (``L``, a constraint or a gauge
    condition depends explicitly on the time ``t``); ``multiplier_solution`` (the general solution
    ``u = U + v_a V_a``: ``particular``, ``null_vectors``, ``free``);
    ``multiplier_subexpressions`` (name -> text) when a multiplier is too large to print
    as one tree: its text then uses those names (see :func:`shared_form`). Gauge keys:
    ``gauge_generators`` (one ``{"terms": [G_0, G_1, ...]}`` per gauge parameter),
    ``gauge_transformations`` (for each, its ``parameter``, free ``multiplier`` and
    ``delta``: variable -> ``{z, G}``), ``first_class_without_gauge_transformation`` and
    ``gauge_conditions``; ``forces`` (coordinate name -> the generalized force ``Q_r`` in
    phase-space variables; ``{}`` when none); ``singular_loci`` (one ``{"expression", "where", "stage",
    "what"}`` per locus of the surface where an expression of the analysis divides by zero,
    :class:`~dirac.analysis.core.divisors.SingularLocus`; ``[]`` when none);
    ``singular_loci_unsearched`` (one sentence per place of the analysis whose expressions were
    too long to search for divisions by zero, :class:`~dirac.analysis.core.divisors.Unsearched`;
    ``[]`` when everything was searched).
    """
    multipliers, solution, definitions = _multiplier_texts(analysis)
    gauge = analysis.gauge_structure
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
        "multiplier_solution": solution,
        "physical_degrees_of_freedom": analysis.physical_degrees_of_freedom,
        "phase_space": [s.name for s in analysis.phase_space],
        "parameters": [p.name for p in analysis.parameters],
        "canonical_hamiltonian": expression_text(analysis.canonical_hamiltonian),
        "primary_multipliers": [u.name for u in analysis.primary_multipliers],
        "undetermined_multipliers": [u.name for u in analysis.undetermined_multipliers],
        "hessian_rank": analysis.hessian_rank,
        "bracket_strategy": analysis.bracket_strategy,
        "notes": list(analysis.notes) + list(gauge.notes),
        "reducible_constraints": [expression_text(c) for c in analysis.reducible_constraints],
        "special_parameter_values": [s.to_json() for s in analysis.special_parameter_values],
        "time_dependent": analysis.time is not None,
        "gauge_generators": [{"terms": [expression_text(g) for g in gen.terms]} for gen in gauge.generators],
        "gauge_transformations": [
            {
                "parameter": gen.parameter,
                "multiplier": gen.multiplier,
                "delta": {z.name: expression_text(d) for z, d in gen.delta.items()},
            }
            for gen in gauge.generators
        ],
        "first_class_without_gauge_transformation": [expression_text(c) for c in gauge.without_transformation],
        "gauge_conditions": list(analysis.gauge_conditions),
        "forces": {name: expression_text(Q) for name, Q in getattr(analysis, "forces", {}).items()},
        "singular_loci": [locus.to_json() for locus in getattr(analysis, "singular_loci", ())],
        "singular_loci_unsearched": [str(u) for u in getattr(analysis, "singular_loci_unsearched", ())],
    }
    if definitions:
        out["multiplier_subexpressions"] = definitions
    return out


def _gauge_lines(a: AnalysisResult) -> list[str]:
    """Text lines on the gauge conditions, generators and first-class constraints without one."""
    lines: list[str] = []
    if a.gauge_conditions:
        lines.append(f"gauge conditions: {', '.join(f'{c} = 0' for c in a.gauge_conditions)}")
    if not a.first_class:
        return lines
    gauge = a.gauge_structure
    lines.append(f"gauge generators (Castellani): {len(gauge.generators)}, G = sum_k eps^(k) G_k, delta z = {{z, G}}")
    for gen in gauge.generators:
        lines.append(f"  {gen.parameter} (free multiplier {gen.multiplier}): G = {_short(gen.generator())}")
        for z, d in gen.delta.items():
            lines.append(f"    delta {z} = {_short(d, 120)}")
    for gamma in gauge.unclosed:
        lines.append(f"  {_short(gamma, 120)}: Castellani's chain did not close; no generator")
    for reason in gauge.rejected:
        lines.append(f"  {reason}")
    for term in gauge.irregular_terms:
        lines.append(f"  {_short(term, 120)}: irregular (vanishing gradient on the surface), generates nothing")
    for c in gauge.without_transformation:
        lines.append(f"  {gauge.account(c)}")
    return lines


#: the ``"multipliers"`` entry of a multiplier that is not fixed alone
UNDETERMINED = "undetermined"


def _multiplier_texts(analysis: AnalysisResult) -> tuple[dict, dict, dict]:
    """Texts of ``"multipliers"`` and ``"multiplier_solution"``, sharing sub-expressions.

    ``"multipliers"`` has one entry per multiplier (its expression where it is fixed
    alone, ``"undetermined"`` where not); a particular-solution entry that is the same
    expression as a fixed multiplier is printed once and its text reused.
    """
    solved = dict(analysis.multipliers)
    sol = analysis.multiplier_solution
    exprs: dict = {("fixed", name): e for name, e in solved.items()}
    particular_keys: dict = {}
    for name, e in sol.particular.items():
        key = ("fixed", name) if name in solved and solved[name] is e else ("particular", name)
        exprs.setdefault(key, e)
        particular_keys[name] = key
    for a, vec in enumerate(sol.null_vectors):
        for name, e in vec.items():
            exprs[("null", a, name)] = e
    texts, definitions = shared_form(exprs)
    multipliers = {
        u.name: texts[("fixed", u.name)] if u.name in solved else UNDETERMINED for u in analysis.primary_multipliers
    }
    solution = {
        "particular": {name: texts[key] for name, key in particular_keys.items()},
        "null_vectors": [{name: texts[("null", a, name)] for name in vec} for a, vec in enumerate(sol.null_vectors)],
        "free": [v.name for v in sol.free],
    }
    return multipliers, solution, definitions


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
    forces = getattr(a, "forces", {})
    if forces:
        lines.append("  generalized forces (not from a potential), Lagrange: d/dt dL/dq_dot - dL/dq = Q + constraint forces")
        for name, Q in forces.items():
            lines.append(f"    Q_{name} = {_short(Q)}")
        lines.append("  forced equations of motion: q_dot = dH_T/dp, and for each forced coordinate")
        for name in forces:
            lines.append(f"    d p_{name}/dt = -dH_T/d{name} + Q_{name}")
    if a.time is not None:
        lines.append("time-dependent: t occurs explicitly; consistency is d Phi/dt = {Phi, H_T} + d_t Phi = 0")
    lines.append(
        f"phase space: {2 * n} dimensions ({', '.join(s.name for s in a.coordinates)} and their momenta)"
    )
    if a.parameters:
        lines.append(f"parameters (symbolic): {', '.join(p.name for p in a.parameters)}")
    lines.append(f"Hessian d2L/dq_dot2: rank {a.hessian_rank} of {len(a.lagrangian.coordinates)}")
    lines.append(f"canonical Hamiltonian H_c = {_short(a.canonical_hamiltonian)}")
    general = not a.multiplier_solution.each_fixed_or_free
    if general:
        lines.append(_general_total_hamiltonian(a.multiplier_solution))
    elif a.primary_multipliers:
        terms = " + ".join(f"{u}*({_short(phi, 80)})" for u, phi in zip(a.primary_multipliers, a.primary_constraints))
        lines.append(f"total Hamiltonian H_T = H_c + {terms}")
    else:
        lines.append("total Hamiltonian H_T = H_c")
    lines.append("")
    lines.append(f"constraint chain: {len(a.stages)} stage(s), {sum(len(stage) for stage in a.stages)} constraint(s)")
    for k, stage in enumerate(a.stages, start=1):
        label = " (primary)" if k == 1 else ""
        lines.append(f"  stage {k}{label}: {len(stage)} constraint(s)")
        for c in stage:
            lines.append(f"    {_short(c)} = 0")
    lines.append("")
    lines.append("multipliers of the primary constraints:")
    if not a.primary_multipliers:
        lines.append("  (none)")
    sizes: dict = {}  # tree sizes of the multipliers' shared sub-trees, walked once
    for u in a.primary_multipliers:
        if u.name in a.multipliers:
            lines.append(f"  {u} = {_short(a.multipliers[u.name], sizes=sizes)}")
        elif general:
            lines.append(f"  {u}: not fixed alone (see the general solution)")
        else:
            lines.append(f"  {u}: undetermined (gauge freedom)")
    if general:
        lines.extend(_general_solution_lines(a.multiplier_solution))
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
    if a.reducible_constraints:
        lines.append(
            f"reducible: {len(a.reducible_constraints)} more constraint(s) hold but depend on the independent set above: "
            + ", ".join(_short(c, 80) for c in a.reducible_constraints)
        )
    lines.extend(_gauge_lines(a))
    lines.extend(_singular_lines(a))
    lines.append(f"Dirac bracket: {a.bracket_strategy}")
    for s in a.special_parameter_values:
        if s.is_curve:
            lines.append(f"special parameter curve: {s.equation} ({s.where})")
        else:
            lines.append(f"special parameter value: {s.parameter} = {s.value} ({s.where})")
    for note in a.notes:
        lines.append(f"note: {note}")
    return "\n".join(lines)


def _singular_lines(a: AnalysisResult) -> list[str]:
    """``singular locus: x = 0 (divisor 3*x - 4*z, stage 2): the multiplier solution divides by zero`` per locus."""
    return [f"singular locus: {locus}" for locus in getattr(a, "singular_loci", ())] + [
        f"singular loci: {u}" for u in getattr(a, "singular_loci_unsearched", ())]


def _gauge_latex_rows(a: AnalysisResult) -> list[str]:
    """LaTeX rows: gauge conditions and ``G = sum_k eps^(k) G_k`` for each gauge parameter."""
    conditions = list(a.constraints)[len(a.constraints) - len(a.gauge_conditions):] if a.gauge_conditions else []
    rows = [rf"&{_latex(c)} = 0 \quad \text{{(gauge)}}" for c in conditions]
    if not a.first_class or not a.gauge_structure.generators:
        return rows
    rows.append(r"&\text{gauge generators (Castellani)}")
    for gen in a.gauge_structure.generators:
        G = gen.generator()
        names = latex_names(G)
        index = gen.parameter.rsplit("_", 1)[1]
        for k, eps in enumerate(gen.parameter_symbols()):
            base = rf"\varepsilon_{{{index}}}"
            names[eps] = base if k == 0 else (rf"\dot{{{base}}}" if k == 1 else (rf"\ddot{{{base}}}" if k == 2 else rf"{base}^{{({k})}}"))
        rows.append(rf"G_{{{index}}} &= {sympy.latex(G, symbol_names=names)}")
    return rows


def to_latex(analysis: AnalysisResult, display: bool = False) -> str:
    """LaTeX rendering: one ``align*`` environment (``display=True``: ``$$ aligned $$`` for Jupyter)."""
    a = analysis
    lx = _latex
    name = a.name.replace("_", r"\_")
    rows = [rf"&\text{{Dirac--Bergmann analysis of {name}}}"]
    rows.append(rf"L &= {lx(a.lagrangian.expression)}")
    for k, chi in enumerate(a.lagrangian.constraints, start=1):
        rows.append(rf"\chi_{{{k}}} &= {lx(chi)} = 0")
    if a.time is not None:
        rows.append(r"&\text{time-dependent: } \frac{d\Phi}{dt} = \{\Phi, H_T\} + \partial_t \Phi")
    rows.append(rf"H_c &= {lx(a.canonical_hamiltonian)}")
    for k, stage in enumerate(a.stages, start=1):
        title = "primary constraints" if k == 1 else f"stage {k}"
        rows.append(rf"&\text{{{title} ({len(stage)})}}")
        rows.extend(rf"&{lx(c)} = 0" for c in stage)
    sol = a.multiplier_solution
    if a.primary_multipliers and not sol.each_fixed_or_free:
        free = ", ".join(lx(v) for v in sol.free)
        rows.append(rf"&\text{{multipliers: general solution, }} {free} \text{{ free}}")
        for u in a.primary_multipliers:
            rows.append(rf"{lx(u)} &= {lx(sol.general[u.name])}")
        for v, phi in zip(sol.free, sol.first_class_primary):
            rows.append(rf"&\text{{first-class primary combination of }} {lx(v)}: {lx(phi)}")
        rows.append(rf"H_T &= H_c + {lx(sol.total_hamiltonian - sol.canonical_hamiltonian)}")
    elif a.primary_multipliers:
        rows.append(r"&\text{multipliers}")
        for u in a.primary_multipliers:
            if u.name in a.multipliers:
                rows.append(rf"{lx(u)} &= {lx(a.multipliers[u.name])}")
            else:
                rows.append(rf"{lx(u)} &\;\text{{undetermined (gauge)}}")
    rows.extend(_gauge_latex_rows(a))
    for locus in getattr(a, "singular_loci", ()):
        what = locus.what.replace("_", r"\_").replace("^", r"\^{}")
        rows.append(rf"&\text{{singular locus (stage {locus.stage}): }} {lx(locus.expression)} = 0 \text{{: {what}}}")
    rows.append(
        rf"&\text{{first class: {len(a.first_class)}, second class: {len(a.second_class)}, "
        rf"physical degrees of freedom: {a.physical_degrees_of_freedom}}}"
    )
    body = " \\\\\n".join(rows)
    if display:
        return "$$\\begin{aligned}\n" + body + "\n\\end{aligned}$$"
    return "\\begin{align*}\n" + body + "\n\\end{align*}"


def _general_total_hamiltonian(sol: MultiplierSolution) -> str:
    """``H_T = H_c + U_k phi_k + v_a phi_a`` as one text line (the ``U_k = 0`` terms left out)."""
    terms = [
        f"({_short(sol.particular[u.name], 80)})*({_short(phi, 80)})"
        for u, phi in zip(sol.multipliers, sol.primary)
        if sol.particular[u.name] != 0
    ]
    terms += [f"{v}*({_short(phi, 80)})" for v, phi in zip(sol.free, sol.first_class_primary)]
    free = ", ".join(v.name for v in sol.free)
    return f"total Hamiltonian H_T = H_c + {' + '.join(terms) or '0'}   ({free} free: the general solution below)"


def _general_solution_lines(sol: MultiplierSolution) -> list[str]:
    """The general solution ``u = U + v_a V_a`` and the first-class primary combinations."""
    names = [u.name for u in sol.multipliers]
    free = " + ".join(f"{v}*V_{a}" for a, v in enumerate(sol.free, start=1))
    lines = [f"general solution u = U + {free} ({', '.join(v.name for v in sol.free)} free):"]
    lines.append("  particular solution U:")
    lines.extend(f"    {name} = {_short(sol.particular[name])}" for name in names)
    for a, (vec, phi) in enumerate(zip(sol.null_vectors, sol.first_class_primary), start=1):
        components = ", ".join(_short(vec[name], 80) for name in names)
        lines.append(f"  null vector V_{a} = ({components}) of ({', '.join(names)})")
        lines.append(f"    first-class primary combination V_{a}.phi = {_short(phi)}")
    return lines
