"""Partial derivatives of polynomial expressions in a sparse polynomial ring.

``sympy.diff`` rebuilds and re-checks the assumptions of every sub-expression it
touches; for the polynomial expressions of most mechanical systems (constraints,
Hamiltonians, brackets of polynomials) differentiating the same expression as an element
of the sparse ring ``QQ[variables, parameters]`` and converting the non-zero partials
back costs one to two orders of magnitude less. The result is the same polynomial
(expanded); anything that is not a polynomial in the ring's generators (``sin``,
denominators with variables, ``sqrt`` ...) is left to ``sympy.diff`` by the caller.
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy
from sympy.polys.rings import PolyElement, PolyRing

__all__ = ["PolynomialPartials"]


class _NotPolynomial(Exception):
    """The expression is not a polynomial in the ring's generators."""


class PolynomialPartials:
    """Differentiate polynomials in the ``variables`` as elements of a sparse ring over ``QQ``.

    Parameters
    ----------
    variables
        The symbols to differentiate by (phase-space variables, or coordinates and
        velocities): an expression must be a polynomial in them.
    parameters
        Symbols that may occur in the coefficients, in any form (``1/m``, ``sqrt(g)``):
        parameters are extra generators of the ring and any other variable-free piece
        (``1/m``) becomes a generator of its own for the duration of one call, so the
        coefficients stay in ``QQ`` (no rational-function arithmetic). An expression with
        any other symbol, a variable in a denominator or a non-polynomial function of the
        variables is not a polynomial here (:meth:`partials` returns ``None``).
    """

    def __init__(self, variables: Sequence[sympy.Symbol], parameters: Sequence[sympy.Symbol] = ()) -> None:
        self.variables = tuple(variables)
        self.parameters = tuple(parameters)
        self._variable_set = frozenset(self.variables)
        self._allowed = self._variable_set | set(self.parameters)

    def _atoms(self, e: sympy.Expr, found: dict, seen: set) -> None:
        """Variable-free pieces of ``e`` that are not polynomials in the parameters (``1/m``)."""
        if e in seen:
            return
        seen.add(e)
        if e.is_Symbol or e.is_Rational:
            return
        if not (e.free_symbols & self._variable_set):
            if e.is_Add or e.is_Mul or (e.is_Pow and e.exp.is_Integer and e.exp >= 0):
                for a in e.args:
                    self._atoms(a, found, seen)
            elif e not in found:
                found[e] = sympy.Dummy(f"a{len(found)}")
            return
        if e.is_Add or e.is_Mul or (e.is_Pow and e.exp.is_Integer and e.exp >= 0):
            for a in e.args:
                self._atoms(a, found, seen)
            return
        raise _NotPolynomial

    def _walk(self, e: sympy.Expr, gens: dict, ring: PolyRing, cache: dict) -> PolyElement:
        hit = cache.get(e)
        if hit is not None:
            return hit
        if e in gens:
            out = gens[e]
        elif e.is_Rational:
            out = ring.ground_new(sympy.QQ(int(e.p), int(e.q)))
        elif e.is_Add:
            out = ring.zero
            for a in e.args:
                out = out + self._walk(a, gens, ring, cache)
        elif e.is_Mul:
            out = ring.one
            for a in e.args:
                out = out * self._walk(a, gens, ring, cache)
        elif e.is_Pow and e.exp.is_Integer and e.exp >= 0:
            out = self._walk(e.base, gens, ring, cache) ** int(e.exp)
        else:
            raise _NotPolynomial
        cache[e] = out
        return out

    def element(self, expr: sympy.Expr) -> tuple[PolyElement, list[sympy.Symbol], dict] | None:
        """``(p, variables, back)``: ``expr`` in the ring of the variables it contains, or ``None``.

        ``variables`` are the ring's first generators (the variables ``expr`` contains, in
        the order given at construction); ``back`` maps the generators that stand for
        variable-free pieces (``1/m``) back to them (:meth:`to_expr`).
        """
        expr = sympy.sympify(expr)
        free = expr.free_symbols
        if not free <= self._allowed:
            return None
        atoms: dict = {}
        try:
            self._atoms(expr, atoms, set())
        except _NotPolynomial:
            return None
        variables = [v for v in self.variables if v in free]
        params = sorted((free - self._variable_set), key=lambda s: s.name)
        symbols = [*variables, *params]
        ring = PolyRing([*symbols, *atoms.values()], sympy.QQ)
        gens = dict(zip([*symbols, *atoms], ring.gens))
        try:
            p = self._walk(expr, gens, ring, {})
        except (_NotPolynomial, ZeroDivisionError, TypeError, ValueError, sympy.CoercionFailed, sympy.PolynomialError):
            return None
        return p, variables, {d: a for a, d in atoms.items()}

    @staticmethod
    def to_expr(p: PolyElement, back: dict) -> sympy.Expr:
        """A ring element as a sympy expression (the stand-in generators replaced back)."""
        value = p.as_expr()
        return value.xreplace(back) if back else value

    def partials(self, expr: sympy.Expr, wanted: Sequence[sympy.Symbol]) -> dict[sympy.Symbol, sympy.Expr] | None:
        """Non-zero ``d expr / d s`` for the symbols ``s`` of ``wanted`` (expanded), or ``None``.

        ``None`` means ``expr`` is not a polynomial in the variables: the caller
        differentiates with sympy. Only the variables that occur in ``expr`` are
        differentiated.
        """
        found = self.element(expr)
        if found is None:
            return None
        p, variables, back = found
        position = {v: k for k, v in enumerate(variables)}
        out: dict[sympy.Symbol, sympy.Expr] = {}
        for s in wanted:
            k = position.get(s)
            if k is None:
                continue
            d = p.diff(k)
            if d:
                out[s] = self.to_expr(d, back)
        return out


