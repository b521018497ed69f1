"""``dirac.analyze``: a :class:`~dirac.model.lagrangian.Lagrangian` to the engine, a
:class:`~dirac.fields.theory.FieldTheory` mode by mode (:mod:`dirac.fields.analysis`).

The engine (:func:`dirac.analysis.components.analyze`) never sees a field theory: this
function, one layer above it, chooses the road.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from dirac.fields.theory import FieldTheory

__all__ = ["analyze"]


def analyze(
    system: Any,
    progress: Callable[[str], None] | None = None,
    assume: Sequence[str] = (),
    cases: bool = False,
    **options: Any,
) -> Any:
    """Run the Dirac–Bergmann algorithm on a Lagrangian, or on a field theory mode by mode.

    Parameters
    ----------
    system
        A :class:`dirac.Lagrangian` (see :func:`dirac.analysis.components.analyze` for
        ``progress``, ``assume``, ``cases`` and any further keyword ``options``, passed on
        unchanged), or a :class:`dirac.FieldTheory` whose
        density is quadratic with constant coefficients: then a
        :class:`~dirac.fields.analysis.FieldAnalysis` with the counts per spatial point,
        constraints in position space, gauge transformations and the special wave vectors
        (always ``k = 0``) as its parameter cases (docs/field_theories.md).

    Examples
    --------
    >>> import dirac
    >>> kg = dirac.FieldTheory.from_strings("klein_gordon", ["x"], ["phi"],
    ...     "phi_t**2/2 - phi_x**2/2 - m**2*phi**2/2", parameters={"m": 1.0})
    >>> dirac.analyze(kg).physical_degrees_of_freedom
    1
    """
    if isinstance(system, FieldTheory):
        from dirac.errors import InputError
        from dirac.fields.analysis import analyze_field_theory

        if assume or options:
            raise InputError(f"{'assume=' if assume else ', '.join(options) + '='} is for mechanical systems; a field "
                             "theory is analysed for a generic wave vector with its special wave vectors as cases")
        return analyze_field_theory(system, progress=progress)
    from dirac.analysis.components import analyze as analyze_lagrangian

    return analyze_lagrangian(system, progress=progress, assume=assume, cases=cases, **options)
