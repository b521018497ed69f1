"""Systems whose size is a parameter: for the analysis at scale (docs/scale.md, ``dirac bench``).

Each factory returns a :class:`dirac.Lagrangian` whose number of variables grows with its
argument, while every constraint touches O(1) variables (local systems): the planar
N-link chain in Cartesian coordinates, 1+1-dimensional lattice Maxwell theory on a ring
and 2+1-dimensional lattice Maxwell theory on a torus. The docstrings give the
Lagrangian and the hand counts (stages, classes, reducible constraints, degrees of
freedom) that the tests check.

The factories are functions of the size, not entry-point systems (those take no
required size, and the list of built-in names stays the paper's systems):
``from dirac_systems.scale_models import chain; chain(16)``.
"""

from __future__ import annotations

from dirac.errors import InputError
from dirac.model.lagrangian import Lagrangian

__all__ = ["chain", "maxwell_ring", "maxwell_torus"]


def _size(value: int, least: int, what: str) -> int:
    """``value`` as an int of at least ``least`` (else a clear InputError)."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise InputError(f"{what} must be an integer, not {value!r}")
    if value < least:
        raise InputError(f"{what} must be at least {least}, not {value}")
    return value


def chain(n: int) -> Lagrangian:
    """Planar chain of ``n`` rigid links in Cartesian coordinates, under gravity.

    Point masses ``m`` at ``r_k = (x_k, y_k)``, ``k = 1..n``, joined by massless rods of
    length ``l``, the first hinged at the origin:

        L = sum_k m/2 (x_k_dot^2 + y_k_dot^2) - m g sum_k y_k,
        chi_1 = x_1^2 + y_1^2 - l^2,   chi_k = (x_k - x_{k-1})^2 + (y_k - y_{k-1})^2 - l^2.

    The extended Lagrangian (multipliers ``lambda_k`` as coordinates) has a phase space
    of dimension ``6 n``. Hand counts: four stages of ``n`` constraints each
    (``p_lambda_k = 0``; ``chi_k = 0``; ``d chi_k/dt = 0``; ``d^2 chi_k/dt^2 = 0``,
    which fixes the ``lambda_k``), all ``4 n`` second class, no reducible constraint,
    ``n`` physical degrees of freedom (``(6 n - 4 n)/2``). Parameters ``m, g, l``
    (defaults 1, 9.81, 1) stay symbolic until fixed.
    """
    n = _size(n, 1, "the number of links n")
    coords = [name for k in range(1, n + 1) for name in (f"x{k}", f"y{k}")]
    kinetic = " + ".join(f"x{k}_dot**2 + y{k}_dot**2" for k in range(1, n + 1))
    height = " + ".join(f"y{k}" for k in range(1, n + 1))
    rods = ["x1**2 + y1**2 - l**2"] + [
        f"(x{k} - x{k - 1})**2 + (y{k} - y{k - 1})**2 - l**2" for k in range(2, n + 1)
    ]
    return Lagrangian.from_strings(
        f"chain_{n}",
        coords,
        f"m/2*({kinetic}) - m*g*({height})",
        constraints=rods,
        parameters={"m": 1.0, "g": 9.81, "l": 1.0},
        description=f"planar chain of {n} rigid links in Cartesian coordinates",
    )


def maxwell_ring(n: int) -> Lagrangian:
    """1+1-dimensional lattice Maxwell theory on a ring of ``n`` sites (temporal links ``A0``).

    Site variables ``A0_i`` (no velocity in ``L``) and link variables ``A1_i``
    (``i = 1..n``, periodic: site ``n + 1`` is site 1):

        L = sum_i (A1_i_dot - (A0_{i+1} - A0_i))^2 / 2.

    Hand counts: primary constraints ``p_A0_i = 0`` (``n``); their consistency gives the
    Gauss laws ``G_i = p_A1_i - p_A1_{i-1} = 0`` (``n``, second stage), of which ``n - 1``
    are independent: their sum vanishes identically, so one is reducible. All ``2 n - 1``
    independent constraints are first class, the ``n`` multipliers stay free, and
    ``(4 n - 2 (2 n - 1))/2 = 1`` physical degree of freedom remains (the electric flux
    around the ring and its conjugate holonomy).
    """
    n = _size(n, 2, "the number of sites n")
    coords = [f"A0_{i}" for i in range(1, n + 1)] + [f"A1_{i}" for i in range(1, n + 1)]
    terms = [f"(A1_{i}_dot - (A0_{i % n + 1} - A0_{i}))**2" for i in range(1, n + 1)]
    return Lagrangian.from_strings(
        f"maxwell_ring_{n}",
        coords,
        "(" + " + ".join(terms) + ")/2",
        description=f"1+1 lattice Maxwell theory on a ring of {n} sites",
    )


def maxwell_torus(size: int) -> Lagrangian:
    """2+1-dimensional lattice Maxwell theory on a ``size`` x ``size`` torus.

    Per site ``(a, b)`` (periodic in both directions): the temporal link ``A0_a_b`` (no
    velocity in ``L``) and the spatial links ``Ax_a_b``, ``Ay_a_b``. With the electric
    fields ``Ex = Ax_dot - (A0_{a+1,b} - A0_{a,b})``, ``Ey = Ay_dot - (A0_{a,b+1} - A0_{a,b})``
    and the plaquettes ``B = Ax_{a,b} + Ay_{a+1,b} - Ax_{a,b+1} - Ay_{a,b}``:

        L = sum_sites (Ex^2 + Ey^2) / 2 - g/2 sum_plaquettes B^2.

    Hand counts (``L^2`` sites, ``3 L^2`` coordinates): primary ``p_A0 = 0`` (``L^2``);
    Gauss laws ``p_Ax_{a,b} - p_Ax_{a-1,b} + p_Ay_{a,b} - p_Ay_{a,b-1} = 0`` (``L^2``,
    second stage), ``L^2 - 1`` independent (their sum vanishes: one reducible); all
    ``2 L^2 - 1`` independent constraints first class, the ``L^2`` multipliers free;
    ``(6 L^2 - 2 (2 L^2 - 1))/2 = L^2 + 1`` physical degrees of freedom. The magnetic
    coupling ``g`` (default 1) stays symbolic until fixed.
    """
    size = _size(size, 2, "the torus size")
    L = size

    def site(a: int, b: int) -> str:
        return f"{a % L}_{b % L}"

    coords = [f"{field}_{site(a, b)}" for field in ("A0", "Ax", "Ay") for a in range(L) for b in range(L)]
    electric = []
    magnetic = []
    for a in range(L):
        for b in range(L):
            s, east, north = site(a, b), site(a + 1, b), site(a, b + 1)
            electric.append(f"(Ax_{s}_dot - (A0_{east} - A0_{s}))**2")
            electric.append(f"(Ay_{s}_dot - (A0_{north} - A0_{s}))**2")
            magnetic.append(f"(Ax_{s} + Ay_{east} - Ax_{north} - Ay_{s})**2")
    return Lagrangian.from_strings(
        f"maxwell_torus_{L}",
        coords,
        "(" + " + ".join(electric) + ")/2 - g/2*(" + " + ".join(magnetic) + ")",
        parameters={"g": 1.0},
        description=f"2+1 lattice Maxwell theory on a {L} x {L} torus",
    )
