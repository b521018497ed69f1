"""The inverse velocity map of a symmetric Lagrangian: one Gröbner basis, the other velocities by symmetry.

Hand derivation, relativistic particle in 3-D in an isotropic potential,
``L = -m c^2 sqrt(1 - v^2/c^2) - k r^2/2``: ``p = m v / sqrt(1 - v^2/c^2)``, so
``p^2 (1 - v^2/c^2) = m^2 v^2``, ``v^2 = c^2 p^2/(m^2 c^2 + p^2)`` and
``v = c p / sqrt(m^2 c^2 + p^2)`` (the branch with ``v`` along ``p`` for ``m > 0``);
``H = p.v - L = c sqrt(m^2 c^2 + p^2) + k r^2/2``. The Lagrangian is unchanged when two
axes are exchanged, so the relation of ``y_dot`` and ``z_dot`` to the momenta is that of
``x_dot`` with the axes exchanged.
"""

from __future__ import annotations

import numpy as np
import sympy

import dirac
from dirac.analysis.legendre import velocity_elimination
from dirac.analysis.legendre.velocity_elimination import _mirrored, _signed
from dirac.model.lagrangian import Lagrangian


def _counting_groebner(monkeypatch) -> list[int]:
    calls: list[int] = []
    inner = sympy.groebner

    def counted(*args, **kwargs):
        calls.append(1)
        return inner(*args, **kwargs)

    monkeypatch.setattr(velocity_elimination.sympy, "groebner", counted)
    return calls


def test_a_relativistic_particle_in_three_dimensions_needs_one_basis(monkeypatch):
    calls = _counting_groebner(monkeypatch)
    particle = Lagrangian.from_strings(
        "relativistic_3d", ["x", "y", "z"], "-m*c**2*sqrt(1 - (x_dot**2 + y_dot**2 + z_dot**2)/c**2) - k*(x**2 + y**2 + z**2)/2",
        parameters={"m": 1.0, "c": 1.0, "k": 1.0},
    )
    a = dirac.analyze(particle)
    assert len(calls) == 1
    syms = {**a.symbols, **particle.parameter_symbols}
    p = [syms[n] for n in ("p_x", "p_y", "p_z")]
    x, y, z, m, c, k = (syms[n] for n in ("x", "y", "z", "m", "c", "k"))
    rng = np.random.default_rng(3)
    for _ in range(4):
        values = dict(zip([*p, x, y, z], rng.normal(size=6)))
        values.update({m: 1.7, c: 0.8, k: 0.4})
        norm = np.sqrt(sum(values[s] ** 2 for s in p))
        root = np.sqrt(1.7**2 * 0.8**2 + norm**2)
        for s, velocity in zip(p, particle.velocities):
            got = float(a._legendre.velocity_solution[velocity].subs(values))
            assert abs(got - 0.8 * values[s] / root) < 1e-12
        energy = 0.8 * root + 0.4 * (values[x] ** 2 + values[y] ** 2 + values[z] ** 2) / 2
        assert abs(float(a.canonical_hamiltonian.subs(values)) - energy) < 1e-12
    assert a.physical_degrees_of_freedom == 3


def _gives_back_the_momenta(L: Lagrangian, a, seed: int) -> None:
    """The velocities ``v(q, p)`` found put into ``p = dL/dq_dot`` give back ``p`` at random points."""
    names = [c.name for c in L.coordinates]
    q = [a.symbols[n] for n in names]
    p = [a.symbols[f"p_{n}"] for n in names]
    momenta = [sympy.diff(L.expression, v) for v in L.velocities]
    rng = np.random.default_rng(seed)
    for _ in range(3):
        point = {s: 0.3 * rng.normal() for s in [*q, *p]}
        velocities = {v: a._legendre.velocity_solution[v].subs(point) for v in L.velocities}
        for got, want in zip(momenta, p):
            assert abs(float(got.subs({**velocities, **point})) - point[want]) < 1e-12


def test_an_inertia_that_depends_on_a_coordinate_alone_keeps_the_symmetry_of_the_velocities(monkeypatch):
    """``-sqrt(1 - (x_dot^2 + y_dot^2)/(1 + x^2))``: the factor ``1/(1 + x^2)`` enters the relations as one
    coefficient symbol, and exchanging the velocities with their momenta maps them onto themselves: one basis."""
    calls = _counting_groebner(monkeypatch)
    L = Lagrangian.from_strings("conformal", ["x", "y"], "-sqrt(1 - (x_dot**2 + y_dot**2)/(1 + x**2))")
    a = dirac.analyze(L)
    assert len(calls) == 1
    _gives_back_the_momenta(L, a, 5)


def test_a_lagrangian_without_the_symmetry_computes_every_basis(monkeypatch):
    """``-sqrt(1 - x_dot^2 - 2 y_dot^2)``: exchanging the axes changes the relations, so two bases."""
    calls = _counting_groebner(monkeypatch)
    L = Lagrangian.from_strings("anisotropic", ["x", "y"], "-sqrt(1 - x_dot**2 - 2*y_dot**2)")
    a = dirac.analyze(L)
    assert len(calls) == 2
    _gives_back_the_momenta(L, a, 7)


def test_a_swap_that_does_not_map_the_relations_onto_themselves_is_not_used():
    """``p_x = 2 x_dot``, ``p_y = 3 y_dot``: exchanging the axes maps ``p_x - 2 x_dot`` to ``p_y - 2 y_dot``, no relation."""
    q = sympy.symbols("x y")
    v = sympy.symbols("x_dot y_dot")
    p = sympy.symbols("p_x p_y")
    relations = [p[0] - 2 * v[0], p[1] - 3 * v[1]]
    assert _mirrored(relations, {_signed(r) for r in relations}, q, v, p, [p[0] - 2 * v[0]], 1) is None
    symmetric = [p[0] - 2 * v[0], 2 * v[1] - p[1]]  # the second written with the other sign
    assert _mirrored(symmetric, {_signed(r) for r in symmetric}, q, v, p, [p[0] - 2 * v[0]], 1) == p[1] - 2 * v[1]
