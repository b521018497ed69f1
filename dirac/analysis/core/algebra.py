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


def _split_denominators(expr: sympy.Expr, variables: set) -> tuple[sympy.Expr, dict, list]:
    """Replace powers ``base**(-k)`` of variable-free bases by ``d_i**k`` (new symbols).

    Returns the new expression, ``{d_i: 1/base}`` and the list of ``d_i``.
    """
    replacements: dict = {}
    back: dict = {}
    for node in sympy.preorder_traversal(expr):
        if node.is_Pow and node.exp.is_Integer and node.exp < 0 and not (node.base.free_symbols & variables):
            base = node.base
            if base not in back.values():
                d = sympy.Dummy(f"d{len(back)}")
                back[d] = base
            d = next(k for k, v in back.items() if v == base)
            replacements[node] = d ** int(-node.exp)
    if not replacements:
        return expr, {}, []
    return expr.xreplace(replacements), {d: 1 / b for d, b in back.items()}, list(back)


def _poly_to_expr(p, variables: Sequence[sympy.Symbol], others: Sequence[sympy.Symbol], back: dict) -> sympy.Expr:
    """Ring element in ``variables + others`` -> sympy, terms grouped by variable monomial."""
    nv = len(variables)
    groups: dict = {}
    for monom, c in p.terms():
        coeff = sympy.Rational(int(c.numerator), int(c.denominator)) * sympy.Mul(*[s**k for s, k in zip(others, monom[nv:]) if k])
        groups.setdefault(monom[:nv], []).append(coeff)
    terms = []
    for monom, coeffs in groups.items():
        coeff = sympy.Add(*coeffs).xreplace(back) if back else sympy.Add(*coeffs)
        if back and len(coeffs) > 1:
            coeff = sympy.factor_terms(sympy.together(coeff))
        terms.append(coeff * sympy.Mul(*[v**k for v, k in zip(variables, monom) if k]))
    return sympy.Add(*terms)


def tidy(expr: sympy.Expr, variables: Sequence[sympy.Symbol] = (), sign: bool = False, rational: bool = True) -> sympy.Expr:
    """Readable exact form: expanded in the phase-space ``variables`` over one denominator.

    A polynomial in ``variables`` is expanded with coefficients functions of the
    parameters; a rational function becomes ``numerator / factored denominator``.
    Anything else (``sin``, ``sqrt`` …) is returned cancelled. With ``sign=True`` (for
    constraints, whose sign is free) the overall sign is chosen so that the leading term
    is positive; otherwise the value is unchanged. Expansion runs in the sparse polynomial ring
    over ``QQ`` (parameter denominators become extra generators, so no gcd is needed).
    """
    expr = sympy.sympify(expr)
    present = expr.free_symbols
    variables = [v for v in variables if v in present]
    if not variables:
        out = sympy.cancel(expr) if expr.free_symbols else expr
        return -out if sign and out.could_extract_minus_sign() else out
    work, back, ds = _split_denominators(expr, set(variables))
    params = sorted(present - set(variables), key=lambda s: s.name)
    others = [*params, *ds]
    gens_all = [*variables, *others]
    ring = PolyRing(gens_all, sympy.QQ)
    gens = dict(zip(gens_all, ring.gens))
    try:
        value = _evaluate(work, gens, ring, allow_division=False)
        out = _poly_to_expr(value, variables, others, back)
    except (_NotRational, ZeroDivisionError, TypeError, ValueError, sympy.CoercionFailed, sympy.PolynomialError):
        if not rational:  # rational normal forms need gcds: too slow for large expressions
            return expr
        field = FracField(gens_all, sympy.QQ)
        fgens = dict(zip(gens_all, field.gens))
        try:
            value = _evaluate(work, fgens, field, allow_division=True)
        except (_NotRational, ZeroDivisionError, TypeError, ValueError, sympy.CoercionFailed, sympy.PolynomialError):
            out = sympy.cancel(expr)
            return -out if sign and out.could_extract_minus_sign() else out
        ring = PolyRing(gens_all, sympy.QQ)
        num = _poly_to_expr(ring(value.numer.as_expr()) if False else value.numer, variables, others, back)
        den = _poly_to_expr(value.denom, variables, others, back)
        if den.could_extract_minus_sign():
            num, den = -num, -den
        out = num / sympy.factor(den) if den != 1 else num
    if sign and out.could_extract_minus_sign():
        out = -out
    return out
