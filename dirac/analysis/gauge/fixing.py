"""Gauge fixing: user gauge conditions ``chi_i = 0`` turn first-class constraints second class.

Conditions ``chi_i`` are admissible (Dirac; Henneaux–Teitelboim, chs. 1 and 3) when

1. each fixes something: the matrix ``{chi_i, F_a}`` with the first-class constraints
   ``F_a`` has full row rank on the surface (a condition whose row vanishes commutes with
   every first-class constraint and is refused, naming them);
2. their preservation in time, ``{chi_i, H'} + {chi_i, gamma_f} v_f ~ 0`` on the gauge
   surface (``H_T = H' + v_f gamma_f``, :func:`~dirac.analysis.gauge.generators.first_class_hamiltonian`),
   can be met by choosing the free multipliers ``v_f``, and creates no new constraint.

Then constraints and conditions are classified together; the conditions and the
first-class constraints they fix are second class, the Dirac bracket (240) is taken over
all second-class functions, and the number of physical degrees of freedom,
``(2n - 2 #first - #second)/2``, is that of the unfixed system (checked). With fewer
conditions than first-class constraints the fixing is partial: the first-class
constraints that remain are reported.

Time-dependent gauges (``x^0 - t``; Henneaux–Teitelboim, ch. 4, for the relativistic
particle): a condition may name the time ``t`` when ``t`` is not a coordinate. Its
preservation is then ``d chi/dt = {chi, H'} + {chi, gamma_f} v_f + d_t chi ~ 0`` (the
partial time derivative as in the constraint chain), the multipliers it fixes may depend
on ``t``, and the gauge-fixed analysis is time dependent (:attr:`time` set): its points
carry ``t`` as their last component, and its equations of motion have the explicit-time
term of the Dirac bracket (Gitman–Tyutin), which carries the whole motion in a gauge like
``x^0 = t`` where ``H_c`` is a combination of constraints.
"""

from __future__ import annotations

import ast
import copy
from collections.abc import Sequence
from typing import Any

import numpy as np
import sympy

from dirac.analysis.brackets.dirac_bracket import DiracBracket
from dirac.analysis.chain.constraint_chain import SAMPLE_POINTS
from dirac.analysis.classes.classification import bracket_matrix, classify
from dirac.analysis.core.algebra import tidy
from dirac.analysis.core.linear_solve import weak_solve
from dirac.analysis.core.numeric import ZERO_TOLERANCE, Numerics, numeric_rank
from dirac.analysis.gauge.generators import first_class_hamiltonian, independent
from dirac.errors import AnalysisError, InputError
from dirac.model.expressions import ALLOWED_CONSTANTS, ALLOWED_FUNCTIONS, parse_expression
from dirac.validate import did_you_mean

__all__ = ["fix_gauge", "parse_gauge_condition", "regular_gauge_point"]

#: relative residual below which the preservation equations count as solved
SOLVE_TOLERANCE = 1e-8

#: largest second-class set whose bracket matrix is called small in the report (as for the analysis)
SMALL_SECOND_CLASS = 8

#: rounds of surface points sampled to find regular points of the gauge surface
REGULAR_ROUNDS = 5

#: random starts allowed to find one regular point of a gauge-fixed surface
REGULAR_ATTEMPTS = 20


