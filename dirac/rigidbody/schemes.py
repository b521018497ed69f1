"""The Lie–Poisson composition schemes of the free rigid body as data, and the sub-step
sequence of one composed step: what the method registry and ``auto`` need, without
importing numba (the kernels that run the sequence are in
:mod:`dirac.rigidbody.splitting`, whose docstring describes the splittings).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dirac.compositions import COMPOSITIONS
from dirac.errors import InputError

__all__ = ["CompositionScheme", "SCHEMES", "build_sequence"]


@dataclass(frozen=True)
class CompositionScheme:
    """A symmetric composition of a symmetric (Strang) base step, as data.

    Attributes
    ----------
    name : str
        Method name (docs/integrators.md), e.g. ``"lie-poisson-4"``.
    order : int
        Classical order of the composed method.
    coefficients : tuple of float
        Step fractions ``gamma_1, ..., gamma_s`` (palindromic, ``sum = 1``).
    splitting : str
        ``"axes"`` (3-term split) or ``"symmetric"`` (symmetric-top split).
    reference : str
        Source of the coefficients.
    """

    name: str
    order: int
    coefficients: tuple[float, ...]
    splitting: str = "axes"
    reference: str = ""


def _make_schemes() -> dict[str, CompositionScheme]:
    schemes: dict[str, CompositionScheme] = {}
    for suffix, order, coefficients, reference in COMPOSITIONS:
        for splitting, prefix in (("axes", "lie-poisson-"), ("symmetric", "lie-poisson-sym-")):
            name = prefix + suffix
            schemes[name] = CompositionScheme(name, order, coefficients, splitting, reference)
    return schemes


#: Every named Lie–Poisson method: ``lie-poisson-{2,4,6,8}`` (3-term split) and extras
#: (``lie-poisson-4-suzuki``, ``lie-poisson-8-s15``, ``lie-poisson-sym-*``).
SCHEMES: dict[str, CompositionScheme] = _make_schemes()


def _middle_axis(inv_inertia: np.ndarray) -> int:
    order = np.argsort(inv_inertia, kind="stable")
    return int(order[1])


def build_sequence(
    inv_inertia: np.ndarray,
    coefficients: tuple[float, ...],
    splitting: str = "axes",
    casimir_axis: int | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """The merged sub-step sequence of one composed step.

    Parameters
    ----------
    inv_inertia : numpy.ndarray, shape (3,)
        ``1 / I_i``.
    coefficients : tuple of float
        Composition fractions ``gamma``.
    splitting : {"axes", "symmetric"}
        Which splitting (module docstring).
    casimir_axis : int, optional
        The axis ``a`` of the symmetric split; default: the middle moment.

    Returns
    -------
    axes : numpy.ndarray of int64, shape (L,)
        Body axis of each sub-step; the first and the last are the same axis.
    rates : numpy.ndarray, shape (L,)
        Rotation rate per unit ``M_k`` (``1/I_k`` or ``1/I_k - 1/I_a``).
    fractions : numpy.ndarray, shape (L,)
        Sub-step lengths as fractions of the step ``dt``.
    casimir_rate : float
        ``1/I_a`` for the symmetric split, 0 for the 3-term split.
    """
    inv = np.asarray(inv_inertia, dtype=float)
    base: tuple[tuple[int, float], ...]
    if splitting == "axes":
        base = ((0, 0.5), (1, 0.5), (2, 1.0), (1, 0.5), (0, 0.5))
        rate_of = {k: float(inv[k]) for k in range(3)}
        casimir_rate = 0.0
    elif splitting == "symmetric":
        a = _middle_axis(inv) if casimir_axis is None else int(casimir_axis)
        b, c = [k for k in range(3) if k != a]
        base = ((b, 0.5), (c, 1.0), (b, 0.5))
        rate_of = {k: float(inv[k] - inv[a]) for k in (b, c)}
        casimir_rate = float(inv[a])
    else:
        raise InputError(f"splitting = {splitting!r} is unknown; use 'axes' or 'symmetric'")
    merged: list[list[float]] = []
    for gamma in coefficients:
        for axis, fraction in base:
            if merged and merged[-1][0] == axis:
                merged[-1][1] += gamma * fraction
            else:
                merged.append([axis, gamma * fraction])
    axes = np.array([int(entry[0]) for entry in merged], dtype=np.int64)
    fractions = np.array([entry[1] for entry in merged], dtype=float)
    rates = np.array([rate_of[int(axis)] for axis in axes], dtype=float)
    return axes, rates, fractions, casimir_rate
