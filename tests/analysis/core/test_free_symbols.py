"""Free symbols of expressions that share sub-trees (:func:`dirac.analysis.core.phase_space.free_symbols_of`)."""

import sympy

from dirac.analysis.core.phase_space import free_symbols_of


def _doubling(depth: int) -> tuple[sympy.Expr, sympy.Symbol, sympy.Symbol, sympy.Symbol]:
    """``e_0 = x``, ``e_{k+1} = e_k * (e_k + y)`` (unexpanded): a tree of about ``2^depth`` nodes in ``depth`` shared steps."""
    x, y, a = sympy.symbols("x y a")
    e: sympy.Expr = x
    for _ in range(depth):
        e = sympy.Mul(e, sympy.Add(e, y, evaluate=False), evaluate=False)
    return e, x, y, a


def test_a_tree_of_2_to_the_60_nodes_is_walked_once_per_shared_node():
    """By hand: every ``e_k`` contains ``x`` and, from ``k = 1`` on, ``y``; nothing else.

    The tree has more than ``2^60`` nodes, so a walk of the tree (sympy's own
    ``free_symbols``) would never end; the walk of the shared nodes takes ``60`` steps.
    """
    e, x, y, _ = _doubling(60)
    assert free_symbols_of([e]) == {x, y}


def test_matrix_entries_and_a_shared_memo():
    """The symbols of all entries together; a memo reused across calls gives the same answer."""
    e, x, y, a = _doubling(40)
    M = sympy.Matrix([[e, a], [0, 1]])
    memo: dict = {}
    assert free_symbols_of(M, memo) == {x, y, a}
    assert free_symbols_of(M[0:1, 1:2], memo) == {a}
    assert free_symbols_of(sympy.Matrix([[0, 2]]), memo) == frozenset()
