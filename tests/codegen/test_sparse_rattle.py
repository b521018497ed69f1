"""The looped RATTLE of large systems (dirac.codegen.sparse_rattle): families, the banded
solve, and steps that keep the rods of a chain and agree with the unrolled kernel."""

from __future__ import annotations

import numpy as np
import pytest
import sympy

from dirac.codegen import kernel_source
from dirac.codegen.numba_backend import interpret_source
from dirac.codegen.sparse_rattle import RATTLE_ONLY, group_families


def _chain(N: int) -> tuple[list[sympy.Symbol], list[sympy.Symbol], sympy.Expr, list[sympy.Expr]]:
    """Planar chain of N unit-mass links in Cartesian coordinates: rods |r_1| = l, |r_k - r_{k-1}| = l."""
    x = sympy.symbols(f"x1:{N + 1}", real=True)
    y = sympy.symbols(f"y1:{N + 1}", real=True)
    m, g, l = sympy.symbols("m g l", real=True)
    q = [s for k in range(N) for s in (x[k], y[k])]
    rods = [x[0] ** 2 + y[0] ** 2 - l ** 2] + [(x[k] - x[k - 1]) ** 2 + (y[k] - y[k - 1]) ** 2 - l ** 2
                                              for k in range(1, N)]
    return q, [m, g, l], m * g * sum(y), rods


def test_the_rods_of_a_chain_are_two_families_with_the_coordinates_each_reads() -> None:
    q, _, _, rods = _chain(4)
    families = group_families(rods, q)
    assert [f.members for f in families] == [[0], [1, 2, 3]]
    assert families[0].columns == [(0, 1)]
    assert families[1].columns == [(0, 1, 2, 3), (2, 3, 4, 5), (4, 5, 6, 7)]
    u = families[1].placeholders
    l = sympy.Symbol("l", real=True)
    assert sympy.expand(families[1].template - ((u[0] - u[2]) ** 2 + (u[1] - u[3]) ** 2 - l ** 2)) == 0


def _module(N: int, sparse: bool):
    q, params, V, rods = _chain(N)
    mass = sympy.eye(2 * N) * params[0]
    limit = kernel_source.SPARSE_MIN_CONSTRAINTS
    try:
        kernel_source.SPARSE_MIN_CONSTRAINTS = 1 if sparse else 10 ** 9
        source = kernel_source.mechanical_kernel_source(q, params, mass, V, rods, title=f"chain {N}")
    finally:
        kernel_source.SPARSE_MIN_CONSTRAINTS = limit
    assert (RATTLE_ONLY in source) == sparse
    return interpret_source(source), source


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_banded_elimination_with_row_exchanges_solves_like_a_dense_solve(seed: int) -> None:
    module, _ = _module(6, sparse=True)  # tridiagonal pattern: KL = KU = 1
    M, KL, KU, BW = module.M, module.KL, module.KU, module.BW
    assert (KL, KU) == (1, 1)
    rng = np.random.default_rng(seed)
    dense = np.zeros((M, M))
    for a in range(M):
        for b in range(max(0, a - KL), min(M, a + KU + 1)):
            dense[a, b] = rng.normal()
    dense[0, 0] = 0.0  # the first pivot must come from a row exchange
    dense[3, 3] = 1e-3 * dense[4, 3]
    band = np.zeros((M, BW))
    for a in range(M):
        for b in range(max(0, a - KL), min(M, a + KU + 1)):
            band[a, b - a + KL] = dense[a, b]
    rhs = rng.normal(size=M)
    x = rhs.copy()
    module.band_solve(band, x, np.empty(M, dtype=np.int64))
    np.testing.assert_allclose(dense @ x, rhs, atol=1e-12)


