"""Connected components and maximum bipartite matchings of small sparsity patterns, in plain Python.

``scipy.sparse.csgraph`` imports ``scipy.sparse.linalg`` and ``scipy.linalg`` with it
(about 0.1-0.2 s of a fresh process), while the patterns of an analysis of a few
coordinates have tens of rows. Here both searches run in Python up to :data:`SMALL_EDGES`
edges and give the results of the scipy functions exactly; larger patterns go to scipy.
Both take a sparse matrix or a dense array (its non-zero entries are the edges): the
analysis of a few coordinates then never imports ``scipy.sparse`` at all (about 0.13 s of
a fresh process, through scipy's array-API layer and ``numpy.f2py``).

* :func:`connected_components`: the components of the undirected graph, labelled in the
  order of their smallest vertex (the labels scipy's search gives: a new label at each
  vertex not reached from an earlier one).
* :func:`maximum_bipartite_matching`: the Hopcroft–Karp algorithm (J. E. Hopcroft and
  R. M. Karp, SIAM J. Comput. 2 (1973) 225) in the order of ``scipy.sparse.csgraph``'s
  implementation, so that the same matching is chosen among the maximum ones: layers by a
  breadth-first search from the unmatched rows, then from each unmatched row in turn a
  depth-first search along the layers with an explicit stack (neighbours in column
  order, the last pushed explored first), each path found flipped at once.
"""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # scipy.sparse is imported where it is used
    import scipy.sparse as sp

__all__ = ["SMALL_EDGES", "connected_components", "issparse", "maximum_bipartite_matching"]

#: patterns with at most this many stored entries are searched in Python
SMALL_EDGES = 4096


def issparse(matrix: Any) -> bool:
    """Whether ``matrix`` is a ``scipy.sparse`` matrix, without importing ``scipy.sparse`` when it was never imported.

    No sparse matrix can exist before ``scipy.sparse`` is imported, so the answer is then ``False``.
    """
    module = sys.modules.get("scipy.sparse")
    return module is not None and bool(module.issparse(matrix))


def _edges(graph: sp.spmatrix | np.ndarray) -> tuple[tuple[int, int], list[int], list[int]] | None:
    """``(shape, rows, columns)`` of the non-zero entries of a dense ``graph``, row by row in column order.

    The order of a CSR matrix with sorted indices (what :func:`maximum_bipartite_matching`
    walks). ``None`` for a sparse matrix or for more than :data:`SMALL_EDGES` entries.
    """
    if issparse(graph):
        return None
    dense = np.asarray(graph)
    rows, cols = np.nonzero(dense)  # row-major: by row, then by column
    if len(rows) > SMALL_EDGES:
        return None
    return (int(dense.shape[0]), int(dense.shape[1])), rows.tolist(), cols.tolist()


def connected_components(graph: sp.spmatrix | np.ndarray) -> tuple[int, np.ndarray]:
    """``(count, labels)`` of the undirected graph of the square ``graph`` (sparse or dense; non-zero entries are edges).

    The same result as ``scipy.sparse.csgraph.connected_components(graph, directed=False)``.
    """
    edges = _edges(graph)
    if edges is None:
        import scipy.sparse as sp  # imported when used: a dense pattern of a small system never needs it

        graph = sp.csr_matrix(graph)
        if graph.nnz > SMALL_EDGES:
            from scipy.sparse.csgraph import connected_components as scipy_components

            count, labels = scipy_components(graph, directed=False)
            return int(count), labels
        coo = graph.tocoo()
        edges = graph.shape, coo.row.tolist(), coo.col.tolist()
    (n, _), edge_rows, edge_cols = edges
    parent = list(range(n))

    def root(v: int) -> int:
        while parent[v] != v:
            parent[v] = parent[parent[v]]
            v = parent[v]
        return v

    for i, j in zip(edge_rows, edge_cols):
        a, b = root(i), root(j)
        if a != b:
            parent[max(a, b)] = min(a, b)  # each root is the smallest vertex of its set
    labels = np.empty(n, dtype=np.int32)
    label_of: dict[int, int] = {}
    for v in range(n):
        labels[v] = label_of.setdefault(root(v), len(label_of))
    return len(label_of), labels


def maximum_bipartite_matching(graph: sp.spmatrix | np.ndarray) -> np.ndarray:
    """The column matched to each row of ``graph`` (sparse or dense; ``-1``: unmatched).

    The same result as ``scipy.sparse.csgraph.maximum_bipartite_matching(graph,
    perm_type="column")``.
    """
    edges = _edges(graph)
    if edges is None:
        import scipy.sparse as sp  # imported when used: a dense pattern of a small system never needs it

        graph = sp.csr_matrix(graph)
        if graph.nnz > SMALL_EDGES:
            from scipy.sparse.csgraph import maximum_bipartite_matching as scipy_matching

            return np.asarray(scipy_matching(graph, perm_type="column"))
        graph.sort_indices()
        indptr, indices = graph.indptr.tolist(), graph.indices.tolist()
        rows, cols = graph.shape
        neighbours = [indices[indptr[v]: indptr[v + 1]] for v in range(rows)]
    else:
        (rows, cols), edge_rows, edge_cols = edges
        neighbours = [[] for _ in range(rows)]
        for i, j in zip(edge_rows, edge_cols):
            neighbours[i].append(j)
    free = rows  # a column matched to this extra vertex is unmatched
    row_match = [-1] * rows
    col_match = [free] * cols
    far = float("inf")
    while True:
        # layers: breadth-first from the unmatched rows, through matched columns
        level = [0 if row_match[v] < 0 else far for v in range(rows)] + [far]
        queue = [v for v in range(rows) if row_match[v] < 0]
        head = 0
        while head < len(queue):
            v = queue[head]
            head += 1
            if level[v] < level[free]:
                for u in neighbours[v]:
                    w = col_match[u]
                    if level[w] == far:
                        level[w] = level[v] + 1
                        queue.append(w)
        if level[free] == far:  # no augmenting path left: the matching is maximum
            break
        parents = [0] * rows
        for start in range(rows):
            if row_match[start] >= 0:
                continue
            stack = [start]
            found = False
            while stack and not found:
                v = stack.pop()
                for u in neighbours[v]:
                    w = col_match[u]
                    if level[w] != level[v] + 1:
                        continue
                    if w == free:  # an augmenting path: flip it back to its start
                        found = True
                        while True:
                            level[v] = far  # each row in one path of this round only
                            previous = row_match[v]
                            col_match[u] = v
                            row_match[v] = u
                            u = previous
                            if v == start:
                                break
                            v = parents[v]
                        break
                    stack.append(w)
                    parents[w] = v
    return np.asarray(row_match, dtype=np.int32)
