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
from sympy.core.add import _addsort
from sympy.core.mul import _mulsort
from sympy.polys.rings import PolyElement, PolyRing

from dirac.analysis.core.algebra import NotInRing, ring_value

__all__ = ["PolynomialPartials", "SPARSE_HESSIAN"]

#: sums of more terms than this are differentiated term by term (:meth:`PolynomialPartials.partials`)
PIECEWISE_TERMS = 64

#: from this many velocities :func:`quadratic_parts` returns ``W`` as a ``sympy.SparseMatrix``
#: (a dense one of a large local system holds ``n^2`` zeros, and scanning it costs ``O(n^2)``)
SPARSE_HESSIAN = 64


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
        self._position = {v: k for k, v in enumerate(self.variables)}
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
        variables = sorted(free & self._variable_set, key=self._position.__getitem__)  # O(size), not O(all variables)
        params = sorted((free - self._variable_set), key=lambda s: s.name)
        symbols = [*variables, *params]
        ring = PolyRing([*symbols, *atoms.values()], sympy.QQ)
        gens = dict(zip([*symbols, *atoms], ring.gens))
        try:
            p = ring_value(expr, gens, ring)
        except (NotInRing, ZeroDivisionError, TypeError, ValueError, sympy.CoercionFailed, sympy.PolynomialError):
            return None
        return p, variables, {d: a for a, d in atoms.items()}

    @staticmethod
    def to_expr(p: PolyElement, back: dict) -> sympy.Expr:
        """A ring element as a sympy expression (the stand-in generators replaced back)."""
        value = canonical_expr(p)
        return value.xreplace(back) if back else value

    def partials(self, expr: sympy.Expr, wanted: Sequence[sympy.Symbol]) -> dict[sympy.Symbol, sympy.Expr] | None:
        """Non-zero ``d expr / d s`` for the symbols ``s`` of ``wanted`` (expanded), or ``None``.

        ``None`` means ``expr`` is not a polynomial in the variables: the caller
        differentiates with sympy. Only the variables that occur in ``expr`` are
        differentiated.
        """
        if expr.is_Add and len(expr.args) > PIECEWISE_TERMS:
            return self._partials_by_term(expr, wanted)
        found = self.element(expr)
        if found is None:
            return None
        p, variables, back = found
        out: dict[sympy.Symbol, sympy.Expr] = {}
        if wanted is not self.variables:  # the ring's variables that are wanted, in the order of ``wanted``
            position = {v: k for k, v in enumerate(variables)}
            pairs = [(s, position[s]) for s in wanted if s in position]
        else:
            pairs = [(s, k) for k, s in enumerate(variables)]
        for s, k in pairs:
            d = p.diff(k)
            if d:
                out[s] = self.to_expr(d, back)
        return out


    def _partials_by_term(self, expr: sympy.Expr, wanted: Sequence[sympy.Symbol]) -> dict[sympy.Symbol, sympy.Expr] | None:
        """:meth:`partials` of a long sum, term by term, each in the small ring of its own variables.

        A ring of all the variables a long sum contains costs ``O(variables)`` per monomial
        operation (exponent tuples are dense), so differentiating a Hamiltonian of ``n``
        terms by each of its variables costs ``O(n^2)``; term by term it costs ``O(n)``. The
        derivative of each term is expanded, and their sum, collected by ``sympy.Add``, is the
        expanded derivative of the whole (the same expression).
        """
        pieces: dict[sympy.Symbol, list[sympy.Expr]] = {}
        for term in expr.args:
            found = self.partials(term, wanted)
            if found is None:
                return None
            for s, d in found.items():
                pieces.setdefault(s, []).append(d)
        order = wanted if wanted is not self.variables else self.variables
        out: dict[sympy.Symbol, sympy.Expr] = {}
        for s in (s for s in order if s in pieces):
            total = sympy.Add(*pieces[s])
            if total != 0:
                out[s] = total
        return out


def canonical_expr(p: PolyElement) -> sympy.Expr:
    """``p.as_expr()``, the same expression built without re-flattening each product and the sum.

    ``sympy.Mul`` and ``sympy.Add`` put their arguments in canonical order (numeric
    coefficient first, the rest sorted by ``Basic.compare``) after collecting like factors
    and terms; the monomials of a ring element over ``QQ`` in distinct commutative
    symbols have nothing to collect, so sorting them in that order and building the
    product and the sum from their arguments gives the identical expression (the same
    arguments in the same order) at a fraction of the cost. Any other ring falls back to
    ``p.as_expr()``.
    """
    ring = p.ring
    symbols = ring.symbols
    if ring.domain != sympy.QQ or not all(isinstance(s, sympy.Symbol) and s.is_commutative for s in symbols):
        return p.as_expr()
    to_sympy = ring.domain.to_sympy
    pow_ = sympy.Pow
    terms: list[sympy.Expr] = []
    constant: sympy.Expr | None = None
    for monom, c in p.iterterms():
        coeff = to_sympy(c)
        factors = [symbols[i] if k == 1 else pow_(symbols[i], k) for i, k in enumerate(monom) if k]
        if not factors:
            constant = coeff
            continue
        _mulsort(factors)
        if coeff is sympy.S.One:
            terms.append(factors[0] if len(factors) == 1 else sympy.Mul._from_args(factors, True))
        else:
            terms.append(sympy.Mul._from_args([coeff, *factors], True))
    _addsort(terms)
    if constant is not None:
        terms.insert(0, constant)
    if not terms:
        return sympy.S.Zero
    return terms[0] if len(terms) == 1 else sympy.Add._from_args(terms, True)


