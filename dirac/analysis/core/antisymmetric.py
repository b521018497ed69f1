"""Values of an antisymmetric matrix of expressions from the entries above its diagonal.

The bracket matrix ``C_ab = {Phi_a, Phi_b}`` is antisymmetric as a matrix of functions:
``{Phi_b, Phi_a} = -{Phi_a, Phi_b}`` for the canonical bracket of
:meth:`~dirac.analysis.core.phase_space.PhaseSpace.poisson_bracket` (``C_ba`` is built
as the negated ``C_ab`` by :func:`~dirac.analysis.classes.classification.bracket_matrix`).
Its entries below the diagonal need not be compiled nor evaluated: each is the exact
negative of its mirror's value (negation is exact in floating point), and the sizes of
its terms are its mirror's. The compiled text of ``C`` is halved; the bracket matrix was
the largest batch an analysis compiled ((228): 174 entries, 0.23 s of printing and
``compile``; (19): 287 entries, 0.24 s; measured by wrapping ``scaled_function`` in a
fresh process).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = ["mirrored"]


def mirrored(where: Sequence[tuple[int, int]]) -> tuple[list[int], np.ndarray, np.ndarray] | None:
    """How to read entries at positions ``where`` off those above the diagonal, or ``None``.

    Returns ``(upper, pick, sign)``: ``upper`` the indices into ``where`` of the entries
    above the diagonal; entry ``k`` of ``where`` has the value ``sign[k] * u[pick[k]]``
    where ``u`` are the values of the ``upper`` entries, in their order. ``None`` when an
    entry lies on the diagonal or its mirror is not among ``where`` (not the non-zero
    pattern of an antisymmetric matrix): then every entry must be evaluated as it is.
    """
    present = set(where)
    if any(i == j or (j, i) not in present for i, j in where):
        return None
    upper = [k for k, (i, j) in enumerate(where) if i < j]
    column = {where[k]: n for n, k in enumerate(upper)}
    pick = np.array([column[(i, j)] if i < j else column[(j, i)] for i, j in where], dtype=np.intp)
    sign = np.array([1.0 if i < j else -1.0 for i, j in where])
    return upper, pick, sign
