"""Fast exact normal forms: sympy trees evaluated in polynomial rings and fields.

Expanding large brackets with ``sympy.expand`` is slow; evaluating the same expression
tree directly in the sparse polynomial ring ``QQ(parameters)[variables]`` (or its
fraction field when the variables occur in denominators) is orders of magnitude faster.
:func:`tidy` uses this to give constraints and multipliers a readable, expanded form.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import sympy
from sympy.core.add import _addsort
from sympy.polys.fields import FracField
from sympy.polys.polyerrors import BasePolynomialError
from sympy.polys.rings import PolyRing
from sympy.printing.str import StrPrinter

from dirac.codegen.printer import distinct_nodes

__all__ = ["NotInRing", "shared_xreplace", "tidy", "prints_shorter", "printed", "printed_at_most", "text_of", "present_in_order", "ring_value", "rational_parts"]


class NotInRing(Exception):
    """An expression is not an element of the ring asked for (a function, a non-integer power, a division)."""


def prints_shorter(expr: sympy.Expr, limit: int) -> bool:
    """``len(str(expr)) < limit``, without printing a long expression.

    Every occurrence of a symbol prints its whole name, so the names summed over the
    occurrences (a shared sub-tree counted as often as it occurs, as the printer does)
    are a lower bound of the printed length: when that bound reaches ``limit`` the
    answer is ``False`` at once (printing a 15 000-character condition of (228) costs
    more than a tenth of a second); otherwise the expression is printed and measured,
    so the answer is always that of ``len(str(expr)) < limit``.
    """
    names: dict[sympy.Basic, int] = {}

    def walk(node: sympy.Basic) -> int:
        hit = names.get(node)
        if hit is None:
            if node.is_Symbol:
                hit = len(node.name)
            else:
                hit = 0
                for a in node.args:
                    hit += walk(a)
                    if hit >= limit:
                        break
            names[node] = hit
        return hit

    if walk(expr) >= limit:
        return False
    longest = printed_at_most(expr, limit)
    if longest is not None and longest < limit:
        return True
    return len(printed(expr)) < limit


#: texts of the expressions printed last (:func:`printed`), at most PRINTED_KEPT of them
_PRINTED: dict[sympy.Basic, str] = {}
PRINTED_KEPT = 256

#: texts of sub-trees printed before, per printer settings (:class:`_SharedTextPrinter`);
#: each memo is emptied when its texts hold more than SUBTREE_CHARACTERS characters
_SUBTREES: dict[tuple, dict[sympy.Basic, str]] = {}
SUBTREE_CHARACTERS = 20_000_000
_subtree_characters: dict[tuple, int] = {}


class _SharedTextPrinter(StrPrinter):
    """sympy's ``str`` printer that prints each sub-tree with arguments once.

    The printer's text of a node is a function of the node alone (its children print at
    a nesting level above 1 wherever the node stands; only a ``Float`` at the top level
    prints otherwise, and atoms are not remembered), so a sub-tree met again, in the
    same expression or in another printed with the same settings, is looked up. The
    stage-3 conditions of (228), about 68 000 characters, share long factors: printing
    them is ten times faster so, with the same texts.
    """

    def __init__(self, settings: dict | None = None) -> None:
        super().__init__(settings)
        self._key = tuple(sorted((k, repr(v)) for k, v in self._settings.items()))
        self._memo = _SUBTREES.setdefault(self._key, {})
        if _subtree_characters.get(self._key, 0) > SUBTREE_CHARACTERS:
            self._memo.clear()
            _subtree_characters[self._key] = 0

    def _print(self, expr: Any, **kwargs: Any) -> str:
        if kwargs or not isinstance(expr, sympy.Basic) or not expr.args:
            return super()._print(expr, **kwargs)
        hit = self._memo.get(expr)
        if hit is None:
            hit = super()._print(expr)
            self._memo[expr] = hit
            _subtree_characters[self._key] = _subtree_characters.get(self._key, 0) + len(hit)
        return hit


def text_of(expr: sympy.Basic, order: str | None = None) -> str:
    """``sympy.sstr(expr, order=order)`` of an expression (``str(expr)`` with the default order), shared sub-trees printed once."""
    if not isinstance(expr, sympy.Expr):
        return sympy.sstr(expr, order=order)
    text: str = _SharedTextPrinter({"order": order}).doprint(expr)
    return text


def printed(expr: sympy.Basic) -> str:
    """``str(expr)``, remembered for the last ``PRINTED_KEPT`` expressions printed.

    A multiplier of (78) is printed to measure it (:func:`prints_shorter`, before its
    denominators are searched) and again in the report: the second time is a lookup.
    """
    text = _PRINTED.get(expr)
    if text is None:
        text = text_of(expr) if isinstance(expr, sympy.Expr) else str(expr)
        if len(_PRINTED) >= PRINTED_KEPT:
            _PRINTED.clear()
        _PRINTED[expr] = text
    return text


#: characters sympy's str printer adds, at most, around the arguments of a node: (per node, per argument).
#: A sum: " + " or " - " between terms (a term's own "-" becomes the separator's) and "(...)"
#: around a term; a product: "*" or "/" between factors (a fraction ``p/q`` is counted with its "/"),
#: "(...)" around a factor, and at most a sign, a "1" over an empty numerator and "(...)" around
#: a denominator of several factors; a power: "**", "(...)" around base and exponent, or
#: "sqrt(...)", "1/sqrt(...)", "1/" (a negative exponent inside a product prints shorter).
#: Checked against the printer on random trees in tests/analysis/core/test_printed_bound.py.
_EXTRA = {"Add": (0, 5), "Mul": (5, 3), "Pow": (8, 0)}


def printed_at_most(expr: sympy.Expr, limit: int) -> int | None:
    """An upper bound of ``len(str(expr))`` (in any order of the terms) for sums, products and powers of atoms, else ``None``.

    Atoms count their own printed length; every sum, product or power adds at most the
    characters :data:`_EXTRA` allows for itself and its arguments. ``None`` for any other
    node (a function, a relation) or once the bound reaches ``limit``.
    """
    sizes: dict[sympy.Basic, int] = {}

    def walk(node: sympy.Basic) -> int | None:
        hit = sizes.get(node)
        if hit is not None:
            return hit
        if not node.args:
            if not (node.is_Symbol or node.is_Number):
                return None
            hit = len(str(node))
        elif node.is_Add or node.is_Mul or node.is_Pow:
            per_node, per_argument = _EXTRA["Add" if node.is_Add else "Mul" if node.is_Mul else "Pow"]
            hit = per_node
            for a in node.args:
                size = walk(a)
                if size is None:
                    return None
                hit += size + per_argument
                if hit >= limit:
                    return None
        else:
            return None
        sizes[node] = hit
        return hit

    return walk(expr)


def ring_value(expr: sympy.Expr, gens: Mapping, domain: Any, invert: Callable[[Any], Any] | None = None) -> Any:
    """``expr`` as an element of ``domain`` (a polynomial ring or a field), by one walk of its tree.

    Symbols (and any other node keyed in ``gens``) map through ``gens``; rationals,
    sums, products and integer powers are taken in ``domain``. A negative power needs
    ``invert`` (``base -> 1 / base`` in ``domain``; it may raise :class:`NotInRing` for a
    base that has no inverse there). Any other node raises :class:`NotInRing`. Shared
    sub-trees are walked once.
    """
    cache: dict = {}

    def walk(e: sympy.Expr) -> Any:
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
            elif invert is not None:
                out = invert(base) ** (-k)
            else:
                raise NotInRing
        else:
            raise NotInRing
        cache[e] = out
        return out

    return walk(expr)


@functools.lru_cache(maxsize=256)
def rational_parts(expr: sympy.Expr) -> tuple[sympy.Expr, sympy.Expr] | None:
    """``(N, D)`` with ``expr = N / D`` in lowest terms, polynomials over ``QQ`` in all its symbols; else ``None``.

    ``expr`` is taken into the fraction field ``QQ(symbols)`` by one walk of its graph
    (:func:`ring_value`; ``FracField`` reduces after every operation, so ``N`` and ``D``
    have no common factor and ``D`` has a positive leading coefficient); a function of the
    symbols (``sin(theta)``) is a generator of its own, as in sympy's polynomials. ``None`` for an
    expression that is not a rational function with rational coefficients (a ``Float``, a
    fractional power). What it answers that ``sympy.expand`` cannot say
    cheaply: whether ``expr`` is a polynomial in some of its symbols (``D`` free of them),
    for a nested quotient such as the pivot ``a - b c / d`` of an elimination, whose
    expansion costs seconds (Geddes, Czapor & Labahn, "Algorithms for Computer Algebra",
    1992, Sect. 2.8 on the canonical form of rational functions). Remembered for the last
    256 expressions (the divisor searches ask about the same bases several times).
    """
    symbols = sorted(expr.free_symbols, key=lambda s: s.name)
    if not symbols or not all(s.is_Symbol for s in symbols):
        return None
    # a function of the symbols (sin(theta), exp(x)) is one more generator, as for sympy's polynomials
    applied = sorted({node for node in distinct_nodes(expr) if isinstance(node, sympy.Function)}, key=sympy.default_sort_key)
    field = FracField([*symbols, *applied], sympy.QQ)
    gens = dict(zip([*symbols, *applied], field.gens))
    try:
        value = ring_value(expr, gens, field, invert=lambda base: field(1) / base)
    except (NotInRing, ZeroDivisionError, TypeError, ValueError, BasePolynomialError):
        return None
    return value.numer.as_expr(), value.denom.as_expr()


def _split_denominators(expr: sympy.Expr, variables: set) -> tuple[sympy.Expr, dict, list]:
    """Replace powers ``base**(-k)`` of variable-free bases by ``d_i**k`` (new symbols).

    Returns the new expression, ``{d_i: 1/base}`` and the list of ``d_i``.

    The nodes are met in preorder, each distinct sub-tree once (a shared sub-tree met again
    holds nothing new: its nodes were all met at its first occurrence), so the ``d_i`` are
    numbered in the order of first occurrence, as a walk of the whole tree numbers them;
    the stage-3 conditions of (228) share sub-trees of many thousands of tree nodes
    (``sympy.preorder_traversal`` walked them every time: 0.08 s of (228)'s analysis).
    """
    replacements: dict = {}
    back: dict = {}
    symbol_of: dict = {}  # base -> its d_i
    for node in distinct_nodes(expr):
        if node.is_Pow and node.exp.is_Integer and node.exp < 0 and not (node.base.free_symbols & variables):
            base = node.base
            d = symbol_of.get(base)
            if d is None:
                d = symbol_of[base] = sympy.Dummy(f"d{len(back)}")
                back[d] = base
            replacements[node] = d ** int(-node.exp)
    if not replacements:
        return expr, {}, []
    return shared_xreplace(expr, replacements), {d: 1 / b for d, b in back.items()}, list(back)


def shared_xreplace(expr: sympy.Basic, rule: Mapping) -> sympy.Basic:
    """``expr.xreplace(rule)``, each distinct sub-tree rebuilt once.

    sympy's ``xreplace`` walks the expression as a tree: a sub-tree shared by many
    terms is walked, and rebuilt, at every occurrence (in (228)'s stage-3 conditions,
    17 000 node visits for 6 expressions, 0.3 s profiled). The rebuilt node is a function
    of the node alone (its class applied to its rebuilt arguments, as ``Basic._xreplace``
    does), so it is kept and reused: the same expression. Classes with an ``_xreplace`` of
    their own are left to it.
    """
    own = sympy.Basic._xreplace
    memo: dict = {}

    def walk(node: sympy.Basic) -> tuple[sympy.Basic, bool]:
        hit = memo.get(node)
        if hit is not None:
            return hit
        if node in rule:
            out = (rule[node], True)
        elif getattr(type(node), "_xreplace", None) is not own:
            out = node._xreplace(rule)
        else:
            args = []
            changed = False
            for a in node.args:
                if isinstance(a, sympy.Basic):
                    value, moved = walk(a)
                    args.append(value)
                    changed |= moved
                elif (other := getattr(a, "_xreplace", None)) is not None:
                    value, moved = other(rule)
                    args.append(value)
                    changed |= moved
                else:
                    args.append(a)
            out = (node.func(*args), True) if changed else (node, False)
        memo[node] = out
        return out

    if not rule:
        return expr
    return walk(expr)[0]


@functools.lru_cache(maxsize=4096)
def _combined(coeff: sympy.Expr) -> sympy.Expr:
    """``factor_terms(together(coeff))``, once per distinct coefficient (many monomials share one)."""
    return sympy.factor_terms(sympy.together(coeff))


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
            coeff = _combined(coeff)
        terms.append(coeff * sympy.Mul(*[v**k for v, k in zip(variables, monom) if k]))
    return sympy.Add(*terms)


_POSITIONS: dict[int, tuple[Sequence[sympy.Symbol], dict[sympy.Symbol, int]]] = {}


def present_in_order(variables: Sequence[sympy.Symbol], present: set | frozenset) -> list[sympy.Symbol]:
    """The ``variables`` that are in ``present``, in the order of ``variables``.

    ``O(len(present))`` for a long sequence passed again and again (the phase-space
    variables): its positions are kept for the last few sequences, recognised by identity.
    """
    if len(variables) <= 2 * len(present) + 8:
        return [v for v in variables if v in present]
    held = _POSITIONS.get(id(variables))
    if held is None or held[0] is not variables:
        if len(_POSITIONS) >= 8:
            _POSITIONS.clear()
        held = (variables, {v: k for k, v in enumerate(variables)})
        _POSITIONS[id(variables)] = held
    position = held[1]
    return sorted((v for v in present if v in position), key=position.__getitem__)


def _tidy_by_term(work: sympy.Expr, variables: Sequence[sympy.Symbol], others: Sequence[sympy.Symbol], back: dict) -> sympy.Expr | None:
    """:func:`_poly_to_expr` of the polynomial ``work`` (a long sum), expanded term by term; ``None`` if a term is not one.

    Each term is evaluated in the small ring of its own generators and the monomials are
    merged by their exponents (kept sparse): a ring of all the generators of a long sum
    costs ``O(generators)`` per monomial operation (dense exponent tuples), ``O(n^2)`` for
    ``n`` terms. The result is the expression :func:`_poly_to_expr` gives for the whole.
    """
    vpos = {v: k for k, v in enumerate(variables)}
    opos = {o: k for k, o in enumerate(others)}
    merged: dict[tuple[tuple, tuple], Any] = {}
    for term in work.args:
        if term.is_Rational:
            key: tuple[tuple, tuple] = ((), ())
            merged[key] = merged.get(key, sympy.QQ(0)) + sympy.QQ(int(term.p), int(term.q))
            continue
        free = term.free_symbols
        own_v = sorted((v for v in free if v in vpos), key=vpos.__getitem__)
        own_o = sorted((o for o in free if o in opos), key=opos.__getitem__)
        gens_all = [*own_v, *own_o]
        if not gens_all or len(gens_all) < len(free):
            return None
        ring = PolyRing(gens_all, sympy.QQ)
        value = ring_value(term, dict(zip(gens_all, ring.gens)), ring)
        nv = len(own_v)
        for monom, c in value.terms():
            key = (
                tuple((vpos[own_v[i]], e) for i, e in enumerate(monom[:nv]) if e),
                tuple((opos[own_o[i]], e) for i, e in enumerate(monom[nv:]) if e),
            )
            merged[key] = merged.get(key, sympy.QQ(0)) + c
    groups: dict[tuple, list[sympy.Expr]] = {}
    for (vkey, okey), c in merged.items():
        if not c:
            continue
        coeff = sympy.Rational(int(c.numerator), int(c.denominator)) * sympy.Mul(*[others[i] ** e for i, e in okey])
        groups.setdefault(vkey, []).append(coeff)
    terms = []
    for vkey, coeffs in groups.items():
        coeff = sympy.Add(*coeffs).xreplace(back) if back else sympy.Add(*coeffs)
        if back and len(coeffs) > 1:
            coeff = _combined(coeff)
        terms.append(coeff * sympy.Mul(*[variables[i] ** e for i, e in vkey]))
    return sympy.Add(*terms)


def _reduced_product(work: sympy.Expr, gens: Mapping, ring: PolyRing) -> tuple[Any, Any] | None:
    """``(p, q)``, the reduced fraction ``work = p / q`` of a product of polynomials and negative powers of polynomials.

    The same pair as the fraction field gives (``FracField`` reduces after every
    operation; its elements are the unique representatives ``p / q`` with ``p, q`` of
    integer coefficients without a common factor, content included, and the leading
    coefficient of ``q`` positive, which :meth:`PolyElement.cancel` also returns), with one
    ``gcd`` at the end instead of one per operation: a multiplier of (78), a long sum over
    one polynomial denominator, is reduced in a fraction of the time. ``None`` for any
    other shape (a sum of fractions), left to the field.
    """
    numer, denom = ring.one, ring.one
    try:
        for factor in sympy.Mul.make_args(work):
            if factor.is_Pow and factor.exp.is_Integer and factor.exp < 0:
                denom *= ring_value(factor.base, gens, ring) ** int(-factor.exp)
            else:
                numer *= ring_value(factor, gens, ring)
    except (NotInRing, ZeroDivisionError, TypeError, ValueError, sympy.CoercionFailed, sympy.PolynomialError):
        return None
    if not denom:
        return None  # a division by zero: the field raises it
    return _cancelled(numer, denom)


def _cancelled(numer: Any, denom: Any) -> tuple[Any, Any]:
    """``numer.cancel(denom)`` (sparse polynomials over ``QQ``), the common factor found in the denominator's generators.

    A common factor of ``numer`` and ``denom`` is a polynomial in the generators ``Y``
    that ``denom`` contains; written ``numer = sum_m c_m(Y) X^m`` over the other
    generators ``X``, it divides ``numer`` exactly when it divides every ``c_m`` (the
    monomials ``X^m`` are independent over ``K[Y]``). So ``gcd(numer, denom) = gcd(denom,
    c_1, c_2, ...)`` over ``ZZ[Y]`` (after clearing denominators), stopping at a unit.
    ``cancel`` computes the same gcd in the ring of all the generators, where sympy's
    heuristic gcd evaluates one generator after another and builds a ring for each
    (PolyRing code generation): on the multipliers of (78), 30 generators, 0.17 s of the
    report's 0.75 s, against a ring of the few generators of the denominator here. The
    gcd is the same up to its sign, so the cofactors are, and the pair is made canonical
    as ``cancel`` makes it (integer contents, the denominator's leading coefficient
    positive): the same ``(p, q)``.
    """
    ring = numer.ring
    domain = ring.domain
    if not numer or not domain.is_QQ:
        return numer.cancel(denom)
    in_denominator = sorted({i for monom in denom.itermonoms() for i, e in enumerate(monom) if e})
    if len(in_denominator) == ring.ngens:
        return numer.cancel(denom)
    integers = ring.clone(domain=domain.get_ring())
    cq, f = numer.clear_denoms()
    cp, g = denom.clear_denoms()
    f = f.set_ring(integers)
    g = g.set_ring(integers)
    small = PolyRing([ring.symbols[i] for i in in_denominator], integers.domain)
    outside = [i for i in range(ring.ngens) if i not in set(in_denominator)]
    coefficients: dict[tuple, dict] = {}
    for monom, c in f.iterterms():
        inner = tuple(monom[i] for i in in_denominator)
        coefficients.setdefault(tuple(monom[i] for i in outside), {})[inner] = c
    h = small.from_dict({tuple(monom[i] for i in in_denominator): c for monom, c in g.iterterms()})
    for terms in coefficients.values():
        h = h.gcd(small.from_dict(terms))
        if h.is_ground and abs(h.LC) == 1:  # a unit: nothing is common
            break
    common = integers.from_dict(
        {tuple(monom[in_denominator.index(i)] if i in in_denominator else 0 for i in range(ring.ngens)): c for monom, c in h.iterterms()}
    )
    p, q = (f, g) if common == integers.one else (f.exquo(common), g.exquo(common))
    _, cp, cq = integers.domain.cofactors(cp, cq)
    p = p.set_ring(ring).mul_ground(cp)
    q = q.set_ring(ring).mul_ground(cq)
    if domain.canonical_unit(q.LC) == -domain.one:
        p, q = -p, -q
    return p, q


#: sums of more terms than this are expanded term by term (:func:`_tidy_by_term`)
PIECEWISE_TERMS = 64


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
    variables = present_in_order(variables, present)
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
        by_term = _tidy_by_term(work, variables, others, back) if work.is_Add and len(work.args) > PIECEWISE_TERMS else None
        if by_term is not None:
            out = by_term
        else:
            value = ring_value(work, gens, ring)
            out = _poly_to_expr(value, variables, others, back)
    except (NotInRing, ZeroDivisionError, TypeError, ValueError, sympy.CoercionFailed, sympy.PolynomialError):
        if not rational:  # rational normal forms need gcds: too slow for large expressions
            return expr
        reduced = _reduced_product(work, gens, ring)
        if reduced is None:
            field = FracField(gens_all, sympy.QQ)
            fgens = dict(zip(gens_all, field.gens))
            try:
                value = ring_value(work, fgens, field, invert=lambda base: field(1) / base)
            except (NotInRing, ZeroDivisionError, TypeError, ValueError, sympy.CoercionFailed, sympy.PolynomialError):
                out = sympy.cancel(expr)
                return -out if sign and out.could_extract_minus_sign() else out
            reduced = value.numer, value.denom
        num = _poly_to_expr(reduced[0], variables, others, back)
        den = _poly_to_expr(reduced[1], variables, others, back)
        if _minus_sign_first(den):
            num, den = -num, -den
        out = num / sympy.factor(den) if den != 1 else num
    if sign and _minus_sign_first(out):
        out = -out
    return out


def _minus_sign_first(expr: sympy.Expr) -> bool:
    """``expr.could_extract_minus_sign()``, its tie-break read off the first ordered term.

    For a sum with as many negative as positive terms sympy compares
    ``expr.sort_key()`` with ``(-expr).sort_key()``: the keys of the ordered terms, one
    by one. The terms of ``-expr`` are the negated terms of ``expr`` in the same order
    (the order is by monomial, which negation keeps), and the keys of ``t`` and ``-t``
    differ only in the numeric coefficient, so the first pair decides: the keys of the
    first term and of its negative. The same answer without building ``-expr`` and
    sorting it; anything but a sum of terms with rational coefficients asks sympy.
    """
    if not expr.is_Add:
        return expr.could_extract_minus_sign()
    negative = sum(1 for a in expr.args if _negative_term(a))
    positive = len(expr.args) - negative
    if positive != negative:
        return positive < negative
    if not all(a.as_coeff_Mul()[0].is_Rational for a in expr.args):
        return expr.could_extract_minus_sign()
    first = expr.as_ordered_terms()[0]
    return bool(sympy.default_sort_key(first) < sympy.default_sort_key(-first))


def _negative_term(term: sympy.Expr) -> bool:
    """``term.could_extract_minus_sign()`` for a term of a sum, a product's answer without building ``-term``.

    sympy's ``Mul.could_extract_minus_sign`` is ``False`` when ``term == -term``, else
    whether the leading argument is a negative number; it builds ``-term`` (a flatten of
    the product) to compare, about 45 microseconds a term: 0.12 s of (19)'s analysis,
    measured in a fresh process. A product whose leading argument is a negative number
    (a rational, a float, ``-oo``) is never its own negative (the negation changes that
    coefficient), and one whose leading argument is not is ``False`` either way; so the
    leading argument alone answers. Other terms ask sympy.
    """
    if term.is_Mul:
        lead = term.args[0]
        return bool(lead.is_Number and lead.is_extended_negative)
    return bool(term.could_extract_minus_sign())


def negated(expr: sympy.Expr) -> sympy.Expr:
    """``-expr``, for a sum built from its negated terms without collecting them again.

    ``-(t_1 + ... + t_k)`` distributes the sign and re-collects like terms; the terms of
    a canonical sum are already collected and stay distinct when negated (``-t`` keeps
    the non-numeric part of ``t``), so sorting the negated terms in sympy's canonical
    order (numeric term first) gives the identical sum. Sums with a product holding a
    sum, non-commutative or infinite parts are negated by sympy.
    """
    if not expr.is_Add or not expr.is_commutative:
        return -expr
    terms: list[sympy.Expr] = []
    constant: sympy.Expr | None = None
    for t in expr.args:
        if t.is_Number:
            if not t.is_finite:
                return -expr
            constant = -t
        elif t.is_Symbol or t.is_Pow or (t.is_Mul and not any(a.is_Add for a in t.args)):
            terms.append(-t)
        else:
            return -expr
    _addsort(terms)
    if constant is not None:
        terms.insert(0, constant)
    return sympy.Add._from_args(terms, True)
