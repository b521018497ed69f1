"""The one field emitter: the banded looped solve of a large C against the dense one and numpy."""

from __future__ import annotations

import functools

import numpy as np
import pytest
import sympy

from dirac.codegen.field_source import compile_vector_field, vector_field_source


@functools.cache  # the chain of 24 links serves two tests
def _chain(links: int) -> tuple[list[sympy.Symbol], sympy.Expr, list[sympy.Expr]]:
    """A planar chain of unit masses and unit rods hung at the origin, in Cartesian
    coordinates: ``H = |p|^2 / 2 + g sum y_i``, the rods ``chi_i = |r_i - r_{i-1}|^2 - 1``
    and their velocity constraints ``psi_i = grad chi_i . p`` (unit masses): ``k = 2 links``
    second-class constraints with ``{chi_i, psi_j}`` and ``{psi_i, psi_j}`` non-zero only for
    neighbouring links, so ``C`` is banded once chi and psi of a link are put together."""
    x = sympy.symbols(f"x1:{links + 1}", real=True)
    y = sympy.symbols(f"y1:{links + 1}", real=True)
    q = [s for pair in zip(x, y) for s in pair]
    p = sympy.symbols(f"p1:{2 * links + 1}", real=True)
    g = sympy.Symbol("g", real=True)
    H = sum(s**2 for s in p) / 2 + g * sum(y)
    rods = [x[0]**2 + y[0]**2 - 1] + [(x[i] - x[i - 1])**2 + (y[i] - y[i - 1])**2 - 1 for i in range(1, links)]
    velocities = [sum(sympy.diff(chi, s) * ps for s, ps in zip(q, p)) for chi in rods]
    return [*q, *p], H, [*rods, *velocities]


@functools.cache  # differentiated and lambdified once per chain, not at every point
def _gradients(z: tuple[sympy.Symbol, ...], H: sympy.Expr, constraints: tuple[sympy.Expr, ...]):
    """``grad H`` and ``D = d(constraints)/dz`` as numpy functions of ``(*z, g)``."""
    symbols = [*z, sympy.Symbol("g", real=True)]
    return (sympy.lambdify(symbols, [sympy.diff(H, s) for s in z]),
            sympy.lambdify(symbols, [[sympy.diff(c, s) for s in z] for c in constraints]))


def _numpy_field(z: list[sympy.Symbol], H: sympy.Expr, constraints: list[sympy.Expr], point: np.ndarray,
                 g: float) -> np.ndarray:
    """``J grad H - J D^T C^{-1} D J grad H`` with numpy's dense solve (the definition (240))."""
    n = len(z) // 2
    gradient, jacobian = _gradients(tuple(z), H, tuple(constraints))
    grad = np.array(gradient(*point, g), dtype=float)
    D = np.array(jacobian(*point, g), dtype=float)
    J = np.block([[np.zeros((n, n)), np.eye(n)], [-np.eye(n), np.zeros((n, n))]])
    C = D @ J @ D.T
    flow = J @ grad
    return flow - J @ D.T @ np.linalg.solve(C, D @ flow)


@pytest.fixture(scope="module")
def chain_fields():
    """The chain of 12 links (k = 24) with the looped solve, banded and dense."""
    z, H, constraints = _chain(12)
    g = sympy.Symbol("g", real=True)
    modules = {}
    for label, banded in (("banded", True), ("dense", False)):
        source = vector_field_source(z, [g], H, constraints, constraints, title=f"chain, {label}", unroll_limit=0,
                                     banded=banded)
        assert ("solve_banded" in source) == banded
        modules[label] = compile_vector_field(source)
    return z, H, constraints, modules


def test_banded_solve_agrees_with_dense_and_numpy(chain_fields):
    z, H, constraints, modules = chain_fields
    rng = np.random.default_rng(7)
    for _ in range(5):
        point = rng.normal(size=len(z))
        reference = _numpy_field(z, H, constraints, point, 9.81)
        values = {}
        for label, module in modules.items():
            params = np.zeros(module.PARAMS)
            params[0] = 9.81
            values[label] = module.field(0.0, point, params)
        scale = np.max(np.abs(reference))
        assert np.max(np.abs(values["banded"] - values["dense"])) <= 1e-12 * scale
        assert np.max(np.abs(values["banded"] - reference)) <= 1e-10 * scale


def test_banded_scratch_is_linear_in_k(chain_fields):
    """The band storage holds ``k (2 l + u + 2)`` entries, fewer than the dense ``k (k + 1)``."""
    _, _, constraints, modules = chain_fields
    k = len(constraints)
    assert modules["banded"].PARAMS - 1 < k * (k + 1) / 2
    assert modules["dense"].PARAMS - 1 == k * (k + 1)


def test_large_banded_C_gets_linear_source():
    """Past the unroll limit a banded ``C`` takes the banded solve by itself, and the source
    grows linearly with the number of links (no O(k^2) entries written, no O(k^3) unrolled)."""
    g = sympy.Symbol("g", real=True)
    sizes = {}
    for links in (24, 48):
        z, H, constraints = _chain(links)
        source = vector_field_source(z, [g], H, constraints, constraints, title="chain")
        assert "solve_banded" in source
        sizes[links] = source.count("\n")
    assert sizes[48] / sizes[24] < 2.2


@pytest.mark.slow
def test_analysed_kernel_uses_the_same_banded_field():
    """The step kernels of an analysed system print their field with the same emitter: for
    the chain of 24 links (k = 48) it takes the banded solve and agrees with numpy."""
    from dirac.codegen.kernel_source import analysed_kernel_source, load_kernels

    z, H, constraints = _chain(24)
    source = analysed_kernel_source(z, [sympy.Symbol("g", real=True)], H, constraints)
    assert "solve_banded" in source
    module = load_kernels(source)
    point = np.random.default_rng(5).normal(size=len(z))
    out = np.empty(len(z))
    module.field(point, 0.0, np.array([9.81]), out)
    reference = _numpy_field(z, H, constraints, point, 9.81)
    assert np.max(np.abs(out - reference)) <= 1e-10 * np.max(np.abs(reference))


def test_banded_solve_is_chosen_when_it_needs_fewer_products():
    """Band ``l = u = 11`` (the analysed chain: four constraints a link, neighbours coupled):
    at ``k = 64`` the banded solve needs ``k l (l + u) = 15488`` products against the dense
    ``k^3 / 3 = 87381`` (and writes only the non-zero entries of ``C``, not ``k (k + 1)``);
    at ``k = 16`` it needs ``3872`` against ``1365`` and the dense one is kept; a full ``C``
    (``l = u = k - 1``) is always dense."""
    from dirac.codegen.field_body import _banded_pays

    assert _banded_pays(64, 11, 11)
    assert not _banded_pays(16, 11, 11)
    assert not _banded_pays(24, 23, 23)


def test_looped_solve_of_a_moderate_chain_is_banded():
    """The 16-link chain of this module (k = 32) with the looped solve is banded by itself, so
    its source holds no dense ``k (k + 1)`` scratch (which made such fields take minutes to compile)."""
    g = sympy.Symbol("g", real=True)
    z, H, constraints = _chain(16)
    source = vector_field_source(z, [g], H, constraints, constraints, title="chain", unroll_limit=0)
    assert "solve_banded(" in source and "solve_scratch(" not in source
    assert source.count("\n") < len(constraints) * (len(constraints) + 1)