def parse_gauge_condition(text: str | sympy.Expr, analysis: Any) -> sympy.Expr:
    """A gauge condition as a sympy expression in the phase-space variables of ``analysis``.

    Strings are parsed safely (:func:`~dirac.model.expressions.parse_expression`); names
    are those of ``analysis.symbols`` (``x``, ``p_x``, ``lambda_1``...), the symbolic
    parameters and the time ``t`` (``Lagrangian.time``: unless a coordinate is called ``t``).

    Raises
    ------
    InputError
        For an unknown name (with the closest known names), a syntax error, or an
        expression that involves no phase-space variable.
    """
    names: dict[str, sympy.Symbol] = dict(analysis.symbols)
    names.update({p.name: p for p in analysis.parameters})
    time = analysis.lagrangian.time  # None when a coordinate is called t
    if time is not None and time.name not in names:
        names[time.name] = time
    if isinstance(text, str):
        try:
            tree = ast.parse(text.strip(), mode="eval")
        except SyntaxError:
            tree = None  # parse_expression reports it
        if tree is not None:
            for node in ast.walk(tree):
                if isinstance(node, ast.Name) and node.id not in names and node.id not in ALLOWED_FUNCTIONS \
                        and node.id not in ALLOWED_CONSTANTS:
                    raise InputError(
                        f"gauge condition {text!r}: unknown name {node.id!r}{did_you_mean(node.id, names)}; "
                        f"the phase-space variables are {', '.join(analysis.symbols)}"
                        + (f" and {time} is the time" if time is not None else "")
                    )
        expr = parse_expression(text, names, what="gauge condition")
    else:
        expr = sympy.sympify(text)
        # symbols are matched by name (a plain sympy.Symbol("x") means the variable x)
        expr = expr.xreplace({s: names[s.name] for s in expr.free_symbols if isinstance(s, sympy.Symbol) and s.name in names})
        unknown = sorted(str(s) for s in expr.free_symbols if not (isinstance(s, sympy.Symbol) and names.get(s.name) == s))
        if unknown:
            raise InputError(
                f"gauge condition {expr}: unknown symbol(s) {', '.join(unknown)}"
                f"{did_you_mean(unknown[0], names)}; use the symbols of analysis.symbols"
            )
    if not expr.free_symbols & set(analysis.phase_space):
        raise InputError(f"gauge condition {text!r} involves no phase-space variable: it cannot fix a gauge")
    return expr


