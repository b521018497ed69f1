"""Light-cone SU(2) Yang–Mills mechanics (Gerdt, Khvedelidze, Mladenov, hep-th/0209107).

The light-cone Yang–Mills Lagrangian ``L = -1/4 F^a_{mu nu} F^{a mu nu}`` with metric
``g_{+-} = 1``, ``g_{kk} = -1`` (``k = 1, 2``) is, summing over colours,

    L = 1/2 F_{+-}^2 + F_{+k} F_{-k} - 1/2 F_{12}^2

(from ``F F = -2 F_{+-}^2 - 4 F_{+k} F_{-k} + 2 F_{12}^2``). For potentials depending on the
light-cone time ``x^+`` alone, ``F_{+-} = A_-_dot + g A_+ x A_-``, ``F_{+k} = A_k_dot + g A_+ x A_k``,
``F_{-k} = g A_- x A_k``, ``F_{12} = g A_1 x A_2`` (``x`` the su(2) cross product). By hand:
``L`` is quadratic in ``A_-_dot`` only, linear in ``A_k_dot`` and free of ``A_+_dot``, so the
Hessian has rank 3 of 12 and there are 9 primary constraints: ``p_+^a = 0`` and
``p_k^a - F_{-k}^a = 0``. The paper finds that consistency fixes 4 combinations of the 9
multipliers and that the constraints leave "four canonical" degrees of freedom, read here as
four canonical variables, 2 degrees of freedom (the unconstrained motion is that of a
one-dimensional particle with the gauge-field spin as a constant, hep-th/0210022). An
independent count at points with ``A_- != 0`` agrees: 12 independent constraints, rank of
``C`` 4, so ``(24 - 2*8 - 4)/2 = 2``. The part ``A_- = 0`` has another structure
(7 first class, 10 second class, 0 degrees of freedom; derived in the docstring of
``test_the_part_a_minus_zero_against_the_hand_count``).
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy

import dirac
from dirac.analysis.legendre.transform import legendre_transform

LETTERS = {"plus": "ap", "minus": "am", "one": "ax", "two": "ay"}


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def light_cone_lagrangian() -> dirac.Lagrangian:
    """``L = 1/2 F_{+-}^2 + F_{+k} F_{-k} - 1/2 F_{12}^2`` for ``A_mu^a(x^+)``, coupling ``g = 1``."""
    field = {key: [sympy.Symbol(f"{name}{a}") for a in (1, 2, 3)] for key, name in LETTERS.items()}
    rate = {key: [sympy.Symbol(f"{name}{a}_dot") for a in (1, 2, 3)] for key, name in LETTERS.items()}
    g = sympy.Symbol("g")

    def dot(a, b):
        return sum((x * y for x, y in zip(a, b)), sympy.S.Zero)

    def covariant(key):
        return [v + g * c for v, c in zip(rate[key], _cross(field["plus"], field[key]))]

    F_pm = covariant("minus")
    F_minus = {k: [g * c for c in _cross(field["minus"], field[k])] for k in ("one", "two")}
    F_12 = [g * c for c in _cross(field["one"], field["two"])]
    L = dot(F_pm, F_pm) / 2 + sum((dot(covariant(k), F_minus[k]) for k in ("one", "two")), sympy.S.Zero) - dot(F_12, F_12) / 2
    coordinates = [s.name for key in LETTERS for s in field[key]]
    return dirac.Lagrangian.from_strings("light_cone_su2", coordinates, str(L), parameters={"g": 1.0}).fix(g=1.0)


@pytest.fixture(scope="module")
def light_cone():
    return dirac.analyze(light_cone_lagrangian(), assume=["am1**2 + am2**2 + am3**2 != 0"])


@pytest.fixture(scope="module")
def legendre():
    return legendre_transform(light_cone_lagrangian(), np.random.default_rng(1), {})


def test_both_components_of_the_surface_are_listed_not_mixed():
    """The surface has two components of different structure (rank C = 4 where A_- != 0,
    6 on A_- = 0, see the module docstring): the counts must not come from a mixture of
    points of both. Without an assumption each part is analysed on its own and listed, the
    top-level counts are those of the first part, and a warning says so."""
    with pytest.warns(dirac.errors.DiracWarning, match="2 parts of different structure"):
        analysis = dirac.analyze(light_cone_lagrangian())
    parts = analysis.to_json()["components"]
    assert [p["condition"] for p in parts] == ["am1**2 + am2**2 + am3**2 != 0", "am1 = am2 = am3 = 0"]
    published = parts[0]
    assert (len(published["first_class"]), len(published["second_class"]), published["physical_degrees_of_freedom"]) == (8, 4, 2)
    assert (len(analysis.first_class), len(analysis.second_class)) == (8, 4)
    zero = parts[1]
    assert (len(zero["first_class"]), len(zero["second_class"]), zero["physical_degrees_of_freedom"]) == (7, 10, 0)


def test_primary_constraints(legendre):
    s = legendre.phase_space.symbols
    assert legendre.rank == 3
    primary = legendre.primary
    assert len(primary) == 9
    for a in (1, 2, 3):
        assert s[f"p_ap{a}"] in primary
    A_minus = [s[f"am{a}"] for a in (1, 2, 3)]
    for k in ("ax", "ay"):
        A_k = [s[f"{k}{a}"] for a in (1, 2, 3)]
        F = _cross(A_minus, A_k)
        for a in (1, 2, 3):
            expected = s[f"p_{k}{a}"] - F[a - 1]
            assert any(sympy.expand(c - expected) == 0 or sympy.expand(c + expected) == 0 for c in primary)


def test_published_counts(light_cone):
    """On the part A_- != 0 (the assumption keeps every sample point there): 8 first class,
    4 second class, 2 degrees of freedom, 4 of the 9 multipliers fixed (module docstring)."""
    assert (len(light_cone.first_class), len(light_cone.second_class)) == (8, 4)
    assert len(light_cone.multiplier_solution.null_vectors) == 9 - 4
    assert light_cone.physical_degrees_of_freedom == 2


def test_the_part_a_minus_zero_against_the_hand_count():
    """``A_- = 0`` imposed as constraints without multipliers (stage 2). By hand, with
    ``H_c = p_-^2/2 - p_- . (A_+ x A_-) - sum_k (A_+ x A_k) . (A_- x A_k) + |A_1 x A_2|^2/2``
    and ``phi_k = p_k - A_- x A_k``: stage 3 is ``A_-_dot = p_- - A_+ x A_- = 0`` (3) and
    ``phi_k_dot = 0``, i.e. ``A_2 x F = A_1 x F = 0`` with ``F = A_1 x A_2`` (6 conditions of rank
    2 where ``A_1, A_2`` are not both zero: ``A_1 || A_2``), no multiplier entering: 5 new
    constraints and 4 reducible ones. Stage 4 adds nothing: ``p_-_dot = sum_k A_k x (u_k + A_+ x A_k)``
    and ``F_dot = u_1 x A_2 + A_1 x u_2`` fix 4 of the 6 ``u_k`` (their components normal to the
    common direction ``n``; the ``n`` component of the first vanishes identically). In the order
    ``(A_-, p_-, phi, F)`` the bracket matrix has rank 6 + 4 = 10 (``A_-`` pairs with ``p_-``,
    ``F`` with 2 combinations of ``phi``), so 17 constraints are 10 second class and 7 first
    class (``p_+`` and 4 combinations of ``phi`` with ``A_-``), 0 degrees of freedom, and 5
    free multipliers (``u_+`` and the 2 ``n`` components: the primary first-class ones)."""
    a = dirac.analyze(light_cone_lagrangian(), assume=["am1 = 0", "am2 = 0", "am3 = 0"])
    assert [len(s) for s in a.stages] == [9, 3, 5] and len(a.reducible_constraints) == 4
    assert (len(a.first_class), len(a.second_class), a.physical_degrees_of_freedom) == (7, 10, 0)
    assert len(a.multiplier_solution.free) == 5  # one free parameter per null vector (no exact solve needed)
    # the points of the part satisfy A_1 || A_2 away from A_1 = A_2 = 0 (no decision at the singular locus)
    s = a.symbols
    for z in a._points:
        value = {name: z[a.phase_space.index(sym)] for name, sym in s.items()}
        A1 = np.array([value[f"ax{i}"] for i in (1, 2, 3)])
        A2 = np.array([value[f"ay{i}"] for i in (1, 2, 3)])
        assert np.linalg.norm(np.cross(A1, A2)) < 1e-8 and np.linalg.norm(A1) + np.linalg.norm(A2) > 1e-2
