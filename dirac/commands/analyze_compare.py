"""``dirac analyze SYSTEM --compare SPEC``: compare two brackets of the analysed system.

SPEC is ``FIRST,SECOND`` or ``FIRST,SECOND:N`` (bracket names of
:data:`dirac.analysis.brackets.structures.BRACKET_NAMES`, ``N`` sampled points of the constraint
surface). The comparison itself is :func:`dirac.analysis.brackets.comparison.compare_brackets`.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from typing import Any

from dirac.analysis.brackets.casimirs import casimirs, jacobi_residual
from dirac.analysis.brackets.comparison import compare_brackets, surface_points
from dirac.analysis.brackets.named_brackets import StructureBracket, analysis_variables
from dirac.analysis.brackets.structures import BRACKET_NAMES, named_bracket
from dirac.errors import AnalysisError, InputError

__all__ = ["DEFAULT_POINTS", "parse_spec", "cli_compare"]

#: default number of sampled surface points of ``--compare``
DEFAULT_POINTS = 20


def parse_spec(spec: str) -> tuple[list[str], int]:
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


def cli_compare(analysis: Any, spec: str, as_json: bool, progress: Callable[[str], None] | None = None) -> str:
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
    progress
        Called with one line, with its seconds, as each phase of the comparison finishes.

    Raises
    ------
    InputError
        For a malformed SPEC or a bracket that does not apply to the system.
    """
    names, count = parse_spec(spec)
    clock = [time.perf_counter()]

    def done(message: str) -> None:
        if progress is not None:
            now = time.perf_counter()
            progress(f"{message} ({now - clock[0]:.2f} s)")
            clock[0] = now

    variables = analysis_variables(analysis)
    first = named_bracket(names[0], analysis, variables)
    second = named_bracket(names[1], analysis, variables)
    done(f"compare: brackets {names[0]} and {names[1]} built")
    points = surface_points(analysis, count)
    done(f"compare: {len(points)} point(s) of the constraint surface sampled")
    comparison = compare_brackets(first, second, points)
    done("compare: brackets compared at the points")
    for bracket in (first, second):
        try:
            comparison.jacobi[bracket.name] = jacobi_residual(bracket, points[:5])
        except AnalysisError as exc:
            comparison.jacobi[bracket.name] = f"not checked ({exc})"
        if isinstance(bracket, StructureBracket) and bracket.is_linear:
            comparison.casimirs[bracket.name] = [str(c) for c in casimirs(bracket)]
        done(f"compare: Jacobi identity{' and Casimirs' if bracket.name in comparison.casimirs else ''} of {bracket.name} checked")
    if as_json:
        return json.dumps(comparison.to_dict(), indent=2)
    return comparison.to_text()
