"""Dirac brackets and the motion at a numeric point, against the closed forms of the planar chain.

The chain of ``n`` links (``dirac_systems.scale_models.chain``): masses ``m`` at
``r_k = (x_k, y_k)``, rods ``chi_1 = |r_1|^2 - l^2``, ``chi_k = |r_k - r_{k-1}|^2 - l^2``,
gravity ``V = m g sum_k y_k``. The engine works on the extended phase space
``z = (q, lambda; p, p_lambda)`` (the multipliers as coordinates) with four families of
second-class constraints: ``p_lambda = 0``, ``chi = 0``, ``psi = G M^{-1} p = 0`` (with
``G = d chi/dq``, ``M = m 1``) and the fourth stage ``omega(q, p, lambda) = 0``, which is
linear in ``lambda`` with the invertible coefficient ``-G M^{-1} G^T`` (up to a factor).

Hand derivation of the brackets of coordinates and momenta. The Dirac bracket over all
second-class constraints equals the one obtained in two steps (Dirac, *Lectures on
Quantum Mechanics*; Henneaux & Teitelboim 1.3.3): first over the pair
``(p_lambda, omega)``, with ``C_1 = [[0, A], [-A^T, W]]``, ``A = {p_lambda, omega}``
invertible; ``C_1^{-1} = [[A^{-T} W A^{-1}, -A^{-T}], [A^{-1}, 0]]``. A function ``f(q, p)``
has ``{f, p_lambda} = 0``, so the correction ``{f, Phi} C_1^{-1} {Phi, g}`` reads only the
``(omega, omega)`` block of ``C_1^{-1}``, which is zero: on functions of ``(q, p)`` the
first bracket is the Poisson bracket. Then over ``(chi, psi)``, with
``C_2 = [[0, K], [-K, Y]]``, ``K = {chi, psi} = G M^{-1} G^T`` (symmetric, invertible on
the surface), ``C_2^{-1} = [[K^{-1} Y K^{-1}, -K^{-1}], [K^{-1}, 0]]``. With
``{q_i, chi} = 0``, ``{q_i, psi_b} = (G M^{-1})_{bi}``, ``{chi_a, p_j} = G_{aj}``:

    {q_i, q_j}_D = 0,
    {q_i, p_j}_D = delta_ij - (M^{-1} G^T (G M^{-1} G^T)^{-1} G)_ij = delta_ij - (J^T (J J^T)^{-1} J)_ij,

with ``J = G`` (``M = m 1`` cancels): the orthogonal projector onto the tangent space of
the configuration manifold. And ``p_lambda`` is itself a second-class constraint, so
``{p_lambda_k, F}_D = 0`` for every ``F`` (a Casimir of (240)).

The motion (Hairer, Lubich & Wanner VII.1, the index-1 form of the constrained Newton
equations): ``q_dot = M^{-1} p``, ``p_dot = -grad V + G^T mu`` with ``mu`` from
``d/dt (G v) = 0``: ``G M^{-1} G^T mu = G M^{-1} grad V - G_dot v``; for the chain
``(G_dot v)_k = 2 |v_k - v_{k-1}|^2`` (``v_0 = 0``).
"""

from __future__ import annotations

import numpy as np
import pytest

import dirac
from dirac.errors import InputError
from dirac_systems.scale_models import chain