def quadratic_parts(
    expression: sympy.Expr, coordinates: Sequence[sympy.Symbol], velocities: Sequence[sympy.Symbol], parameters: Sequence[sympy.Symbol]
) -> tuple[sympy.Matrix, list[sympy.Expr], sympy.Expr] | None:
    """``(W, a, V)`` of ``L = 1/2 v^T W(q) v + a(q) . v - V(q)`` for a polynomial ``L``, else ``None``.

    ``W_ij = d^2 L / dv_i dv_j``, ``a_i = dL/dv_i`` at ``v = 0``, ``V = -L`` at ``v = 0``
    (the split of :mod:`dirac.analysis.legendre`), computed in the sparse ring: only the
    non-zero entries of ``W`` are built, so a local Lagrangian with ``n`` velocities costs
    ``O(n)``, not the ``n^2`` second derivatives of ``sympy.diff``. ``None`` when ``L`` is not
    a polynomial in the coordinates and velocities, or when it is not quadratic in the
    velocities (the caller then takes the general path, with its own error messages).
    """
    forms = PolynomialPartials((*velocities, *coordinates), parameters)
    found = forms.element(expression)
    if found is None:
        return None
    p, variables, back = found
    ring = p.ring
    index = {v: k for k, v in enumerate(variables)}
    vel = [index.get(v) for v in velocities]
    vel_positions = [k for k in vel if k is not None]
    if any(sum(monom[k] for k in vel_positions) > 2 for monom in p.itermonoms()):
        return None
    n = len(velocities)
    static = ring.from_dict({m: c for m, c in p.items() if all(m[k] == 0 for k in vel_positions)})
    W = sympy.zeros(n, n)
    a: list[sympy.Expr] = [sympy.S.Zero] * n
    for i, ki in enumerate(vel):
        if ki is None:
            continue
        first = p.diff(ki)
        linear = ring.from_dict({m: c for m, c in first.items() if all(m[k] == 0 for k in vel_positions)})
        a[i] = forms.to_expr(linear, back) if linear else sympy.S.Zero
        for j, kj in enumerate(vel):
            if kj is None or j < i:
                continue
            second = first.diff(kj)
            if second:
                W[i, j] = W[j, i] = forms.to_expr(second, back)
    V = -forms.to_expr(static, back) if static else sympy.S.Zero
    return W, a, V
