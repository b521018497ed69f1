"""Regular constraints: square-free parts, crossing branches, irregular gradients.

The Dirac–Bergmann algorithm assumes *regular* constraints: on the surface
``Phi = 0`` the gradients ``dPhi_a`` of an independent set are linearly independent
(Henneaux–Teitelboim, Sect. 1.1.2, the "regularity conditions"). Two ways to fail:

* a constraint with a repeated factor, ``f^k = 0`` with ``k > 1``: its gradient
  ``k f^(k-1) df`` vanishes wherever it holds. The same surface is described regularly by
  the square-free part ``f = 0`` (:func:`square_free_part`); Cawley's Lagrangian
  ``x_dot z_dot + y z^2/2`` gives ``z^2 = 0``, regular as ``z = 0`` (Henneaux–Teitelboim,
  Sect. 1.2.2);
* a product of distinct factors ``f g = 0`` whose branches ``f = 0`` and ``g = 0`` meet:
  at the crossing the gradient ``f dg + g df`` vanishes, and no single regular surface
  contains both branches (:func:`branches`); each branch is a system of its own.

Square-free parts are computed only for constraints found irregular at surface points
(and for the holonomic constraints of the Lagrangian), since multivariate gcds cost more
than the analysis on large constraints.

Whether branches meet, and whether a gradient is numerically zero on a surface, is
decided at surface points (:mod:`dirac.analysis.core.numeric`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from fractions import Fraction

import numpy as np
import sympy
from sympy.polys.rings import PolyRing

from dirac.analysis.core.algebra import NotInRing, present_in_order, ring_value
from dirac.model.lagrangian import Lagrangian

__all__ = ["square_free_part", "branches", "factors", "factored", "branch_hint", "regular_holonomic", "normal_components", "IRREGULAR_GRADIENT", "MAX_FACTOR_TERMS"]

#: polynomials with more terms than this are not factored (the cost grows fast); their
#: regularity is still checked numerically at surface points
MAX_FACTOR_TERMS = 60



#: a new constraint whose gradient, relative to the size of the gradient's terms, has a
#: component normal to the earlier constraints' gradients below this at every surface
#: point (but above round-off) is irregular: its gradient vanishes where it holds (at a
#: converged point of ``f^2 = 0`` the gradient is of the order of the square root of the
#: residual tolerance, about 1e-6)
IRREGULAR_GRADIENT = 1e-4

#: normal components below this (relative) are round-off: the gradient is dependent
ROUND_OFF = 1e-9


def _polynomial(expr: sympy.Expr, variables: Sequence[sympy.Symbol]) -> sympy.Poly | None:
    """``expr`` as a polynomial in the ``variables`` it contains (parameters in the coefficients), or None."""
    present = present_in_order(variables, expr.free_symbols)
    if not present:
        return None
    terms = len(expr.args) if isinstance(expr, sympy.Add) else 1
    if terms > MAX_FACTOR_TERMS:
        return None
    try:
        if not expr.is_polynomial(*present):
            return None
        return sympy.Poly(expr, *present)
    except (sympy.PolynomialError, sympy.CoercionFailed, ValueError, TypeError):
        return None


def _never_zero(factor: sympy.Expr) -> bool:
    """``factor`` has no real zero (``exp(-y)``, ``y**2 + 1``; all symbols are real): it is no branch."""
    return bool(factor.is_positive or factor.is_negative)


def square_free_part(expr: sympy.Expr, variables: Sequence[sympy.Symbol]) -> sympy.Expr | None:
    """The square-free part of a constraint with a repeated factor, else ``None``.

    For ``Phi = c f_1^k_1 ... f_r^k_r`` (``f_i`` distinct, non-constant in the phase-space
    ``variables``, ``c`` free of them or without a real zero, like ``exp(-y)``) with some ``k_i > 1`` returns ``f_1 ... f_r``: the
    same zero set, with a gradient that does not vanish on it identically (square-free
    decomposition, Yun's algorithm, via :meth:`sympy.Poly.sqf_list`).
    """
    if isinstance(expr, sympy.Mul):  # factors that never vanish (exp(-y), y**2 + 1) do not shape the surface
        expr = sympy.Mul(*[f for f in expr.args if not _never_zero(f)])
    poly = _polynomial(expr, variables)
    if poly is None:
        return None
    try:
        _, factors = poly.sqf_list()
    except (sympy.PolynomialError, sympy.CoercionFailed, NotImplementedError):
        return None
    if all(k == 1 for _, k in factors):
        return None
    return sympy.Mul(*[f.as_expr() for f, _ in factors if f.total_degree() > 0])


def branches(expr: sympy.Expr, variables: Sequence[sympy.Symbol]) -> list[sympy.Expr]:
    """Distinct factors of a constraint written as a product, that depend on the phase-space ``variables``.

    One element (the constraint itself) unless ``expr`` is a product ``f g ...`` (powers
    counted once) of at least two factors in the variables; its zero set is then the union
    of the branches ``f = 0``, ``g = 0``, ... Only the written product structure is read
    (multivariate factorisation of every constraint would cost more than the analysis);
    a product hidden by expansion is caught by the regular-point and rank checks instead.
    """
    if not isinstance(expr, sympy.Mul):
        return [expr]
    found: list[sympy.Expr] = []
    for arg in expr.args:
        base = arg.base if isinstance(arg, sympy.Pow) and arg.exp.is_Integer and arg.exp > 0 else arg
        if base.free_symbols & set(variables) and base not in found and not _never_zero(base):
            found.append(base)
    return found if len(found) > 1 else [expr]


def _linear_with_constant_coefficient(poly: sympy.Poly) -> bool:
    """Whether ``poly = c v + R`` for a generator ``v`` absent from ``R`` and ``c`` free of the generators.

    Such a polynomial is irreducible: in a product ``A B`` one factor has degree 0 in ``v``
    and divides ``c``, so it is a constant (``p_x + 3 x^2 - z``, most constraints met).
    """
    return _linear_in_a_generator(poly.monoms(), len(poly.gens))


def _linear_in_a_generator(monoms: Sequence[tuple[int, ...]], n: int) -> bool:
    """:func:`_linear_with_constant_coefficient` from the monomials (in the ``n`` generators) of the polynomial."""
    for k in range(n):
        with_k = [m for m in monoms if m[k]]
        if with_k == [tuple(int(j == k) for j in range(n))]:
            return True
    return False


_PLANE = sympy.polys.rings.ring("s,t", sympy.QQ)[0]


#: seed of the random plane (and parameter values) of :func:`_irreducible_on_a_plane`
_PLANE_SEED = 20240607


def _irreducible_on_a_plane(poly: sympy.Poly, seed: int = _PLANE_SEED) -> bool:
    """Whether ``poly`` is shown irreducible by its restriction to a random plane (cheap, one-sided).

    Substitutes random integers for the parameters in the coefficients and
    ``v_i = a_i + b_i s + c_i t`` (random integers) for the generators. A factorisation
    ``f g`` restricts to ``f|g|`` with the same degrees on a plane along which the
    polynomial keeps its total degree, so an irreducible restriction of full degree
    proves ``poly`` irreducible (for generic parameters); the bivariate factorisation costs
    ~1 ms where a multivariate one over a parameter field costs up to a second (Bertini;
    Hilbert's irreducibility theorem makes a reducible restriction of an irreducible
    polynomial improbable). ``False`` means "not shown": factor in full.
    """
    rng = np.random.default_rng(seed)
    images = _plane_images(rng, len(poly.gens))
    expr = poly.as_expr()
    params = sorted(expr.free_symbols - set(poly.gens), key=str)
    try:
        if params:
            expr = expr.subs({p: sympy.Integer(int(rng.integers(2, 14))) for p in params})
        numeric = sympy.Poly(expr, *poly.gens, domain=sympy.QQ)
        return _irreducible_restriction(numeric.terms(), images, poly.total_degree())
    except (ZeroDivisionError, sympy.PolynomialError, sympy.CoercionFailed, NotImplementedError, TypeError, ValueError):
        return False


def _plane_images(rng: np.random.Generator, count: int) -> list:
    """``v_i = a_i + b_i s + c_i t`` (random integers) for ``count`` generators, in the ring of the plane."""
    s, t = _PLANE.gens
    return [int(rng.integers(-9, 10)) + int(rng.integers(1, 10)) * s + int(rng.integers(-9, 10)) * t for _ in range(count)]


def _irreducible_restriction(terms, images: list, degree: int) -> bool:
    """Whether the polynomial with rational ``terms`` ``(monomial, coefficient)``, restricted to the plane
    ``images``, keeps its total ``degree`` and is irreducible there (see :func:`_irreducible_on_a_plane`)."""
    total = _PLANE.zero
    for monom, coeff in terms:
        term = _PLANE(coeff)
        for image, e in zip(images, monom):
            if e:
                term *= image**e
        total += term
    if total.is_zero or max(sum(m) for m in total.monoms()) != degree:
        return False
    _, found = total.factor_list()
    return len(found) == 1 and found[0][1] == 1


def _rational_terms(expr: sympy.Expr, variables: Sequence[sympy.Symbol], seed: int = 20240607) -> dict[tuple[int, ...], Fraction] | None:
    """An expanded polynomial as ``{exponents in the variables it contains: rational coefficient}``.

    Parameters in the coefficients take random integer values (seeded, 2..13, as in
    :func:`_irreducible_on_a_plane`). ``None`` for anything that is not a sum of products of
    numbers and integer powers of symbols (then the caller takes the general path).
    """
    terms = expr.args if isinstance(expr, sympy.Add) else (expr,)
    position = {v: k for k, v in enumerate(variables)}
    rng = np.random.default_rng(seed)
    values = {p: Fraction(int(rng.integers(2, 14))) for p in sorted(expr.free_symbols - position.keys(), key=str)}
    out: dict[tuple[int, ...], Fraction] = {}
    for term in terms:
        exponents = [0] * len(variables)
        coeff = Fraction(1)
        for factor in (term.args if isinstance(term, sympy.Mul) else (term,)):
            base, exp = (factor.base, factor.exp) if isinstance(factor, sympy.Pow) else (factor, sympy.S.One)
            if not exp.is_Integer:
                return None
            if base.is_Rational:
                coeff *= Fraction(int(base.p), int(base.q)) ** int(exp)
            elif base in position and exp > 0:
                exponents[position[base]] += int(exp)
            elif base in values:
                coeff *= values[base] ** int(exp)
            else:
                return None
        key = tuple(exponents)
        out[key] = out.get(key, Fraction(0)) + coeff
    return {m: c for m, c in out.items() if c}


def _rank(rows: list[list[Fraction]]) -> int:
    """Exact rank of a small rational matrix (Gaussian elimination)."""
    rows = [list(r) for r in rows]
    rank = 0
    for col in range(len(rows[0]) if rows else 0):
        pivot = next((r for r in range(rank, len(rows)) if rows[r][col]), None)
        if pivot is None:
            continue
        rows[rank], rows[pivot] = rows[pivot], rows[rank]
        for r in range(rank + 1, len(rows)):
            if rows[r][col]:
                f = rows[r][col] / rows[rank][col]
                rows[r] = [a - f * b for a, b in zip(rows[r], rows[rank])]
        rank += 1
    return rank


def _irreducible_quadric(expr: sympy.Expr, variables: Sequence[sympy.Symbol]) -> bool:
    """Whether a polynomial of total degree 2 is shown irreducible by the rank of its quadric (exact, cheap).

    ``f = z^T S z`` with ``z = (v_1, ..., v_n, 1)`` and ``S`` symmetric (the homogenised
    quadric). A product of two polynomials of degree 1, even over the complex numbers,
    has ``rank S <= 2``; so ``rank S >= 3`` proves ``f`` irreducible (the classification of
    quadrics; e.g. Hodge & Pedoe, *Methods of Algebraic Geometry*, Vol. II, Ch. XIII). The
    parameters take random integer values: the rank at a random value is at most the generic
    one, so the proof holds for generic parameters (as for :func:`_irreducible_on_a_plane`).
    ``False`` means "not shown" (another degree, or rank at most 2): factor in full.
    """
    present = present_in_order(variables, expr.free_symbols)
    terms = _rational_terms(expr, present)
    if not terms or max(sum(m) for m in terms) != 2:
        return False
    n = len(present)
    S = [[Fraction(0)] * (n + 1) for _ in range(n + 1)]
    for monom, c in terms.items():
        used = [k for k, e in enumerate(monom) for _ in range(e)] + [n] * (2 - sum(monom))
        i, j = used
        if i == j:
            S[i][i] += c
        else:
            S[i][j] += c / 2
            S[j][i] += c / 2
    return _rank(S) >= 3
def _sparse_polynomial(expr: sympy.Expr, present: Sequence[sympy.Symbol], params: Sequence[sympy.Symbol]):
    """``expr`` in the sparse ring ``QQ(params)[present]``, by one walk of its tree.

    The same polynomial as ``sympy.Poly(expr, *present)`` (exact arithmetic: coefficients
    are reduced rational functions of the parameters); raises :class:`~dirac.analysis.core.algebra.NotInRing` for any
    other node (a function, a non-integer power, a variable in a denominator).
    """
    domain = sympy.QQ.frac_field(*params) if params else sympy.QQ
    ring = PolyRing(list(present), domain)
    gens = dict(zip(present, ring.gens))
    if params:
        field_gens = dict(zip(params, domain.gens))
        gens.update({p: ring.ground_new(g) for p, g in field_gens.items()})

    def invert(base):  # a power of a parameter expression: a field element; a variable in a denominator: no polynomial
        if not base.is_ground or base.is_zero:
            raise NotInRing
        return ring.ground_new(domain.one / base.LC)

    return ring_value(expr, gens, ring, invert)


def _at(p, point: Sequence[int]):
    """The value in ``QQ`` of a polynomial ``p`` over ``QQ`` at the integer ``point``."""
    total = sympy.QQ(0)
    for monom, coeff in p.terms():
        term = coeff
        for v, e in zip(point, monom):
            if e:
                term *= v**e
        total += term
    return total


def _screened_irreducible(expr: sympy.Expr, variables: Sequence[sympy.Symbol]) -> bool:
    """Whether the cheap tests of :func:`factors` already show ``expr`` irreducible (or no product).

    The decisions of ``poly.total_degree() < 2``, :func:`_linear_with_constant_coefficient`
    and :func:`_irreducible_on_a_plane` for ``poly = _polynomial(expr, variables)``, taken on
    the same polynomial in a sparse ring (no ``Poly`` construction, no ``subs``): the same
    random plane and parameter values, the same exact arithmetic. ``False`` when they do not
    decide it, or when the expression is outside what the ring represents (the full path
    then decides, as before).
    """
    free = expr.free_symbols
    present = present_in_order(variables, free)
    if not present:
        return False
    params = sorted(free - set(present), key=lambda s: s.name)
    try:
        p = _sparse_polynomial(expr, present, params)
    except (NotInRing, ZeroDivisionError, TypeError, ValueError, sympy.CoercionFailed, sympy.PolynomialError):
        return False
    if not p:
        return False
    monoms = list(p.itermonoms())
    degree = max(sum(m) for m in monoms)
    if degree < 2 or _linear_in_a_generator(monoms, len(present)):
        return True
    # _irreducible_on_a_plane: the same random draws, in the same order
    rng = np.random.default_rng(_PLANE_SEED)
    images = _plane_images(rng, len(present))
    terms = list(p.terms())
    if params:  # random integers for the parameters the coefficients contain, in the order of their names
        shown: set[sympy.Symbol] = set()
        for _, c in terms:
            for m in (*c.numer.itermonoms(), *c.denom.itermonoms()):
                shown.update(params[i] for i, e in enumerate(m) if e)
        values = {q: int(rng.integers(2, 14)) for q in sorted(shown, key=str)}
        point = [values.get(q, 0) for q in params]
        try:
            terms = [(m, _at(c.numer, point) / _at(c.denom, point)) for m, c in terms]
        except ZeroDivisionError:
            return False
    try:
        return _irreducible_restriction(terms, images, degree)
    except (ZeroDivisionError, sympy.PolynomialError, sympy.CoercionFailed, NotImplementedError, TypeError, ValueError):
        return False


def factors(expr: sympy.Expr, variables: Sequence[sympy.Symbol], max_terms: int) -> list[sympy.Expr]:
    """The distinct irreducible factors of a polynomial constraint that can vanish (the branches of ``expr = 0``).

    ``[expr]`` when it is irreducible, not polynomial in the ``variables`` or has more than
    ``max_terms`` terms. Multiplicities are dropped (the zero set of ``f^k g`` is that of
    ``f g``), factors free of the variables or without a real zero are left out. A
    polynomial linear in some variable with a coefficient free of the variables is
    irreducible and is not factored (:func:`_linear_with_constant_coefficient`), nor is a
    quadric of rank at least 3 (:func:`_irreducible_quadric`, no polynomial arithmetic:
    rods and their time derivatives), nor one
    whose restriction to a random plane is irreducible (:func:`_irreducible_on_a_plane`);
    the others go through multivariate factorisation (``sympy.factor_list``). A quotient
    ``N / D`` with ``D`` depending on the variables (a constraint the Legendre map left with
    a denominator) has the branches of ``N = 0`` where ``D`` does not vanish: the factors of
    ``N`` are returned when it has several.
    """
    if isinstance(expr, sympy.Mul) and any(isinstance(a, sympy.Pow) and a.exp.is_negative for a in expr.args):
        numerator, denominator = sympy.fraction(expr)
        if denominator.free_symbols & set(variables) and numerator != expr:
            parts = factors(sympy.expand(numerator), variables, max_terms)
            return parts if len(parts) > 1 else [expr]
    terms = len(expr.args) if isinstance(expr, sympy.Add) else 1
    if terms > max_terms or _irreducible_quadric(expr, variables):
        return [expr]
    if _screened_irreducible(expr, variables):
        return [expr]
    poly = _polynomial(expr, variables)
    if poly is None or poly.total_degree() < 2 or _linear_with_constant_coefficient(poly) or _irreducible_on_a_plane(poly):
        return [expr]
    try:
        _, found = sympy.factor_list(poly.as_expr(), *poly.gens)
    except (sympy.PolynomialError, sympy.CoercionFailed, NotImplementedError):
        return [expr]
    parts = [f for f, _ in found if f.free_symbols & set(variables) and not _never_zero(f)]
    return parts if len(parts) > 1 else [expr]


def factored(constraints: Sequence[sympy.Expr], variables: Sequence[sympy.Symbol]) -> list[tuple[sympy.Expr, list[sympy.Expr]]]:
    """The constraints that factor into several branches, with their branches (for error messages).

    Multivariate factorisation (``sympy.factor_list``) of each polynomial constraint of at
    most ``MAX_FACTOR_TERMS`` terms: too costly for every constraint of every analysis,
    used when a rank is found to differ between points of the surface, to name the cause.
    """
    found = []
    for c in constraints:
        poly = _polynomial(c, variables)
        if poly is None:
            continue
        try:
            _, factors = sympy.factor_list(poly.as_expr(), *poly.gens)
        except (sympy.PolynomialError, sympy.CoercionFailed, NotImplementedError):
            continue
        parts = [f for f, _ in factors if f.free_symbols & set(variables)]
        if len(parts) > 1:
            found.append((c, parts))
    return found


def branch_hint(constraints: Sequence[sympy.Expr], variables: Sequence[sympy.Symbol]) -> str:
    """``"; the constraint ... is the union of the branches ...: analyse them separately ..."`` or ``""``.

    For refusals caused by a surface whose parts differ (see :func:`factored`).
    """
    products = factored(constraints, variables)
    if not products:
        return ""
    c, parts = products[0]
    shown = " and ".join(f"{f} = 0" for f in parts)
    return f"; the constraint {c} = 0 is the union of the branches {shown}: analyse them separately (one system each)"


def normal_components(rows: np.ndarray, base: np.ndarray, scales: np.ndarray) -> np.ndarray:
    """Size of each row's component normal to the span of ``base``, relative to ``scales``.

    Parameters
    ----------
    rows
        Gradients of new constraints at one point, shape ``(k, n)``.
    base
        Gradients of the earlier constraints at that point, shape ``(m, n)`` (``m`` may be 0).
    scales
        Size of each new gradient's terms at the point (``1 + sum |term|``), shape ``(k,)``.

    Returns
    -------
    numpy.ndarray
        ``|(1 - P) row| / scale`` for each row, ``P`` the orthogonal projector onto the rows of ``base``.
    """
    if base.size:
        q, r = np.linalg.qr(base.T)
        keep = np.abs(np.diag(r)) > 1e-12 * (np.max(np.abs(r)) if r.size else 1.0)
        q = q[:, keep]
        normal = rows - (rows @ q) @ q.T
    else:
        normal = rows
    return np.linalg.norm(normal, axis=1) / scales


def _written_power(expr: sympy.Expr) -> bool:
    """Whether ``expr`` is written as a power ``f**k`` (``k > 1``) or a product containing one."""
    parts = expr.args if isinstance(expr, sympy.Mul) else (expr,)
    return any(isinstance(a, sympy.Pow) and a.exp.is_Integer and a.exp > 1 and a.base.free_symbols for a in parts)


def regular_holonomic(lagrangian: Lagrangian) -> tuple[Lagrangian, list[str]]:
    """The Lagrangian with each holonomic constraint ``chi = f^k`` (``k > 1``) replaced by ``f``.

    In ``L_ext = L - lambda chi`` (the paper's (1)) the constraint force is ``lambda dchi``;
    for ``chi = f^2`` it vanishes on the surface, so the multiplier cannot hold the motion
    there (the chain ends in a contradiction). Constraints written as such a power are
    decomposed here (an expanded one is found irregular by the chain, which refuses it
    and names its square-free part). The user means the surface ``f = 0``: the
    square-free part describes it regularly (Henneaux–Teitelboim, Sect. 1.1.2). Returns the
    new Lagrangian (the same one if nothing changed) and one note per replacement.
    """
    notes: list[str] = []
    new: list[sympy.Expr] = []
    for k, chi in enumerate(lagrangian.constraints, start=1):
        part = square_free_part(chi, lagrangian.coordinates) if _written_power(chi) else None
        if part is None:
            new.append(chi)
            continue
        if part.could_extract_minus_sign():
            part = -part
        new.append(part)
        notes.append(
            f"constraint {k} ({chi} = 0) is irregular: its gradient vanishes where it holds, so its multiplier "
            f"could not enforce it; it was replaced by its square-free part {part} = 0, the same surface "
            "described regularly"
        )
    if not notes:
        return lagrangian, []
    return dataclasses.replace(lagrangian, constraints=tuple(new)), notes
