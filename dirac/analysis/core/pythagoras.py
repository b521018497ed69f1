"""Polynomials in sines and cosines, reduced exactly with ``sin(u)^2 + cos(u)^2 = 1``.

A function of angles written through ``sin(u)`` and ``cos(u)`` is a polynomial in the
symbols ``s_u = sin(u)``, ``c_u = cos(u)`` restricted to the circles ``s_u^2 + c_u^2 = 1``.
Its remainder modulo the circle polynomials (a Groebner basis: their leading monomials
are coprime; Cox, Little & O'Shea, "Ideals, Varieties, and Algorithms", 4th ed., 2015,
Sect. 2.9, Prop. 4) is the same function of the angles; eliminating the squares of the
sines, or of the cosines, whichever leaves fewer terms, is the reduction used here. It
decides what ``sympy.trigsimp`` was asked for (``sin(psi)^2 + cos(psi)^2`` is 1), exactly
and in milliseconds: ``trigsimp`` of the four-term factor ``I r^2 cos(th)^2 - 2 I r s
cos(th) + I s^2 + m r^2 s^2 sin(th)^2`` of a slider-crank did not end in five minutes.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy
from sympy.polys.polyerrors import BasePolynomialError, PolynomialError

from dirac.analysis.core.algebra import rational_parts

__all__ = ["CirclePolynomial", "circle_polynomial", "pythagorean_form", "trig_arguments"]


def trig_arguments(expr: sympy.Expr) -> set[sympy.Expr]:
    """The arguments ``u`` of the ``sin(u)`` and ``cos(u)`` in ``expr``."""
    return {node.args[0] for node in sympy.preorder_traversal(expr) if isinstance(node, (sympy.sin, sympy.cos))}


@dataclass(frozen=True)
class CirclePolynomial:
    """``expr`` as a polynomial in sine and cosine symbols, reduced on the circles.

    Attributes
    ----------
    polynomial
        The reduced polynomial in ``sines``, ``cosines`` and the other symbols of ``expr``.
    sines, cosines
        The real symbols standing for ``sin(u)`` and ``cos(u)``, one pair per argument ``u``
        (in ``sympy.default_sort_key`` order of the arguments).
    back
        Symbol -> the function it stands for (``polynomial.xreplace(back)`` is ``expr``
        as a function of the angles).
    """

    polynomial: sympy.Expr
    sines: list[sympy.Symbol]
    cosines: list[sympy.Symbol]
    back: dict[sympy.Symbol, sympy.Expr]


def circle_polynomial(expr: sympy.Expr, by_angle: bool = True) -> CirclePolynomial | None:
    """``expr`` reduced modulo ``s_u^2 + c_u^2 - 1`` (see the module text); ``None`` when it has
    no sines or cosines or is not a polynomial in them (a sine in a denominator).

    The shortest of: ``expr`` as it is, all sines eliminated, all cosines eliminated (of the
    angles whose sine and cosine both occur), and
    (with ``by_angle``) each angle in turn left alone or reduced by its sine or its cosine,
    whichever leaves the fewest terms (``M + m - m cos(u)^2`` is ``M + m sin(u)^2``).
    """
    arguments = sorted(trig_arguments(expr), key=sympy.default_sort_key)
    if not arguments:
        return None
    sines = [sympy.Symbol(f"_s{k}", real=True) for k in range(len(arguments))]
    cosines = [sympy.Symbol(f"_c{k}", real=True) for k in range(len(arguments))]
    to_symbols: dict[sympy.Expr, sympy.Symbol] = {sympy.sin(u): s for u, s in zip(arguments, sines)}
    to_symbols.update({sympy.cos(u): c for u, c in zip(arguments, cosines)})
    polynomial = sympy.expand(expr.xreplace(to_symbols))
    if polynomial.has(sympy.sin, sympy.cos) or not polynomial.is_polynomial(*sines, *cosines):
        return None  # sines of sums written another way, or not a polynomial in them
    present = [(s, c) for s, c in zip(sines, cosines) if polynomial.has(s) or polynomial.has(c)]
    others = sorted(polynomial.free_symbols - set(sines) - set(cosines), key=str)
    every = [*sines, *cosines]

    def reduced(p: sympy.Expr, leading: list[sympy.Symbol], pairs: list[tuple[sympy.Symbol, sympy.Symbol]]) -> sympy.Expr:
        circle = [s**2 + c**2 - 1 for s, c in pairs]
        rest = [g for g in every if g not in leading]
        try:
            remainder = sympy.reduced(p, circle, *leading, *rest, *others)[1]
        except PolynomialError:  # a parameter in a denominator: the parameters as coefficients
            remainder = sympy.reduced(p, circle, *leading, *rest)[1]
        return sympy.expand(remainder)

    def size(p: sympy.Expr) -> int:
        return len(sympy.Add.make_args(p))

    both = [(s, c) for s, c in present if polynomial.has(s) and polynomial.has(c)]
    candidates = [polynomial]
    try:
        if both:  # all the sines, or all the cosines, of the angles that have both
            candidates += [reduced(polynomial, [pair[k] for pair in both], both) for k in (0, 1)]
        if present and by_angle:
            step = polynomial
            for pair in present:
                step = min([step, *(reduced(step, [pair[k]], [pair]) for k in (0, 1))], key=size)
            candidates.append(step)
    except (BasePolynomialError, NotImplementedError):  # sympy could not divide: no reduction claimed
        return None
    polynomial = min(candidates, key=size)
    back = {symbol: function for function, symbol in to_symbols.items()}
    return CirclePolynomial(polynomial, sines, cosines, back)


def pythagorean_form(expr: sympy.Expr) -> sympy.Expr:
    """``expr`` with ``sin(u)^2 + cos(u)^2 = 1`` used where that leaves fewer terms, else ``expr``.

    The same function of the angles (:func:`circle_polynomial`): ``sin(psi)**2 + cos(psi)**2``
    is ``1``, ``a*sin(u)**2 + a*cos(u)**2 + b`` is ``a + b``. A quotient is taken as its
    reduced numerator over its reduced denominator
    (:func:`~dirac.analysis.core.algebra.rational_parts`, sines and cosines as generators).
    """
    reduced = circle_polynomial(expr)
    if reduced is not None:
        if len(sympy.Add.make_args(reduced.polynomial)) >= len(sympy.Add.make_args(sympy.expand(expr))):
            return expr
        return reduced.polynomial.xreplace(reduced.back)
    parts = rational_parts(expr)
    if parts is None or parts[1] == 1:
        return expr
    pieces = [circle_polynomial(part) for part in parts]
    if all(piece is None for piece in pieces):
        return expr
    numerator, denominator = (part if piece is None else piece.polynomial.xreplace(piece.back)
                              for part, piece in zip(parts, pieces))
    before = sum(len(sympy.Add.make_args(part)) for part in parts)
    if len(sympy.Add.make_args(numerator)) + len(sympy.Add.make_args(denominator)) >= before:
        return expr
    try:
        return sympy.factor(numerator) / sympy.factor(denominator)
    except (BasePolynomialError, NotImplementedError):
        return numerator / denominator
