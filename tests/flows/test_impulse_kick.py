"""The jump of the momenta at an impulse (dirac.flows.impulse_kick): the projection formula by
hand, and the same bits run by Python and compiled by numba (what lets an ensemble member
equal a single run)."""

from __future__ import annotations

import numpy as np
import pytest

from dirac.flows.impulse_kick import impulse_kick, kick_source


def _random_case(rng: np.random.Generator, n: int, m: int):
    A = rng.normal(size=(n, n))
    M = A @ A.T + n * np.eye(n)  # symmetric positive definite
    G = rng.normal(size=(m, n))
    return M, G, rng.normal(size=n), rng.normal(size=n)


@pytest.mark.parametrize("n, m", [(1, 0), (2, 1), (4, 2), (6, 3)])
def test_the_kick_is_the_projected_impulse(n, m):
    """Delta p = J - G^T (G M^-1 G^T)^-1 G M^-1 J (so G M^-1 Delta p = 0: the velocity stage
    keeps holding), and the work is J . (v_before + v_after) / 2 (Lamb, Higher Mechanics,
    Sect. 27), against numpy's solves of the same formulas."""
    rng = np.random.default_rng(7 + n)
    M, G, p, J = _random_case(rng, n, m)
    after = p.copy()
    work = impulse_kick(M, G, after, J)
    kick = J.copy()
    if m:
        kick = J - G.T @ np.linalg.solve(G @ np.linalg.solve(M, G.T), G @ np.linalg.solve(M, J))
    assert np.allclose(after, p + kick, rtol=1e-12, atol=1e-12)
    if m:
        assert np.allclose(G @ np.linalg.solve(M, after - p), 0.0, atol=1e-12)
    expected = J @ (np.linalg.solve(M, p) + np.linalg.solve(M, p + kick)) / 2
    assert work == pytest.approx(expected, rel=1e-12, abs=1e-14)


def test_python_and_numba_give_the_same_bits():
    """kick_source is the text of impulse_kick under numba.njit: compiled, it gives the momenta
    and the work Python gives, bit for bit (no fused or reordered arithmetic), over random cases."""
    import numba

    namespace: dict = {"numba": numba, "np": np}
    text = kick_source().replace("cache=True", "cache=False")  # no file to cache it beside
    exec(compile(text, "<kick_source>", "exec"), namespace)
    compiled = namespace["impulse_kick"]
    assert isinstance(compiled, numba.core.registry.CPUDispatcher)
    rng = np.random.default_rng(3)
    for n, m in [(1, 0), (2, 1), (3, 1), (4, 2), (5, 3), (8, 4)] * 5:
        M, G, p, J = _random_case(rng, n, m)
        by_python, by_numba = p.copy(), p.copy()
        work_python = impulse_kick(M, G, by_python, J)
        work_numba = compiled(M, G, by_numba, J)
        assert np.array_equal(by_python, by_numba)
        assert float(work_python) == float(work_numba)
