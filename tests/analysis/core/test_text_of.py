"""Printing with shared sub-trees remembered (dirac.analysis.core.algebra.text_of) gives sympy's texts.

The reference is sympy's own ``str`` and ``sstr(order="none")`` of the same expressions.
"""

from __future__ import annotations

import sympy

from dirac.analysis.core.algebra import printed, text_of

x, y, z = sympy.symbols("x y z")


def _expressions() -> list[sympy.Expr]:
    shared = (x * y - 2 * z) ** 2 / (1 + x**2)
    return [
        shared * x - shared * y / 3 + sympy.sqrt(shared),
        sympy.Float("0.1") + x * sympy.Float("2.50"),  # floats print alike at every nesting level
        sympy.Float("1.25"),
        -x / (2 * y) + sympy.Rational(3, 7) * x**-2,
        sympy.sin(shared) * sympy.exp(-x) - shared,
        (x + y) * (x - y) * (shared + 1),
    ]


def test_same_text_as_sympy() -> None:
    """Every expression prints as str(expr) and as sstr(expr, order="none"), twice in a row (the second from the memo)."""
    for _ in range(2):
        for e in _expressions():
            assert text_of(e) == str(e)
            assert text_of(e, order="none") == sympy.sstr(e, order="none")
            assert printed(e) == str(e)


def test_hand_written_text() -> None:
    """x*y + (x*y)**2 prints as written by hand: x**2*y**2 + x*y."""
    assert text_of(x * y + (x * y) ** 2) == "x**2*y**2 + x*y"


def test_memo_emptied_past_its_bound(monkeypatch) -> None:
    """With a bound of 10 characters the memo is emptied before each print: it then holds what
    printing that expression alone leaves in an empty memo, and the texts stay sympy's."""
    from dirac.analysis.core import algebra

    memo = algebra._SUBTREES.setdefault(algebra._SharedTextPrinter({"order": None})._key, {})
    alone = []
    for e in _expressions():
        memo.clear()
        text_of(e)
        alone.append(dict(memo))
    monkeypatch.setattr(algebra, "SUBTREE_CHARACTERS", 10)
    for e, expected in zip(_expressions(), alone):
        assert text_of(e) == str(e)
        assert memo == expected
