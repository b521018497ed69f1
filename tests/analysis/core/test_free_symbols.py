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


def test_a_large_sparse_matrix_is_read_by_its_non_zero_entries(monkeypatch):
    """A 3000 x 3000 matrix with one symbol per row (9 million entries, 3000 of them non-zero):
    the symbols of its non-zero entries, and no entry read one by one (reading them took
    1-3 s of the 16 x 16 Maxwell torus's analysis, its 768 x 768 Hessian)."""
    n = 3000
    symbols = sympy.symbols(f"x0:{n}")
    M = sympy.zeros(n, n)
    for i, s in enumerate(symbols):
        M[i, (7 * i) % n] = 2 * s + 1
    read: list = []
    original = type(M).__getitem__

    def counted(self, key):
        read.append(key)
        return original(self, key)

    monkeypatch.setattr(type(M), "__getitem__", counted)
    assert free_symbols_of(M) == frozenset(symbols)
    assert not read
