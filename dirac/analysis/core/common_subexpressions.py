"""Texts of large expressions through named common sub-expressions, in time linear in their graph.

A multiplier solved by block elimination is a graph whose sub-trees are shared many times
over: as one tree (what ``str`` prints) it can hold tens of millions of nodes. Printed
through names for the shared sub-trees, its text is proportional to its graph instead.
The sub-trees named are those met more than once in a walk of the trees that does not
enter a sub-tree met before (the rule of sympy's ``tree_cse``, Sect. "cse" of the sympy
docs); sympy's ``cse`` also rebuilds every expression with the names in place and looks for
common subsets of the arguments of sums and products, which is quadratic in the number of
those arguments and took seconds on the multipliers of a 24-link chain. Here each named
sub-tree and each expression is rebuilt once, with the names of the sub-trees it holds in
their places, and printed: every node of the graph is walked a bounded number of times.

Reading the definitions back in order (``cse_k = definitions["cse_k"]``, each using
earlier names only) and then the texts gives the expressions again.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from itertools import count

import sympy

from dirac.analysis.core.algebra import shared_xreplace
from dirac.analysis.core.phase_space import free_symbols_of

__all__ = ["named_subexpressions"]

#: a repeated sub-tree of at most this many tree nodes (``2*x``, ``x**2``, ``x*y``) is printed
#: where it stands: its name would be no shorter than its text
SMALL_SUBTREE = 3


def _repeated(exprs: Sequence[sympy.Basic]) -> list[sympy.Basic]:
    """Sub-trees with arguments met more than once in the trees of ``exprs``, children before parents.

    A walk that does not enter a sub-tree met before (each node's arguments are visited
    once) marks a node met a second time; the marked nodes are then listed in post-order,
    so that every sub-tree comes after the named sub-trees it holds.
    """
    seen: set[sympy.Basic] = set()
    repeated: set[sympy.Basic] = set()
    stack = list(reversed(exprs))
    while stack:
        node = stack.pop()
        if not node.args:
            continue
        if node in seen:
            repeated.add(node)
            continue
        seen.add(node)
        stack.extend(reversed(node.args))
    small: dict[sympy.Basic, int] = {}

    def size(node: sympy.Basic) -> int:  # tree nodes, counted up to SMALL_SUBTREE + 1
        hit = small.get(node)
        if hit is None:
            hit = 1
            for a in node.args:
                hit += size(a) if a.args else 1
                if hit > SMALL_SUBTREE:
                    break
            small[node] = hit
        return hit

    ordered: list[sympy.Basic] = []
    done: set[sympy.Basic] = set()
    for root in exprs:  # post-order, each node once
        walk = [(root, False)]
        while walk:
            node, expanded = walk.pop()
            if node in done or not node.args:
                continue
            if expanded:
                done.add(node)
                if node in repeated and size(node) > SMALL_SUBTREE:
                    ordered.append(node)
                continue
            walk.append((node, True))
            walk.extend((a, False) for a in reversed(node.args) if a.args and a not in done)
    return ordered


def named_subexpressions(
    exprs: Sequence[sympy.Basic],
    prefix: str,
    text: Callable[[sympy.Basic], str],
    definition_text: Callable[[sympy.Basic], str] | None = None,
) -> tuple[list[str], dict[str, str]]:
    """Texts of ``exprs`` in which names ``<prefix>0, <prefix>1, ...`` stand for their shared sub-trees.

    Each named sub-tree, and each expression, is rebuilt once with the names of the
    sub-trees it holds in their places (one walk of its part of the graph,
    :func:`~dirac.analysis.core.algebra.shared_xreplace`) and printed by ``text``.

    Parameters
    ----------
    exprs
        The expressions.
    prefix
        Stem of the names; a name that is also the name of a symbol of ``exprs`` is skipped.
    text
        The printer of one expression (the report's ``str`` with its order of terms).
    definition_text
        The printer of a definition (default: ``text``).

    Returns
    -------
    (texts, definitions)
        ``texts[i]`` is the text of ``exprs[i]``; ``definitions`` maps each name to the
        text of its sub-tree, in which only earlier names occur.
    """
    exprs = list(exprs)
    used = {s.name for s in free_symbols_of(exprs) if isinstance(s, sympy.Symbol)}
    fresh = (name for name in (f"{prefix}{k}" for k in count()) if name not in used)
    repeated = _repeated(exprs)
    rule = {node: sympy.Symbol(next(fresh)) for node in repeated}

    def inside(node: sympy.Basic) -> sympy.Basic:  # the node with the names of the sub-trees it holds
        return node.func(*[shared_xreplace(a, rule) for a in node.args])

    definition_text = text if definition_text is None else definition_text
    definitions = {rule[node].name: definition_text(inside(node)) for node in repeated}
    texts = [text(shared_xreplace(e, rule)) for e in exprs]
    return texts, definitions
