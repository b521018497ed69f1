"""Comparing two brackets on the same variables at points of the constraint surface.

The paper's central claim (Sect. XI) is that the Dirac bracket (240) of the rigid body,
written in the variables ``M_k = -eps_kij (R^T p)_ij`` (233) and ``R_ij``, *is* the
Chetaev bracket (248)–(249)::

    {M_i, M_j} = -eps_ijk M_k,   {M_i, R_jk} = -eps_ikm R_jm,   {R_ij, R_ab} = 0.

:func:`compare_brackets` makes such statements checkable for any analysed system: it
evaluates two brackets (:mod:`dirac.analysis.brackets.named_brackets`, built-in ones from
:func:`dirac.analysis.brackets.structures.named_bracket`) at sampled points of the constraint
surface (:func:`surface_points`) and reports, in a :class:`BracketComparison`, where they
agree; the Jacobi residuals and Casimirs (:mod:`dirac.analysis.brackets.casimirs`) are added to
the report by the caller.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import sympy

from dirac.analysis.brackets.casimirs import JACOBI_TOLERANCE
from dirac.analysis.brackets.named_brackets import Bracket
from dirac.errors import InputError

__all__ = ["DEFAULT_TOLERANCE", "BracketComparison", "surface_points", "compare_brackets"]

#: absolute agreement tolerance, relative to max(1, size of the entries)
DEFAULT_TOLERANCE = 1e-10


def surface_points(analysis: Any, count: int, seed: int = 0) -> list[dict[str, float]]:
    """``count`` numeric points of the constraint surface of ``analysis``.

    Uses ``analysis.surface_point(seed=…)`` (Gauss–Newton projection of random points);
    parameters that are still symbolic take their default values, which the brackets
    then use too.
    """
    if count < 1:
        raise InputError(f"number of points = {count}: give at least 1")
    return [dict(analysis.surface_point(seed=seed + k)) for k in range(count)]


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
