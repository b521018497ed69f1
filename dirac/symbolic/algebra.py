"""Fast exact normal forms: sympy trees evaluated in polynomial rings and fields.

Expanding large brackets with ``sympy.expand`` is slow; evaluating the same expression
tree directly in the sparse polynomial ring ``QQ(parameters)[variables]`` (or its
fraction field when the variables occur in denominators) is orders of magnitude faster.
:func:`tidy` uses this to give constraints and multipliers a readable, expanded form.
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy
from sympy.polys.fields import FracField
from sympy.polys.rings import PolyRing

__all__ = ["tidy"]


class _NotRational(Exception):
    pass


def _evaluate(expr: sympy.Expr, gens: dict, domain, allow_division: bool):
    """Evaluate ``expr`` in ``domain`` (a ring or field), mapping symbols through ``gens``."""
    cache: dict = {}

    def walk(e):
        hit = cache.get(e)
        if hit is not None:
            return hit
        if e in gens:
            out = gens[e]
        elif e.is_Rational:
            out = domain(sympy.QQ(int(e.p), int(e.q))) if not e.is_Integer else domain(int(e))
        elif e.is_Add:
            out = domain(0)
            for a in e.args:
                out = out + walk(a)
        elif e.is_Mul:
            out = domain(1)
            for a in e.args:
                out = out * walk(a)
        elif e.is_Pow and e.exp.is_Integer:
            base = walk(e.base)
            k = int(e.exp)
            if k >= 0:
                out = base**k
            elif allow_division:
                out = (domain(1) / base) ** (-k)
            else:
                raise _NotRational
        elif not (e.free_symbols - set(gens)) and e.is_number is False:
            raise _NotRational
        elif e.is_number:
            raise _NotRational
        else:
            raise _NotRational
        cache[e] = out
        return out

    return walk(expr)


def _coefficient(c, params: Sequence[sympy.Symbol]) -> sympy.Expr:
    """A coefficient in ``QQ(params)`` as a sympy expression with factored denominator."""
    if hasattr(c, "numer") and hasattr(c, "denom"):
        num = c.numer.as_expr()
        den = c.denom.as_expr()
        if den == 1:
            return sympy.factor_terms(num)
        return sympy.factor_terms(num) / sympy.factor(den)
    return sympy.sympify(c.as_expr() if hasattr(c, "as_expr") else c)


def _poly_to_expr(p, variables: Sequence[sympy.Symbol], params: Sequence[sympy.Symbol]) -> sympy.Expr:
    terms = []
    for monom, c in p.terms():
        coeff = _coefficient(c, params) if params else sympy.Rational(int(c.numerator), int(c.denominator))
        terms.append(coeff * sympy.Mul(*[v**k for v, k in zip(variables, monom)]))
    return sympy.Add(*terms)


def tidy(expr: sympy.Expr, variables: Sequence[sympy.Symbol] = ()) -> sympy.Expr:
    """Readable exact form: expanded in the phase-space ``variables`` over one denominator.

    A polynomial in ``variables`` is expanded with coefficients rational functions of the
    parameters (denominators factored); a rational function becomes
    ``numerator / factored denominator``. Anything else (``sin``, ``sqrt`` …) is returned
    cancelled. The overall sign is chosen so that the first term is positive.
    """
    expr = sympy.sympify(expr)
    present = expr.free_symbols
    variables = [v for v in variables if v in present]
    if not variables:
        out = sympy.cancel(expr) if expr.free_symbols else expr
        return -out if out.could_extract_minus_sign() else out
    params = sorted(present - set(variables), key=lambda s: s.name)
    K = sympy.QQ.frac_field(*params) if params else sympy.QQ
    ring = PolyRing(variables, K)
    gens = dict(zip(variables, ring.gens))
    if params:
        for s in params:
            gens[s] = ring(K.from_sympy(s))
    try:
        value = _evaluate(expr, gens, ring, allow_division=False)
        out = _poly_to_expr(value, variables, params)
    except (_NotRational, ZeroDivisionError, TypeError, ValueError, sympy.CoercionFailed, sympy.PolynomialError):
        field = FracField(variables, K)
        fgens = dict(zip(variables, field.gens))
        for s in params:
            fgens[s] = field(K.from_sympy(s))
        try:
            value = _evaluate(expr, fgens, field, allow_division=True)
        except (_NotRational, ZeroDivisionError, TypeError, ValueError, sympy.CoercionFailed, sympy.PolynomialError):
            out = sympy.cancel(expr)
            return -out if out.could_extract_minus_sign() else out
        num = _poly_to_expr(value.numer, variables, params)
        den = _poly_to_expr(value.denom, variables, params)
        if den.could_extract_minus_sign():
            num, den = -num, -den
        out = num / sympy.factor(den) if den != 1 else num
    if out.could_extract_minus_sign():
        out = -out
    return out