def test_looped_and_unrolled_rattle_take_the_same_steps_and_keep_the_rods() -> None:
    N = 5
    sparse, _ = _module(N, sparse=True)
    unrolled, _ = _module(N, sparse=False)
    c = np.array([1.0, 9.81, 1.0])
    angles = np.linspace(0.3, 1.1, N)
    q0 = np.cumsum(np.column_stack([np.sin(angles), -np.cos(angles)]), axis=0).ravel()
    results = []
    for module in (sparse, unrolled):
        q, p, info = q0.copy(), np.zeros(2 * N), np.zeros(4)
        module.rattle_constant_mass(q, p, 0.0, c, np.array([1.0]), 0.01, 20, 1e-13, 50, info)
        assert info[1] == 0.0 and info[0] == 20
        results.append((q, p))
    np.testing.assert_allclose(results[0][0], results[1][0], atol=1e-11)
    np.testing.assert_allclose(results[0][1], results[1][1], atol=1e-10)
    q, p = results[0]
    r = q.reshape(N, 2)
    rods = np.linalg.norm(np.diff(np.vstack([[0.0, 0.0], r]), axis=0), axis=1)
    np.testing.assert_allclose(rods, 1.0, atol=1e-12)
    # the hidden constraints G M^{-1} p = 0: each rod's relative velocity is normal to it
    v = p.reshape(N, 2)
    relative = np.diff(np.vstack([[0.0, 0.0], v]), axis=0)
    links = np.diff(np.vstack([[0.0, 0.0], r]), axis=0)
    np.testing.assert_allclose(np.sum(relative * links, axis=1), 0.0, atol=1e-12)
    # energy H = |p|^2/2 + g sum y is kept to O(h^2) over the 20 steps
    energy = 0.5 * p @ p + 9.81 * q[1::2].sum()
    assert abs(energy - 9.81 * q0[1::2].sum()) < 1e-2


def test_a_chain_runs_compiled_with_the_looped_kernel_and_refuses_midpoint() -> None:
    from dirac import Lagrangian
    from dirac.errors import InputError
    from dirac.flows.integration import integrate
    from dirac.flows.problems import ConstrainedProblem

    N = 4
    names = [f"{a}{k}" for k in range(1, N + 1) for a in ("x", "y")]
    rods = ["x1**2 + y1**2 - 1"] + [f"(x{k} - x{k - 1})**2 + (y{k} - y{k - 1})**2 - 1" for k in range(2, N + 1)]
    L = Lagrangian.from_strings("chain", names, "(" + " + ".join(f"{s}_dot**2" for s in names) + ")/2 - 9.81*("
                                + " + ".join(f"y{k}" for k in range(1, N + 1)) + ")", constraints=rods)
    q0 = np.array([v for k in range(1, N + 1) for v in (k * np.sin(0.4), -k * np.cos(0.4))])
    problem = ConstrainedProblem(L, q0, np.zeros(2 * N))
    solution = integrate(problem, "rattle-2", t_end=2.0, dt=1e-3, samples=3)  # 2000 steps: compiled when it pays
    assert solution.outputs["constraint_residual"].max() < 1e-10
    with pytest.raises(InputError, match="rattle-2"):
        integrate(problem, "midpoint", t_end=0.01, dt=1e-3)


@pytest.mark.parametrize("seed", [0, 1])
def test_stored_band_factors_solve_like_a_dense_solve(seed: int) -> None:
    """band_factor + band_lu_solve (LAPACK gbtf2/gbtrs order) against numpy's dense solve,
    with a zero first pivot and a small one that force row exchanges; two right-hand sides
    on one factorisation."""
    module, _ = _module(6, sparse=True)
    M, KL, KU, BW = module.M, module.KL, module.KU, module.BW
    rng = np.random.default_rng(10 + seed)
    dense = np.zeros((M, M))
    for a in range(M):
        for b in range(max(0, a - KL), min(M, a + KU + 1)):
            dense[a, b] = rng.normal()
    dense[0, 0] = 0.0
    dense[3, 3] = 1e-3 * dense[4, 3]
    band = np.zeros((M, BW))
    for a in range(M):
        for b in range(max(0, a - KL), min(M, a + KU + 1)):
            band[a, b - a + KL] = dense[a, b]
    piv = np.empty(M, dtype=np.int64)
    module.band_factor(band, piv)
    for _ in range(2):
        rhs = rng.normal(size=M)
        x = rhs.copy()
        module.band_lu_solve(band, piv, x)
        np.testing.assert_allclose(dense @ x, rhs, atol=1e-12)


