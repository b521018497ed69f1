"""A field theory on a periodic lattice: the mechanical Lagrangian of its sites.

:func:`lattice` replaces space by a periodic cubic lattice of ``N_1 x N_2 x ...`` sites
with spacing ``a``, each field by one coordinate per site, ``d_t`` by the velocity, and
each spatial derivative by the **forward difference**

    d_j phi (n) -> (phi(n + e_j) - phi(n)) / a_j        (periodic: site N_j is site 0),

and the action by ``L = (prod_j a_j) sum_n density(n)``. Holonomic constraints of the
theory hold at every site, with one multiplier each (the engine's extended Lagrangian).

What a lattice keeps and loses (H. J. Rothe, *Lattice Gauge Theories: An Introduction*;
I. Montvay and G. Münster, *Quantum Fields on a Lattice*): the time evolution and the local constraints are
exact, and so are global symmetries acting site by site (the O(3) rotations of the sigma
model). A gauge field written as non-compact variables on sites with forward differences
keeps a lattice gauge invariance ``delta A_0 = d_t eps``, ``delta A_j = (eps(n + e_j) -
eps(n)) / a`` only because the differences commute; a non-abelian or compact theory needs
link variables ``U = exp(i a A)``, which this construction does not build. Rotation
invariance is lost at order ``a^2``; a forward difference is accurate to order ``a`` only
where the density is not symmetrised, and the dispersion ``omega^2 = (4/a^2)
sin^2(k a/2) + m^2`` of a scalar replaces ``k^2 + m^2``; first-order (Dirac-type) densities
with a symmetric difference have doublers, which the forward difference avoids at the
price of an ``O(a)`` asymmetric term.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import sympy

from dirac.errors import InputError
from dirac.fields.theory import TIME_DIRECTION, FieldTheory
from dirac.model.lagrangian import Lagrangian, velocity_name

__all__ = ["lattice", "site_name"]

#: largest number of sites (all directions together) a lattice may have
MAX_SITES = 100_000


def site_name(field_name: str, site: Sequence[int]) -> str:
    """``("phi", (3,))`` -> ``phi_3``; ``("A1", (0, 2))`` -> ``A1_0_2``; no index without space."""
    return "_".join([field_name, *(str(i) for i in site)])


def _per_direction(value: object, count: int, what: str, kind: type) -> list:
    values = list(value) if isinstance(value, (list, tuple)) else [value] * count
    if len(values) != count:
        raise InputError(f"{what} needs one value per spatial direction ({count}), got {len(values)}")
    out = []
    for v in values:
        if kind is int:
            if isinstance(v, bool) or not isinstance(v, int) or v < 1:
                raise InputError(f"{what} must be a positive integer (or one per direction), got {v!r}")
        else:
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not v > 0 or v != v or v == float("inf"):
                raise InputError(f"{what} must be a positive finite number (or one per direction), got {v!r}")
        out.append(v)
    return out


def lattice(theory: FieldTheory, sites: int | Sequence[int] = 16, spacing: float | Sequence[float] = 1.0) -> Lagrangian:
    """The Lagrangian of ``theory`` on a periodic lattice (module docstring).

    Parameters
    ----------
    theory
        A :class:`~dirac.fields.theory.FieldTheory` (any density, linear or not).
    sites
        Sites per direction: one int for all, or one per spatial direction.
    spacing
        Lattice spacing ``a``: one number or one per direction (exact rationals in the Lagrangian).

    Returns
    -------
    Lagrangian
        Coordinates ``<field>_<i>`` (``<field>_<i>_<j>`` in two dimensions, and so on),
        site-major; the theory's constraints at every site.

    Examples
    --------
    >>> import dirac
    >>> kg = dirac.FieldTheory.from_strings("kg", ["x"], ["phi"], "phi_t**2/2 - phi_x**2/2")
    >>> dirac.lattice(kg, sites=3, spacing=0.5).expression
    phi_0_dot**2/4 + phi_1_dot**2/4 + phi_2_dot**2/4 - (-phi_0 + phi_1)**2 - (phi_0 - phi_2)**2 - (-phi_1 + phi_2)**2
    """
    if not isinstance(theory, FieldTheory):
        raise InputError(f"lattice() needs a dirac.FieldTheory, not {type(theory).__name__}")
    d = len(theory.space)
    counts = _per_direction(sites, d, "sites", int)
    steps = [sympy.Rational(repr(float(a))) for a in _per_direction(spacing, d, "spacing", float)]
    total = 1
    for n in counts:
        total *= n
    if total > MAX_SITES:
        raise InputError(f"a lattice of {total} sites is larger than {MAX_SITES}: use fewer sites")
    grid = list(itertools.product(*(range(n) for n in counts)))
    q = {(f.name, site): sympy.Symbol(site_name(f.name, site), real=True) for site in grid for f in theory.fields}
    v = {key: sympy.Symbol(velocity_name(s.name), real=True) for key, s in q.items()}
    volume = sympy.Integer(1)
    for a in steps:
        volume *= a
    terms: list[sympy.Expr] = []
    chis: list[sympy.Expr] = []
    for site in grid:
        substitution = {}
        for f in theory.fields:
            here = q[(f.name, site)]
            substitution[f] = here
            substitution[theory.derivative(f, TIME_DIRECTION)] = v[(f.name, site)]
            for j, direction in enumerate(theory.space):
                ahead = list(site)
                ahead[j] = (ahead[j] + 1) % counts[j]
                substitution[theory.derivative(f, direction)] = (q[(f.name, tuple(ahead))] - here) / steps[j]
        terms.append(theory.density.xreplace(substitution))
        chis.extend(chi.xreplace(substitution) for chi in theory.constraints)
    coordinates = tuple(q[(f.name, site)] for site in grid for f in theory.fields)
    velocities = tuple(v[(f.name, site)] for site in grid for f in theory.fields)
    shape = " x ".join(map(str, counts)) or "one site"
    return Lagrangian(
        f"{theory.name} (lattice {shape})", coordinates, velocities, volume * sympy.Add(*terms), tuple(chis),
        dict(theory.parameters),
        f"{theory.name} on a periodic lattice of {shape} sites, spacing {', '.join(map(str, steps)) or '-'}, "
        "forward differences",
    )
