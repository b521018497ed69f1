"""The canonical phase space of the extended Lagrangian and its Poisson bracket.

The multipliers of the holonomic constraints are coordinates (the paper's extended
Lagrangian (1)), so the phase space is ``(q, lambda; p_q, p_lambda)`` with the canonical
bracket ``{q_i, p_j} = delta_ij`` used throughout Sect. X ((207)-(209)).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field

import sympy

from dirac.analysis.core.fast_partials import PolynomialPartials

__all__ = ["PhaseSpace"]


@dataclass
class PhaseSpace:
    """Canonical coordinates and momenta, with a cached canonical Poisson bracket.

    Parameters
    ----------
    coordinates
        Configuration coordinates: the Lagrangian's ``q`` then the multipliers
        ``lambda_1, ...``.
    momenta
        Their conjugate momenta ``p_q``, ``p_lambda_1``, ... in the same order.
    parameters
        Parameter symbols that are still symbolic (constants under the bracket).
    """

    coordinates: tuple[sympy.Symbol, ...]
    momenta: tuple[sympy.Symbol, ...]
    parameters: tuple[sympy.Symbol, ...] = ()
    _gradients: dict[sympy.Expr, tuple[dict, dict]] = field(default_factory=dict, repr=False)
    _polynomials: PolynomialPartials | None = field(default=None, repr=False)

    @property
    def variables(self) -> tuple[sympy.Symbol, ...]:
        """``coordinates + momenta``: the order of every numeric phase-space vector."""
        return self.coordinates + self.momenta

    @property
    def dimension(self) -> int:
        """Dimension ``2n`` of the phase space."""
        return 2 * len(self.coordinates)

    @property
    def symbols(self) -> dict[str, sympy.Symbol]:
        """Name -> symbol of every phase-space variable (names: docs/conventions.md)."""
        return {s.name: s for s in self.variables}

    def partials(self, expr: sympy.Expr) -> tuple[dict, dict]:
        """Non-zero partial derivatives of ``expr``: ``({q_i: df/dq_i}, {q_i: df/dp_i})``.

        Both dictionaries are keyed by the coordinate, so the bracket pairs them up.
        Results are cached (constraints are differentiated many times). Polynomials in
        the variables are differentiated in the sparse polynomial ring
        (:mod:`dirac.analysis.core.fast_partials`, the same derivatives, expanded), other
        expressions by ``sympy.diff``.
        """
        expr = sympy.sympify(expr)
        cached = self._gradients.get(expr)
        if cached is not None:
            return cached
        if self._polynomials is None:
            self._polynomials = PolynomialPartials(self.variables, self.parameters)
        found = self._polynomials.partials(expr, self.variables)
        if found is not None:
            pairs = list(zip(self.coordinates, self.momenta))
            fast = ({q: found[q] for q, _ in pairs if q in found}, {q: found[p] for q, p in pairs if p in found})
            self._gradients[expr] = fast
            return fast
        free = expr.free_symbols
        dq: dict = {}
        dp: dict = {}
        for q, p in zip(self.coordinates, self.momenta):
            if q in free:
                d = sympy.diff(expr, q)
                if d != 0:
                    dq[q] = d
            if p in free:
                d = sympy.diff(expr, p)
                if d != 0:
                    dp[q] = d
        self._gradients[expr] = (dq, dp)
        return dq, dp

    def poisson_bracket(self, f: sympy.Expr, g: sympy.Expr) -> sympy.Expr:
        """Canonical Poisson bracket ``{f, g} = sum_i df/dq_i dg/dp_i - df/dp_i dg/dq_i``.

        The sign convention is the paper's: ``{q_i, p_j} = delta_ij`` and
        ``z_dot = {z, H}`` (Sect. X, below (207)). The result is not simplified.
        """
        fq, fp = self.partials(f)
        gq, gp = self.partials(g)
        terms = [fq[q] * gp[q] for q in fq if q in gp]
        terms += [-fp[q] * gq[q] for q in fp if q in gq]
        return sympy.Add(*terms)

    def gradient(self, expr: sympy.Expr) -> list[sympy.Expr]:
        """Full gradient of ``expr`` in the order of :attr:`variables`."""
        dq, dp = self.partials(expr)
        return [dq.get(q, sympy.S.Zero) for q in self.coordinates] + [dp.get(q, sympy.S.Zero) for q in self.coordinates]

    def check_names(self, values: Mapping[str, float] | Iterable[str], what: str) -> None:
        """Raise :class:`~dirac.errors.InputError` for a name that is not a variable or parameter."""
        from dirac.errors import InputError

        known = set(self.symbols) | {p.name for p in self.parameters}
        unknown = sorted(set(values) - known)
        if unknown:
            raise InputError(
                f"{what}: unknown name(s) {', '.join(unknown)}; the phase-space variables are "
                f"{', '.join(self.symbols)}"
            )