def fix_gauge(analysis: Any, conditions: Sequence[str | sympy.Expr] | str | sympy.Expr) -> Any:
    """The analysis of ``analysis`` (a ``ConstraintAnalysis``) with the gauge ``conditions = 0``.

    Parameters
    ----------
    analysis
        The result of :func:`dirac.analyze` for a system with first-class constraints.
    conditions
        Gauge conditions ``chi_i`` (text in the names of ``analysis.symbols``, or sympy
        expressions in those symbols), meant as ``chi_i = 0``.

    Returns
    -------
    ConstraintAnalysis
        A new analysis: ``constraints`` ends with the conditions, ``gauge_conditions``
        lists them as given, ``first_class`` holds the first-class constraints that
        remain (none when the gauge is fixed completely), the multipliers fixed by the
        preservation of the conditions are in ``multipliers``, and ``dirac_bracket`` is
        the Dirac bracket (240) in this gauge. When a condition names the time ``t``,
        ``time`` is ``t`` (the analysis is time dependent; the multipliers may depend on ``t``).

    Raises
    ------
    InputError
        No first-class constraint to fix; a condition that fixes nothing (named, with the
        first-class constraints it commutes with), or nothing more than the others; a
        condition not preserved in time (its time derivative is named, to be added as a
        further condition); conditions without a real common solution with the constraints.
    """
    if isinstance(conditions, (str, sympy.Basic)):
        conditions = [conditions]
    texts = [c if isinstance(c, str) else str(c) for c in conditions]
    if not texts:
        raise InputError("fix_gauge needs at least one gauge condition")
    exprs = [parse_gauge_condition(c, analysis) for c in conditions]
    first = list(analysis.first_class)
    if not first:
        raise InputError(
            f"{analysis.name!r} has no first-class constraints: there is no gauge freedom to fix "
            f"(gauge condition(s) {', '.join(texts)})"
        )
    space = analysis._space
    time = _gauge_time(analysis, exprs)
    numerics = Numerics(space, analysis._generic, seed=20240607, time=time)
    constraints = list(analysis.constraints) + exprs
    pb = space.poisson_bracket
    points, singular = _regular_points(analysis.name, texts, exprs, first, constraints, numerics, pb)
    split = first_class_hamiltonian(analysis)
    solved, remaining = _preserve(analysis, texts, exprs, split, points, numerics, pb, time)
    C = bracket_matrix(space, constraints)
    cls = classify(space, numerics, constraints, points, C)
    dim = space.dimension
    dof2 = dim - 2 * len(cls.first_class) - len(cls.second_class)
    if dof2 != 2 * analysis.physical_degrees_of_freedom:
        raise InputError(
            f"the gauge conditions {', '.join(texts)} change the number of physical degrees of freedom of "
            f"{analysis.name!r} ({analysis.physical_degrees_of_freedom} -> {dof2 / 2:g}): they constrain more "
            "than the gauge; choose conditions that only fix first-class constraints"
        )
    fixed = copy.copy(analysis)
    fixed.constraints = constraints
    fixed.gauge_conditions = tuple(analysis.gauge_conditions) + tuple(texts)
    fixed.time = time
    fixed.first_class = cls.first_class
    fixed.second_class = cls.second_class
    fixed.bracket_matrix_rank = cls.rank
    fixed.multipliers = {**dict(analysis.multipliers), **solved}
    fixed.undetermined_multipliers = [u for u in analysis.primary_multipliers if u.name in remaining]
    fixed._numerics = numerics
    fixed._points = points
    S = cls.second_indices
    C2 = C[S, S] if S else sympy.zeros(0, 0)
    fixed._bracket = DiracBracket(space, cls.second_class, C2, numerics, points, analysis.lagrangian.parameters)
    fixed._defaults_numerics = None
    fixed._gauge = None
    s = len(cls.second_class)
    fixed.bracket_strategy = (
        f"{'symbolic' if s <= SMALL_SECOND_CLASS else 'block'}: C is {s}x{s} over the second-class constraints "
        "and the gauge conditions; exact brackets solve C x = {Phi, B} after dropping weakly zero entries"
        + ("" if s <= SMALL_SECOND_CLASS else ", by its block-triangular pieces")
        + "; numeric brackets (at=) solve C at the point"
    )
    left = ", ".join(str(c) for c in cls.first_class)
    fixed.notes = list(analysis.notes) + [
        f"gauge conditions {', '.join(f'{t} = 0' for t in texts)}: admissible (their brackets with the first-class "
        "constraints have full rank on the surface and their preservation fixes "
        + (", ".join(sorted(solved)) if solved else "no multiplier")
        + ")"
        + (f"; partial gauge fixing, first class still: {left}" if cls.first_class else "; the gauge is fixed completely")
    ]
    if time is not None and analysis.time is None:
        fixed.notes.append(
            "time-dependent gauge: the conditions depend on t, so the gauge-fixed system is time dependent; "
            "their preservation is d chi/dt = {chi, H_T} + d_t chi = 0, points carry t, and the equations of "
            "motion have the explicit-time term of the Dirac bracket"
        )
    if singular:
        fixed.notes.append(
            f"{singular} sampled point(s) of the gauge surface were singular for the gauge (the brackets of the "
            "conditions with the first-class constraints lose rank there) and were left out of the decisions; "
            "the gauge is not valid at such points"
        )
    return fixed


def _gauge_time(analysis: Any, exprs: Sequence[sympy.Expr]) -> sympy.Symbol | None:
    """The time ``t`` of the gauge-fixed system: that of ``analysis`` when it is time dependent,
    else ``t`` when a condition names it (a time-dependent gauge), else ``None``."""
    if analysis.time is not None:
        return analysis.time
    t = analysis.lagrangian.time
    if t is not None and any(t in chi.free_symbols for chi in exprs):
        return t
    return None


def _weak_values(numerics: Numerics, exprs: Sequence[sympy.Expr], points: Sequence[np.ndarray]) -> np.ndarray:
    """Values of ``exprs`` at ``points`` (points, len(exprs)), with entries below ``1e-8`` times the
    size of their terms set to zero: a bracket like ``x + y`` at ``x = y = 1e-13`` vanishes
    there, which a rank relative to the largest entry alone would not see."""
    values = numerics.evaluate(exprs, points)
    scale = np.array([numerics.term_scale(exprs, [z])[0] for z in points]).reshape(values.shape)
    return np.where(np.abs(values) <= ZERO_TOLERANCE * scale, 0.0, values)


