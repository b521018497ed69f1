"""Constraints that turn uniformly about an axis, and their conserved Jacobi integral.

A system whose time dependence is a uniform rotation -- a bead on a hoop or a parabola
turning at the rate ``w`` about the vertical -- does not conserve its energy ``H``, but in
the frame turning with the constraints it is autonomous, and

    J = H - w L,    L = q_i p_j - q_j p_i,                                   (Jacobi)

the Jacobi integral, is conserved (Landau & Lifshitz, *Mechanics*, §39; Goldstein,
*Classical Mechanics*, §8.2). :func:`uniform_rotation` finds the plane ``(q_i, q_j)`` and
the rate ``w`` when

* ``L`` has no explicit time and is invariant under rotations in that plane,
  ``delta L = 0`` with ``delta q_i = -q_j``, ``delta q_j = q_i`` (and the same on the
  velocities), and
* every constraint turns with the rate ``w``: ``d_t chi + w delta chi = 0`` identically
  (a constraint without ``t`` must be invariant, ``delta chi = 0``).

Then ``{J, H_T} + d_t J`` vanishes on the constraint surface. Other time dependences
(a moving suspension, a driven amplitude) have no such integral: the function returns
``None`` and nothing is claimed.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import sympy

from dirac.model.lagrangian import Lagrangian

__all__ = ["UniformRotation", "uniform_rotation"]


@dataclass(frozen=True)
class UniformRotation:
    """The constraints turn in the plane of coordinates ``first``, ``second`` (indices) at the rate ``rate``.

    The conserved Jacobi integral is ``J = H - rate * (q_first p_second - q_second p_first)``.
    """

    first: int
    second: int
    rate: sympy.Expr

    def label(self, names: tuple[str, ...], rate: str | None = None) -> str:
        """``H - w*(x*p_y - y*p_x)`` written with the coordinate names (and ``rate`` for ``w`` if given)."""
        a, b = names[self.first], names[self.second]
        return f"H - {rate or f'({self.rate})'}*({a}*p_{b} - {b}*p_{a})"


def _rotated(expr: sympy.Expr, pairs: list[tuple[sympy.Symbol, sympy.Symbol]]) -> sympy.Expr:
    """``delta expr`` under ``delta a = -b``, ``delta b = a`` for each pair ``(a, b)``."""
    return sum((-b * sympy.diff(expr, a) + a * sympy.diff(expr, b) for a, b in pairs), sympy.S.Zero)


def uniform_rotation(lagrangian: Lagrangian) -> UniformRotation | None:
    """The plane and rate of a uniformly turning constraint set (see the module docstring), or ``None``.

    Only systems with an explicit time ``t`` in their constraints and not in ``L``
    qualify; the first plane of coordinates (in order) that works is returned.
    """
    t = lagrangian.time
    if t is None or not lagrangian.is_time_dependent or t in lagrangian.expression.free_symbols:
        return None
    q, v = lagrangian.coordinates, lagrangian.velocities
    L = lagrangian.expression
    for i, j in combinations(range(len(q)), 2):
        if sympy.simplify(_rotated(L, [(q[i], q[j]), (v[i], v[j])])) != 0:
            continue
        rate: sympy.Expr | None = None
        for chi in lagrangian.constraints:
            turn = _rotated(chi, [(q[i], q[j])])
            moving = sympy.diff(chi, t)
            if moving == 0:
                if sympy.simplify(turn) != 0:
                    break
                continue
            if sympy.simplify(turn) == 0:
                break
            candidate = sympy.simplify(-moving / turn)
            if candidate.free_symbols & {*q, t}:
                break
            if rate is not None and sympy.simplify(candidate - rate) != 0:
                break
            rate = candidate
        else:
            if rate is not None:
                return UniformRotation(i, j, rate)
    return None
