"""The plain-Python graph searches give scipy.sparse.csgraph's results exactly.

The reference is scipy's own implementation (``connected_components`` and the
Hopcroft–Karp ``maximum_bipartite_matching``): the analysis chooses pivots and blocks from
these results, so the same matching must be chosen among the maximum ones, not only one
of the same size.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse import csgraph

from dirac.analysis.core.graphs import SMALL_EDGES, connected_components, maximum_bipartite_matching


def _patterns(count: int, seed: int):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        rows, cols = int(rng.integers(1, 13)), int(rng.integers(1, 13))
        density = float(rng.uniform(0.05, 0.6))
        yield (rng.random((rows, cols)) < density).astype(np.int8)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_matching_is_scipys(seed: int) -> None:
    """Every row's column equals scipy's Hopcroft–Karp choice, on 300 random rectangular patterns."""
    for dense in _patterns(300, seed):
        ours = maximum_bipartite_matching(sp.csr_matrix(dense))
        theirs = csgraph.maximum_bipartite_matching(sp.csr_matrix(dense), perm_type="column")
        assert ours.tolist() == np.asarray(theirs).tolist()


def test_matching_hand_example() -> None:
    """Rows {0: col 1 or 2, 1: col 0 or 3, 2: col 0 or 3, 3: col 1 or 2} admit a perfect matching (each row its own column)."""
    dense = np.array([[0, 1, 1, 0], [1, 0, 0, 1], [1, 0, 0, 1], [0, 1, 1, 0]], dtype=np.int8)
    match = maximum_bipartite_matching(sp.csr_matrix(dense))
    assert sorted(match.tolist()) == [0, 1, 2, 3]
    assert all(dense[i, j] for i, j in enumerate(match.tolist()))


def test_matching_leaves_unmatchable_rows() -> None:
    """Two rows that both need column 0 only: one of them stays unmatched (-1)."""
    dense = np.array([[1, 0], [1, 0]], dtype=np.int8)
    assert sorted(maximum_bipartite_matching(sp.csr_matrix(dense)).tolist()) == [-1, 0]


@pytest.mark.parametrize("seed", [4, 5])
def test_components_are_scipys(seed: int) -> None:
    """Count and labels equal scipy's (undirected), on 300 random square patterns."""
    rng = np.random.default_rng(seed)
    for _ in range(300):
        n = int(rng.integers(1, 20))
        dense = (rng.random((n, n)) < rng.uniform(0.0, 0.3)).astype(np.int8)
        count, labels = connected_components(sp.csr_matrix(dense))
        ref_count, ref_labels = csgraph.connected_components(sp.csr_matrix(dense), directed=False)
        assert count == ref_count
        assert labels.tolist() == ref_labels.tolist()


def test_components_hand_example() -> None:
    """The path 0-2-4 and the edge 1-3: two components, labelled in the order of their smallest vertex."""
    edges = sp.coo_matrix((np.ones(3), ([0, 2, 3], [2, 4, 1])), shape=(5, 5))
    count, labels = connected_components(edges)
    assert count == 2
    assert labels.tolist() == [0, 1, 0, 1, 0]


def test_large_patterns_go_to_scipy() -> None:
    """Past SMALL_EDGES stored entries the scipy functions answer (the same results)."""
    n = 200
    rng = np.random.default_rng(7)
    dense = (rng.random((n, n)) < (SMALL_EDGES + 2000) / n**2).astype(np.int8)
    assert sp.csr_matrix(dense).nnz > SMALL_EDGES
    ours = maximum_bipartite_matching(sp.csr_matrix(dense))
    assert ours.tolist() == np.asarray(csgraph.maximum_bipartite_matching(sp.csr_matrix(dense), perm_type="column")).tolist()
    count, labels = connected_components(sp.csr_matrix(dense))
    assert (count, labels.tolist()) == tuple((c if i == 0 else c.tolist()) for i, c in enumerate(csgraph.connected_components(sp.csr_matrix(dense), directed=False)))


@pytest.mark.parametrize("seed", [8, 9])
def test_dense_patterns_give_scipys_results(seed: int) -> None:
    """A dense array (its non-zero entries the edges) gives scipy's matching and components, on 300 random patterns each."""
    for dense in _patterns(300, seed):
        theirs = csgraph.maximum_bipartite_matching(sp.csr_matrix(dense), perm_type="column")
        assert maximum_bipartite_matching(dense).tolist() == np.asarray(theirs).tolist()
    rng = np.random.default_rng(seed)
    for _ in range(300):
        n = int(rng.integers(1, 20))
        dense = rng.random((n, n)) < rng.uniform(0.0, 0.3)  # a boolean pattern
        count, labels = connected_components(dense)
        ref_count, ref_labels = csgraph.connected_components(sp.csr_matrix(dense), directed=False)
        assert (count, labels.tolist()) == (ref_count, ref_labels.tolist())


def test_large_dense_pattern_goes_to_scipy() -> None:
    """A dense array with more than SMALL_EDGES non-zeros is searched by scipy (the same matching)."""
    n = 200
    dense = (np.random.default_rng(10).random((n, n)) < (SMALL_EDGES + 2000) / n**2).astype(np.int8)
    assert np.count_nonzero(dense) > SMALL_EDGES
    theirs = csgraph.maximum_bipartite_matching(sp.csr_matrix(dense), perm_type="column")
    assert maximum_bipartite_matching(dense).tolist() == np.asarray(theirs).tolist()