def regular_gauge_point(analysis: Any, numerics: Numerics, fixed: dict[int, float]) -> np.ndarray:
    """A point of the gauge-fixed surface of ``analysis`` where the gauge is valid.

    The gauge surface can contain points where the conditions stop fixing the gauge (the
    second-class matrix ``C`` of (240) is singular there, e.g. the origin for a rotation
    gauge); random starts are repeated until ``C`` has full rank.

    Raises
    ------
    InputError
        If every point found (with the ``fixed`` values held) is singular for the gauge.
    AnalysisError
        If no point of the surface is found at all.
    """
    C = list(analysis._bracket.C)
    size = len(analysis.second_class)
    for _ in range(REGULAR_ATTEMPTS):
        point = numerics.surface_points(analysis.constraints, 1, fixed=fixed)[0]
        if not size or numeric_rank(_weak_values(numerics, C, [point]).reshape(size, size)) == size:
            return point
    raise InputError(
        f"every point found on the gauge surface of {analysis.name!r} with the given values is singular for the "
        f"gauge conditions {', '.join(analysis.gauge_conditions)} (their brackets with the first-class "
        "constraints lose rank there): the gauge is not valid at these values; give other values"
    )


def _regular_points(name, texts, exprs, first, constraints, numerics, pb) -> tuple[list[np.ndarray], int]:
    """Points of the gauge surface where ``{chi_i, F_a}`` has full row rank, and how many sampled points were not.

    Refuses a condition whose brackets with all first-class constraints vanish at every
    sampled point, and one that fixes nothing the others do not fix (rank below the
    number of conditions at every point). A gauge can be singular on part of its surface
    (e.g. ``y = 0`` for rotations at ``x = 0``): such points are left out of the decisions
    and counted.
    """
    flat = [pb(chi, F) for chi in exprs for F in first]
    c, F = len(exprs), len(first)
    listed = ", ".join(str(f) for f in first)
    sampled: list[np.ndarray] = []
    regular: list[np.ndarray] = []
    for _ in range(REGULAR_ROUNDS):
        try:
            batch = numerics.surface_points(constraints, SAMPLE_POINTS)
        except AnalysisError:
            raise InputError(
                f"the gauge conditions {', '.join(texts)} have no real solution together with the constraints of "
                f"{name!r}: choose conditions that meet the constraint surface"
            ) from None
        sampled += batch
        values = _weak_values(numerics, flat, batch).reshape(len(batch), c, F)
        regular += [z for z, m in zip(batch, values) if numeric_rank(m) == c]
        if len(regular) >= SAMPLE_POINTS:
            break
    values = numerics.evaluate(flat, sampled).reshape(len(sampled), c, F)
    zero = numerics.weakly_zero(flat, sampled).reshape(c, F)
    for text, z in zip(texts, zero):
        if np.all(z):
            raise InputError(
                f"gauge condition {text!r} fixes nothing: its bracket with every first-class constraint "
                f"({listed}) vanishes on the surface, so it fixes none of them; choose a condition that "
                "changes under the gauge transformations"
            )
    if not regular:
        best = max(values, key=numeric_rank)
        kept = independent([best], list(range(c)))
        text = next(t for i, t in enumerate(texts) if i not in kept)
        raise InputError(
            f"gauge condition {text!r} fixes nothing the other conditions do not fix already (its brackets "
            f"with the first-class constraints {listed} depend on theirs): drop it or choose another"
        )
    return regular[:SAMPLE_POINTS], len(sampled) - len(regular)