def _rods(point: dict[str, float], n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``G`` (n, 2n) over (x1, y1, x2, ...), the positions and the momenta at ``point``."""
    r = np.array([[point[f"x{k}"], point[f"y{k}"]] for k in range(1, n + 1)])
    p = np.array([[point[f"p_x{k}"], point[f"p_y{k}"]] for k in range(1, n + 1)])
    G = np.zeros((n, 2 * n))
    for k in range(n):
        d = r[k] - (r[k - 1] if k else 0.0)
        G[k, 2 * k : 2 * k + 2] = 2 * d
        if k:
            G[k, 2 * k - 2 : 2 * k] = -2 * d
    return G, r.ravel(), p.ravel()


@pytest.fixture(scope="module", params=[3, 12], ids=["dense C (12 constraints)", "sparse C (48 constraints)"])
def chain_analysis(request):
    n = request.param
    return n, dirac.analyze(chain(n))


def test_coordinate_momentum_brackets_are_the_tangent_projector(chain_analysis):
    """{q_i, p_j}_D = delta_ij - (G^T (G G^T)^{-1} G)_ij and {q_i, q_j}_D = 0 at two surface
    points with moving links (hand derivation in the module docstring)."""
    n, analysis = chain_analysis
    names = [c for k in range(1, n + 1) for c in (f"x{k}", f"y{k}")]
    for seed in (1, 2):
        point = analysis.surface_point(seed=seed)
        G, _, p = _rods(point, n)
        assert np.abs(p).max() > 1e-3  # the links move (a generic point)
        expected = np.eye(2 * n) - G.T @ np.linalg.solve(G @ G.T, G)
        for i, qi in enumerate(names):
            for j, qj in enumerate(names):
                value = analysis.dirac_bracket(qi, "p_" + qj, at=point)
                assert value == pytest.approx(expected[i, j], abs=1e-9)
                assert abs(analysis.dirac_bracket(qi, qj, at=point)) < 1e-9


def test_multiplier_momenta_are_casimirs(chain_analysis):
    """p_lambda_k is a second-class constraint: {p_lambda_k, F}_D = 0 for any F (240)."""
    n, analysis = chain_analysis
    point = analysis.surface_point(seed=3)
    s = analysis.symbols
    for k in (1, n):
        momentum = s[f"p_lambda_{k}"]
        for other in ("x1", f"p_y{n}", s[f"x{n}"] * s[f"p_x{n}"] + s["y1"] ** 2):
            assert abs(analysis.dirac_bracket(momentum, other, at=point)) < 1e-9


def test_motion_at_a_point_is_the_constrained_newton_equation(chain_analysis):
    """equations_of_motion(at=point): q_dot = p/m and p_dot = -grad V + G^T mu with
    (G G^T) mu = G grad V - m G_dot v (module docstring), m = 1, g = 9.81."""
    n, analysis = chain_analysis
    point = analysis.surface_point(seed=4)
    G, _, p = _rods(point, n)
    v = p.reshape(n, 2)
    relative = v - np.vstack([np.zeros(2), v[:-1]])
    g_dot_v = 2 * np.sum(relative**2, axis=1)
    grad_V = np.tile([0.0, 9.81], n)
    mu = np.linalg.solve(G @ G.T, G @ grad_V - g_dot_v)
    p_dot = -grad_V + G.T @ mu
    rates = analysis.equations_of_motion(at=point)
    s = analysis.symbols
    names = [c for k in range(1, n + 1) for c in (f"x{k}", f"y{k}")]
    for i, name in enumerate(names):
        assert rates[s[name]] == pytest.approx(p[i], abs=1e-9)
        assert rates[s["p_" + name]] == pytest.approx(p_dot[i], abs=1e-8)
    some = analysis.equations_of_motion([names[0], s["p_" + names[-1]] ** 2], at=point)
    assert some[s[names[0]]] == pytest.approx(p[0], abs=1e-9)
    assert some[s["p_" + names[-1]] ** 2] == pytest.approx(2 * p[-1] * p_dot[-1], abs=1e-8)


def test_singular_point_is_refused():
    """At the origin every rod of chain(2) has zero length: G = 0 and C is singular."""
    analysis = dirac.analyze(chain(2))
    point = {s.name: 0.0 for s in analysis.phase_space}
    with pytest.raises(InputError, match="singular"):
        analysis.dirac_bracket("x1", "p_x1", at=point)


def test_the_exact_bracket_has_a_budget_that_names_the_numeric_road():
    """The exact ``{x1, p_x1}_D`` of the one-link chain is ``1 - x1^2 / (x1^2 + y1^2)`` by hand (the tangent
    projector above, ``J = (2 x1, 2 y1)``), with or without a budget (compared at a point of the rod's circle,
    where the weakly simplified form agrees); with no CPU time at all it is refused, naming ``at=point``, and
    the analysis stays usable."""
    from dirac.errors import AnalysisError

    analysis = dirac.analyze(chain(1))
    s = analysis.symbols
    x1, y1 = s["x1"], s["y1"]
    by_hand = 1 - x1**2 / (x1**2 + y1**2)
    for limit in (None, 60.0):
        exact = analysis.dirac_bracket("x1", "p_x1", time_limit=limit)
        point = {x1: 0.6, y1: -0.8}
        assert abs(float(exact.subs(point)) - float(by_hand.subs(point))) < 1e-12
    with pytest.raises(AnalysisError, match=r"at=point"):
        analysis.dirac_bracket("x1", "p_x1", time_limit=0.0)
    again = analysis.dirac_bracket("x1", "p_x1")
    assert abs(float(again.subs(point)) - float(by_hand.subs(point))) < 1e-12