def test_a_long_chain_far_from_the_origin_keeps_its_rods_to_round_off() -> None:
    """A 40-link chain hanging in an arc (its bob about 25 from the hinge, |q|^2 ~ 1e4) falls
    for 100 steps of 1e-3 with the run's default tolerance 1e-12: every rod stays within
    1e-12 of its length. Each rod is judged against tol (1 + |grad chi_a|^2) = 9e-12, not
    against tol (1 + |q|^2) ~ 1e-8, which would allow a stretch of ~5e-9."""
    N = 40
    module, _ = _module(N, sparse=True)
    angles = np.linspace(-1.5, 1.5, N)
    q = np.cumsum(np.column_stack([np.sin(angles), -np.cos(angles)]), axis=0).ravel()
    assert q @ q > 5000
    p, info = np.zeros(2 * N), np.zeros(4)
    module.rattle_constant_mass(q, p, 0.0, np.array([1.0, 9.81, 1.0]), np.array([1.0]), 1e-3, 100, 1e-12, 50, info)
    assert info[1] == 0.0 and info[0] == 100
    rods = np.linalg.norm(np.diff(np.vstack([[0.0, 0.0], q.reshape(N, 2)]), axis=0), axis=1)
    assert np.abs(rods - 1.0).max() < 1e-12
    assert np.abs(p).max() > 0.1  # it moved


def test_the_termwise_gradient_is_sympys_gradient() -> None:
    from dirac.codegen.sparse_rattle import termwise_gradient

    x = sympy.symbols("x0:5", real=True)
    a = sympy.Symbol("a", positive=True)
    V = sympy.expand(a * (x[1] - x[0]) ** 2 + sympy.sin(x[2]) * x[3] + x[4] ** 3 / 3 - sympy.cos(x[0] - x[4]) + 7)
    gradient = termwise_gradient(V, x)
    # by hand: dV/dx0 = -2a(x1 - x0) + sin(x0 - x4), dV/dx4 = x4^2 - sin(x0 - x4), ...
    by_hand = [-2 * a * (x[1] - x[0]) + sympy.sin(x[0] - x[4]), 2 * a * (x[1] - x[0]), sympy.cos(x[2]) * x[3],
               sympy.sin(x[2]), x[4] ** 2 - sympy.sin(x[0] - x[4])]
    assert all(sympy.expand(g - h) == 0 for g, h in zip(gradient, by_hand))
    assert gradient == [sympy.diff(V, s) for s in x]  # the same expressions, so the same printed kernels
    assert termwise_gradient(sympy.Integer(3), x) == [0] * 5


def test_a_klein_gordon_lattice_runs_looped_and_keeps_its_normal_mode() -> None:
    """``L = a sum_j (phi_j'^2 - ((phi_{j+1} - phi_j)/a)^2 - m^2 phi_j^2)/2`` on a ring of n sites: the mode
    ``phi_j = cos(theta j)``, ``theta = 2 pi / n``, oscillates as ``cos(omega t)`` with
    ``omega^2 = (4/a^2) sin^2(theta/2) + m^2`` (from ``phi_j'' = (phi_{j+1} - 2 phi_j + phi_{j-1})/a^2 - m^2 phi_j``).
    Stoermer-Verlet (``rattle-2``) is second order: halving dt quarters the error."""
    import dirac
    from dirac.codegen.kernel_source import SPARSE_MIN_COORDINATES
    from dirac.errors import InputError

    n, a = SPARSE_MIN_COORDINATES, 0.1
    kg = dirac.FieldTheory.from_strings("kg", ["x"], ["phi"], "phi_t**2/2 - phi_x**2/2 - phi**2/2")
    theta = 2 * np.pi / n
    mode = np.cos(theta * np.arange(n))
    problem = dirac.ConstrainedProblem(dirac.lattice(kg, sites=n, spacing=a), q0=mode, qdot0=np.zeros(n))
    assert RATTLE_ONLY in problem.mechanics.module.source  # the looped module: n^2 entries of M not written
    omega = np.sqrt(4 / a**2 * np.sin(theta / 2) ** 2 + 1.0)
    errors = []
    for dt in (2e-3, 1e-3):
        solution = dirac.integrate(problem, "rattle-2", t_end=1.0, dt=dt, samples=3)
        errors.append(np.abs(solution["q"][-1] - mode * np.cos(omega * 1.0)).max())
    assert errors[1] < 1e-6
    assert 3.6 < errors[0] / errors[1] < 4.4
    with pytest.raises(InputError, match=f"{n} coordinates and 0 constraints.*rattle-2"):
        dirac.integrate(problem, "midpoint", t_end=0.01, dt=1e-3)
    with pytest.raises(InputError, match="^a scipy method needs the Dirac vector field"):
        dirac.integrate(problem, "scipy-RK45", t_end=0.01)