def _preserve(analysis, texts, exprs, split, points, numerics, pb, time=None) -> tuple[dict[str, sympy.Expr], set[str]]:
    """Solve ``{chi, H'} + {chi, gamma_f} v_f + d_t chi ~ 0`` for the free multipliers.

    ``d_t chi`` is the partial derivative by the time ``time`` (none when ``time`` is
    ``None``); the solved multipliers may then depend on ``t``.

    Returns ``(solved, remaining)``: multiplier name -> expression for every multiplier
    that the preservation fixes (the free ``u_f = v_f`` and the ``u_q = U_q + v_f V_fq``
    that depend on them), and the names of the multipliers that stay free.

    Raises
    ------
    InputError
        When a condition's time derivative cannot be made to vanish by the free multipliers.
    """
    space = analysis._space
    variables = space.variables
    names = [u.name for u in analysis.primary_multipliers]
    gammas = split.primary_first_class
    H1 = split.hamiltonian
    c, F = len(exprs), len(gammas)
    e_sym = [pb(chi, H1) + (sympy.diff(chi, time) if time is not None else sympy.S.Zero) for chi in exprs]
    B_sym = sympy.Matrix(c, F, lambda i, f: pb(exprs[i], gammas[f]))
    zero = numerics.weakly_zero(list(B_sym), points) if F else []
    B_sym = sympy.Matrix(c, F, lambda i, f: sympy.S.Zero if zero[i * F + f] else B_sym[i, f])
    e_num = numerics.evaluate(e_sym, points).reshape(len(points), c)
    B_num = numerics.evaluate(list(B_sym), points).reshape(len(points), c, F) if F else np.zeros((len(points), c, 0))
    bad = np.zeros(c, dtype=bool)
    for e, B in zip(e_num, B_num):
        best = np.linalg.lstsq(B, -e, rcond=None)[0] if F else np.zeros(0)
        residual = e + B @ best
        scale = 1.0 + np.abs(e) + (np.abs(B) @ np.abs(best) if F else 0.0)
        bad |= np.abs(residual) > SOLVE_TOLERANCE * scale
    if np.any(bad):
        i = int(np.argmax(bad))
        zero_row = F == 0 or bool(numerics.weakly_zero(list(B_sym[i, :]), points).all())
        derivative = tidy(e_sym[i], variables)
        kind = "time-dependent gauge condition" if time is not None and time in exprs[i].free_symbols else "gauge condition"
        if zero_row:
            raise InputError(
                f"{kind} {texts[i]!r} is not preserved in time: its time derivative {derivative} does not "
                "vanish on the gauge surface and no free multiplier enters it; add it as a further gauge condition "
                f"(--gauge '{derivative}')"
            )
        raise InputError(
            f"gauge conditions {', '.join(texts)} are not preserved in time: the free multipliers cannot make the "
            f"time derivative {derivative} of {texts[i]!r} vanish on the gauge surface; choose other conditions"
        )
    if F == 0:
        return {}, set()
    free_names = [names[f] for f in split.free]
    rows = independent(list(B_num), list(range(c)))
    cols = independent([B[rows].T for B in B_num], list(range(F))) if rows else []
    rest = [f for f in range(F) if f not in cols]
    v: dict[int, sympy.Expr] = {f: sympy.Symbol(free_names[f], real=True) for f in rest}
    if cols:
        # right-hand sides: -e, then -B_f for each multiplier f that stays free (a symbol)
        cols_sym = [sympy.Matrix([-e_sym[i] for i in rows])] + [sympy.Matrix([-B_sym[i, f] for i in rows]) for f in rest]
        cols_num = [[-e[rows].reshape(-1, 1) for e in e_num]] + [[-B[rows, f].reshape(-1, 1) for B in B_num] for f in rest]
        rhs = sympy.Matrix.hstack(*cols_sym)
        rhs_num = [np.hstack([column[k] for column in cols_num]) for k in range(len(points))]
        x = weak_solve(B_sym[rows, cols], rhs, [B[np.ix_(rows, cols)] for B in B_num], rhs_num, variables=variables)
        for r, f in enumerate(cols):
            v[f] = tidy(x[r, 0] + sum((x[r, j + 1] * v[g] for j, g in enumerate(rest)), sympy.S.Zero), variables)
    solved: dict[str, sympy.Expr] = {}
    for f in cols:
        solved[free_names[f]] = v[f]
    for q, U in split.particular.items():
        value = U + sum((split.null_vectors[split.free[f]].get(q, sympy.S.Zero) * v[f] for f in range(F)), sympy.S.Zero)
        if any(split.null_vectors[split.free[f]].get(q, 0) != 0 for f in cols):
            solved[names[q]] = tidy(value, variables)
    return solved, {free_names[f] for f in rest}
