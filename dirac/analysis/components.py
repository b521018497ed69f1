"""Components: a constraint surface with parts of different structure, analysed part by part.

Two refusals of the analysis name parts that can be told apart
(:class:`~dirac.errors.SeparableParts`):

* a holonomic constraint ``chi = f g = 0`` whose branches ``f = 0`` and ``g = 0`` cross
  (``x**2 - y**2``: the lines ``x - y = 0`` and ``x + y = 0`` meet at the origin, where the
  gradient of ``chi`` vanishes). Each branch is a regular constraint of its own; the part
  ``f = 0`` is the system with ``chi`` replaced by ``f`` (on ``f = 0`` away from the
  crossing, ``grad chi = g grad f`` with ``g != 0``: the same surface, the multiplier
  rescaled by ``g``);
* a rank of the bracket matrix ``C_ab = {Phi_a, Phi_b}`` (240) that differs between sample
  points of the surface. The points are grouped by rank; the phase-space variables that
  vanish at every point of one group and not at every point of the others name the part
  (light-cone SU(2) Yang–Mills mechanics: ``A_-^a = 0`` at every point where the rank is 6).
  Each part is analysed with the assumption that picks it (``sum v**2 != 0``: sample points
  away from the other part; each ``v = 0``: imposed as constraints, so that the chain keeps
  the motions that stay in the part; :mod:`dirac.analysis.chain.assumptions`). A part whose
  own analysis is refused is listed with the reason.

Where no separating condition is found, the refusal stands (it names the parts).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import sympy

from dirac.analysis.constraint_analysis import ConstraintAnalysis, at_given_values
from dirac.analysis.constraint_analysis import analyze as analyze_one_part
from dirac.analysis.report import structure_json, structure_summary
from dirac.errors import DiracError, SeparableParts, warn
from dirac.model.lagrangian import Lagrangian
from dirac.model.lagrangian import Lagrangian as _Lagrangian

__all__ = ["Component", "analyze", "analyze_components", "separating_assumptions"]

#: a variable counts as vanishing at a point below this size (relative to the point's largest entry)
ZERO_AT_POINT = 1e-8


@dataclass
class Component:
    """One part of the constraint surface: its ``condition`` and its analysis (or why there is none)."""

    condition: str
    analysis: Any
    error: str | None = None

    def to_json(self) -> dict:
        """``{"condition", "stages", "first_class", "second_class", "physical_degrees_of_freedom"}`` or ``{"condition", "error"}``."""
        if self.analysis is None:
            return {"condition": self.condition, "error": self.error}
        # only the structure (not analysis.to_json(): the first part is the top-level analysis, and a
        # part's gauge generators or multipliers are not asked for here)
        return {"condition": self.condition, **structure_json(self.analysis)}

    def summary(self) -> str:
        """One line: stage sizes and counts, or the refusal."""
        if self.analysis is None:
            return f"not analysed: {self.error}"
        return structure_summary(self.analysis)


def separating_assumptions(error: SeparableParts) -> list[tuple[str, list[str]]] | None:
    """``(condition, assumptions)`` per part for a rank that differs between points, or ``None``.

    The variables that vanish (below ``ZERO_AT_POINT`` times the point's largest entry) at
    every point of the group with the most zeros, and not at every other point, define the
    parts ``sum v**2 != 0`` and ``v = 0`` (each ``v``).
    """
    if not error.points or len(set(error.ranks)) < 2:
        return None
    points = np.asarray(error.points, dtype=float)
    small = np.abs(points) <= ZERO_AT_POINT * (1.0 + np.max(np.abs(points), axis=1, keepdims=True))
    best: list[int] = []
    for rank in sorted(set(error.ranks)):
        group = np.array([r == rank for r in error.ranks])
        zero_here = np.all(small[group], axis=0) & ~np.all(small[~group], axis=0)
        found = [int(i) for i in np.flatnonzero(zero_here)]
        if len(found) > len(best):
            best = found
    if not best:
        return None
    half = len(error.variables) // 2  # the phase space is the coordinates, then their momenta
    if any(i < half for i in best):  # momenta that vanish there follow from the constraints: name the coordinates
        best = [i for i in best if i < half]
    names = [error.variables[i] for i in best]
    total = sympy.Add(*[v**2 for v in names])
    return [
        (f"{total} != 0", [f"{total} != 0"]),
        (" = ".join(str(v) for v in names) + " = 0", [f"{v} = 0" for v in names]),
    ]


def _analyse(analyse: Callable[[Lagrangian, Sequence[str]], Any], lagrangian: Lagrangian, assume: Sequence[str]) -> tuple[Any, str | None]:
    try:
        return analyse(lagrangian, assume), None
    except DiracError as exc:
        return None, str(exc)


def analyze_components(lagrangian: Lagrangian, error: SeparableParts, analyse: Callable[[Lagrangian, Sequence[str]], Any]) -> Any:
    """Analyse each part named by ``error``; the first part's analysis, with :attr:`components` set.

    ``analyse(lagrangian, assume)`` is the analysis of one part (a
    :class:`~dirac.analysis.constraint_analysis.ConstraintAnalysis`; passed in, so that this
    module does not import the one that calls it).

    Raises ``error`` again where the parts cannot be separated, or where no part could be
    analysed.

    Warns
    -----
    DiracWarning
        Naming every part: the counts at the top level are those of the first part.
    """
    components: list[Component] = []
    if error.holonomic is not None and error.branches:
        k = error.holonomic - 1
        for branch in error.branches:
            constraints = list(lagrangian.constraints)
            constraints[k] = branch
            part = replace(lagrangian, constraints=tuple(constraints))
            analysis, why = _analyse(analyse, part, ())
            components.append(Component(f"{branch} = 0", analysis, why))
    else:
        parts = separating_assumptions(error)
        if parts is None:
            raise error
        for condition, assume in parts:
            analysis, why = _analyse(analyse, lagrangian, assume)
            components.append(Component(condition, analysis, why))
    analysed = [c for c in components if c.analysis is not None]
    if not analysed:
        shown = "; ".join(f"{c.condition}: {c.error}" for c in components)
        raise SeparableParts(f"{error}; no part could be analysed on its own ({shown})", points=error.points,
                             ranks=error.ranks, variables=error.variables, holonomic=error.holonomic,
                             branches=error.branches) from error
    first = analysed[0].analysis
    shown = "; ".join(f"{c.condition}: {c.summary()}" for c in components)
    kind = "crossing branches" if error.holonomic is not None else "parts of different structure"
    message = (
        f"the constraint surface of {lagrangian.name!r} has {len(components)} {kind} ({shown}), analysed one by one; "
        f"the counts shown are those of the part {analysed[0].condition}, every part is listed under components"
    )
    first.notes.append(message)
    first.components = components
    warn(message)
    return first


def analyze(
    lagrangian: Lagrangian,
    progress: Callable[[str], None] | None = None,
    assume: Sequence[str] = (),
    cases: bool = False,
) -> ConstraintAnalysis:
    """``dirac.analyze``: :func:`dirac.analysis.constraint_analysis.analyze`, part by part where the surface has parts.

    Parameters
    ----------
    lagrangian, progress, assume
        As for :func:`dirac.analysis.constraint_analysis.analyze`; ``assume`` (``"EXPR != 0"``,
        ``"EXPR = 0"``) picks a part of the phase space.
    cases
        Also build the parameter case tree (:func:`dirac.analysis.cases.parameter_cases`):
        then ``analysis.parameter_cases`` holds it.

    Returns
    -------
    ConstraintAnalysis
        Where the constraint surface has crossing branches (and no assumption is given),
        the analysis of the first branch, with every branch in ``.components`` and a
        warning; likewise for a surface whose parts differ in rank (each part analysed
        with the assumption that picks it, a part that cannot be analysed listed with the
        reason).

    Examples
    --------
    >>> import dirac
    >>> line = dirac.Lagrangian.from_strings("cross", ["x", "y"], "(x_dot**2 + y_dot**2)/2 - y", ["x**2 - y**2"])
    >>> import warnings
    >>> with warnings.catch_warnings():
    ...     warnings.simplefilter("ignore")
    ...     a = dirac.analyze(line)
    >>> [(c.condition, c.analysis.physical_degrees_of_freedom) for c in a.components]
    [('x + y = 0', 1), ('x - y = 0', 1)]
    """
    if isinstance(assume, str):
        assume = [assume]
    try:
        analysis = analyze_one_part(lagrangian, progress=progress, assume=assume)
    except SeparableParts as error:
        if assume or not isinstance(lagrangian, _Lagrangian):
            raise
        analysis = analyze_components(
            lagrangian, error, lambda part, conditions: at_given_values(ConstraintAnalysis(part, progress=progress, assume=conditions), progress)
        )
    if cases:
        from dirac.analysis.cases import parameter_cases

        analysis.parameter_cases = parameter_cases(analysis, progress=progress)
    return analysis
