"""Castellani's generators of the lattice Maxwell models, against hand derivations.

maxwell_ring(n), L = sum_i (A1_i_dot - (A0_{i+1} - A0_i))^2/2 (sites periodic), by hand:
  p_A0_i = 0 (primary, all first class, A = {Phi, phi} = 0 so every multiplier is free and
  H' = H_c = sum_i p_A1_i^2/2 + sum_i p_A1_i (A0_{i+1} - A0_i)). One generator per site i:
  G_1 = p_A0_i; R = {p_A0_i, H_c} = -dH_c/dA0_i = p_A1_i - p_A1_{i-1} (the Gauss law at i);
  G_0 = -R = p_A1_{i-1} - p_A1_i; {G_0, H_c} = 0 (H_c has no A1), so the chain closes:
      G^(i) = eps_i (p_A1_{i-1} - p_A1_i) + eps_i_dot p_A0_i,
  delta A0_i = eps_i_dot, delta A1_{i-1} = eps_i, delta A1_i = -eps_i: summed over i the
  lattice gauge transformation A1_i -> A1_i + eps_{i+1} - eps_i, A0_i -> A0_i + eps_i_dot,
  which leaves every E_i = A1_i_dot - (A0_{i+1} - A0_i) unchanged. n generators; the G_0
  terms obey one relation, sum_i G_0^(i) = 0 (telescoping): equal constant parameters
  eps_i = c move nothing (the global relation among the Gauss laws, whose sum vanishes).
maxwell_torus(L): the same with G_0 at site s = -(Gauss law at s)
  = -(p_Ax_s - p_Ax_{s-x} + p_Ay_s - p_Ay_{s-y}); {G_0, H_c} = 0 since the magnetic energy
  depends on the links through lattice curls; delta Ax_s = eps_{s+x} - eps_s,
  delta Ay_s = eps_{s+y} - eps_s, delta A0_s = eps_s_dot; L^2 generators, one relation.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy
from stress_scaling import stress_scale

import dirac
from dirac_systems.scale_models import maxwell_ring, maxwell_torus


def _ratio(found: sympy.Expr, expected: sympy.Expr) -> sympy.Expr:
    ratio = sympy.cancel(found / expected)
    assert ratio.is_number and ratio != 0, (found, expected)
    return ratio


def _check_generators(analysis, site_of, gauss_at, moved_at) -> None:
    """Each generator is c (G_0, G_1) = c (-Gauss_i, p_A0_i) for one site i, every site once;
    delta z = {z, G} by hand; the G_0 terms satisfy exactly one relation, their sum."""
    s = analysis.symbols
    structure = analysis.gauge_structure
    gens = structure.generators
    sites = list(site_of.values())
    assert len(gens) == len(sites) == len(analysis.undetermined_multipliers)
    assert structure.unclosed == [] and structure.rejected == [] and structure.without_transformation == []
    seen = []
    normalised = []
    for gen in gens:
        assert gen.order == 1
        G0, G1 = gen.terms
        [p0] = G1.free_symbols
        site = site_of[p0.name]
        seen.append(site)
        c = _ratio(G1, p0)
        assert sympy.expand(G0 + c * gauss_at(site)) == 0
        eps, eps_dot = gen.parameter_symbols()
        expected = {s[f"A0_{site}"]: c * eps_dot}
        for name, sign in moved_at(site):
            expected[s[name]] = -sign * c * eps
        assert {z: sympy.expand(d) for z, d in gen.delta.items()} == expected
        normalised.append(sympy.expand(G0 / c))
    assert sorted(seen) == sorted(sites)
    assert sympy.expand(sum(normalised)) == 0  # the global relation
    # exactly one relation: the coefficient matrix of the G_0 over the momenta has rank (sites - 1)
    momenta = sorted(set().union(*(g.free_symbols for g in normalised)), key=lambda x: x.name)
    matrix = np.array([[float(g.coeff(p)) for p in momenta] for g in normalised])
    assert np.linalg.matrix_rank(matrix) == len(gens) - 1


def check_ring_generators(n: int) -> None:
    analysis = dirac.analyze(maxwell_ring(n))
    s = analysis.symbols

    def p1(i: int) -> sympy.Symbol:
        return s[f"p_A1_{(i - 1) % n + 1}"]

    def gauss(i: int) -> sympy.Expr:
        return p1(i) - p1(i - 1)

    def moved(i: int) -> list[tuple[str, int]]:  # {A1_j, Gauss_i} = d Gauss_i / d p_A1_j
        return [(f"A1_{i}", 1), (f"A1_{(i - 2) % n + 1}", -1)]

    _check_generators(analysis, {f"p_A0_{i}": i for i in range(1, n + 1)}, gauss, moved)


def check_torus_generators(size: int) -> None:
    analysis = dirac.analyze(maxwell_torus(size))
    s = analysis.symbols

    def at(a: int, b: int) -> str:
        return f"{a % size}_{b % size}"

    def split(site: str) -> tuple[int, int]:
        a, b = site.split("_")
        return int(a), int(b)

    def gauss(site: str) -> sympy.Expr:
        a, b = split(site)
        return s[f"p_Ax_{at(a, b)}"] - s[f"p_Ax_{at(a - 1, b)}"] + s[f"p_Ay_{at(a, b)}"] - s[f"p_Ay_{at(a, b - 1)}"]

    def moved(site: str) -> list[tuple[str, int]]:
        a, b = split(site)
        return [(f"Ax_{at(a, b)}", 1), (f"Ax_{at(a - 1, b)}", -1), (f"Ay_{at(a, b)}", 1), (f"Ay_{at(a, b - 1)}", -1)]

    sites = {f"p_A0_{at(a, b)}": at(a, b) for a in range(size) for b in range(size)}
    _check_generators(analysis, sites, gauss, moved)


@pytest.mark.parametrize("n", [3, 8, 32])  # 32 sites: 128 variables, the large-system (sparse block) path
def test_ring_generators_are_lattice_gauge_transformations(n):
    check_ring_generators(n)


def test_torus_generators_are_lattice_gauge_transformations():
    check_torus_generators(3)


def test_torus_generators_on_the_large_system_path():
    check_torus_generators(5)  # 150 phase-space variables


@pytest.mark.slow
def test_ring_generators_at_scale():
    """256 sites (``DIRAC_FULL_STRESS=1``; 64 in the bounded form)."""
    check_ring_generators(256 if stress_scale() == 1.0 else 64)


@pytest.mark.slow
def test_torus_generators_at_scale():
    """8 x 8 (``DIRAC_FULL_STRESS=1``; 6 x 6 in the bounded form)."""
    check_torus_generators(8 if stress_scale() == 1.0 else 6)