def quadratic_parts(
    expression: sympy.Expr, coordinates: Sequence[sympy.Symbol], velocities: Sequence[sympy.Symbol], parameters: Sequence[sympy.Symbol]
) -> tuple[sympy.Matrix, list[sympy.Expr], sympy.Expr] | None:
    """``(W, a, V)`` of ``L = 1/2 v^T W(q) v + a(q) . v - V(q)`` for a polynomial ``L``, else ``None``.

    ``W_ij = d^2 L / dv_i dv_j``, ``a_i = dL/dv_i`` at ``v = 0``, ``V = -L`` at ``v = 0``
    (the split of :mod:`dirac.analysis.legendre`), computed in the sparse ring: only the
    non-zero entries of ``W`` are built, a long sum term by term in the small ring of each
    term's variables, so a local Lagrangian with ``n`` velocities costs ``O(n)``, not the ``n^2``
    second derivatives of ``sympy.diff``; from ``SPARSE_HESSIAN`` velocities ``W`` is a
    ``sympy.SparseMatrix``. ``None`` when ``L`` is not
    a polynomial in the coordinates and velocities, or when it is not quadratic in the
    velocities (the caller then takes the general path, with its own error messages).
    """
    forms = PolynomialPartials((*velocities, *coordinates), parameters)
    n = len(velocities)
    column = {v: j for j, v in enumerate(velocities)}
    pieces = _summands(expression)
    # a long sum piece by piece, each in the small ring of its own variables (a ring of all the
    # variables costs O(n) per monomial operation); the whole at once if a piece is not quadratic
    found = [_split(forms, piece, column) for piece in pieces] if len(pieces) > 1 else [None]
    parts = [part for part in found if part is not None]
    if len(parts) < len(found):
        whole = _split(forms, expression, column)
        if whole is None:
            return None
        parts = [whole]
    entries: dict[tuple[int, int], list[sympy.Expr]] = {}
    linear: dict[int, list[sympy.Expr]] = {}
    static: list[sympy.Expr] = []
    for part in parts:
        for key, value in part[0].items():
            entries.setdefault(key, []).append(value)
        for i, value in part[1].items():
            linear.setdefault(i, []).append(value)
        static.extend(part[2])
    summed = {key: sympy.Add(*values) for key, values in entries.items()}
    summed = {key: value for key, value in summed.items() if value != 0}
    a = [sympy.Add(*linear[i]) if i in linear else sympy.S.Zero for i in range(n)]
    W = sympy.SparseMatrix(n, n, summed) if n >= SPARSE_HESSIAN else sympy.Matrix(sympy.SparseMatrix(n, n, summed))
    return W, a, -sympy.Add(*static)


def _summands(expr: sympy.Expr) -> list[sympy.Expr]:
    """The terms of ``expr`` as a sum, distributing a product over its one sum factor (``c (a + b)``)."""
    if expr.is_Add:
        return [t for arg in expr.args for t in _summands(arg)]
    if expr.is_Mul:
        sums = [f for f in expr.args if f.is_Add]
        if len(sums) == 1:
            rest = sympy.Mul(*[f for f in expr.args if f is not sums[0]])
            return [rest * t for t in _summands(sums[0])]
    return [expr]


def _split(
    forms: PolynomialPartials, expr: sympy.Expr, column: dict[sympy.Symbol, int]
) -> tuple[dict[tuple[int, int], sympy.Expr], dict[int, sympy.Expr], list[sympy.Expr]] | None:
    """``W`` entries, ``a`` entries and the velocity-free part of one polynomial, or ``None``.

    ``None`` when ``expr`` is not a polynomial in the ring's variables or has a monomial of
    degree above 2 in the velocities (``column`` maps each velocity to its index).
    """
    found = forms.element(expr)
    if found is None:
        return None
    p, variables, back = found
    ring = p.ring
    vel = [(k, column[v]) for k, v in enumerate(variables) if v in column]
    vel_positions = [k for k, _ in vel]
    if any(sum(monom[k] for k in vel_positions) > 2 for monom in p.itermonoms()):
        return None
    static = ring.from_dict({m: c for m, c in p.items() if all(m[k] == 0 for k in vel_positions)})
    entries: dict[tuple[int, int], sympy.Expr] = {}
    linear: dict[int, sympy.Expr] = {}
    for ki, i in vel:
        first = p.diff(ki)
        part = ring.from_dict({m: c for m, c in first.items() if all(m[k] == 0 for k in vel_positions)})
        if part:
            linear[i] = forms.to_expr(part, back)
        for kj, j in vel:
            if j < i:
                continue
            second = first.diff(kj)
            if second:
                entries[(i, j)] = entries[(j, i)] = forms.to_expr(second, back)
    return entries, linear, [forms.to_expr(static, back)] if static else []
