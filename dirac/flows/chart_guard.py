"""A guard that stops a run near a coordinate singularity of its chart.

The equations of motion of ``L = q_dot^T W(q) q_dot / 2 - V(q)`` solve the velocities
from the momenta, ``q_dot = W^{-1} p``: they divide by ``det W``. Where ``det W``
vanishes on a locus of configurations (``sin(theta) = 0`` for Euler angles, the poles of
a sphere in polar angles) the coordinates, not the motion, are singular (a coordinate
singularity: Arnold, "Mathematical Methods of Classical Mechanics", Sect. 30; Goldstein,
Sect. 4.4 on the gimbal-lock of Euler angles). Near it the velocities grow like
``1/det W`` and a fixed step loses its accuracy without a word (a top in Euler angles
passing ``theta = 4e-4`` keeps a 1 % energy error), or its Newton iteration fails.

:class:`ChartGuard` measures how close a configuration is to the locus by the first-order
distance ``d(q) = min_f |f(q)| / |grad f(q)|`` over the factors ``f`` of ``det W`` that can
vanish (``|tan(theta)|`` for ``sin(theta)``: radians for an angle, the coordinates' units in
general), compiled as one scalar function. The loop of :func:`dirac.flows.integrate` reads it
between calls of the step loop, stops with :class:`~dirac.errors.CoordinateSingularityError`
when ``d < STOP_DISTANCE`` (naming the locus, the time and another chart), and chooses the
steps until the next reading from the rate at which ``d`` fell (:meth:`ChartGuard.next_reading`):
every step once ``d < WATCH_DISTANCE``, up to ``MAX_GUARD_STEPS`` far from the locus, so
that the check costs little. Systems whose ``det W`` is constant or never vanishes
(Cartesian coordinates, a rotation matrix) have no guard and run exactly as before; so has
a system without explicit time whose factors an interval enclosure at its parameters'
values proves never zero (:func:`never_zero`: the double pendulum in its angles, ``det W =
m2 (m1 + m2 sin(a - b)^2)``). Its default run to ``t = 100`` (rattle-8, 41 steps a sample)
made two calls of the step loop per sample with the guard and one without, the same numbers.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

__all__ = ["ChartGuard", "chart_guard", "built_once", "never_zero", "GUARD_STEPS", "WATCH_DISTANCE", "STOP_DISTANCE"]

#: steps between the first two readings of the guard
GUARD_STEPS = 32
#: most steps between two readings
MAX_GUARD_STEPS = 4096
#: below this distance (radians for an angle) the guard is read at every step
WATCH_DISTANCE = 0.1
#: below this distance the run stops
STOP_DISTANCE = 1e-2
#: largest number of coordinates for which ``det W`` is formed symbolically
MAX_GUARD_DIMENSION = 8

REMEDY = (
    "describe the motion in another chart: for a rigid body or a top, its rotation matrix (the rigid-body or "
    "heavy-top scene, HeavyTopProblem, or the rigid_body_matrix system); otherwise Cartesian coordinates with a "
    "holonomic constraint (a spherical pendulum as x, y, z with x**2 + y**2 + z**2 = l**2)"
)


class ChartGuard:
    """The distance of a configuration to the locus ``det W = 0`` of one system, compiled (module docstring).

    Attributes
    ----------
    locus
        The locus as text (``"sin(theta) = 0"``): the factors of ``det W`` that can vanish.
    """

    def __init__(self, values: Callable[..., list[float]], locus: str, time: bool, params: np.ndarray) -> None:
        self._values = values  # (f_1, |grad f_1|, f_2, |grad f_2|, ...)
        self.locus = locus
        self._time = time
        self._params = tuple(float(c) for c in params)
        self._last: float | None = None

    def distance(self, q: np.ndarray, t: float = 0.0) -> float:
        """The smallest ``d(q)`` over a batch of configurations ``q`` (shape ``(n,)`` or ``(B, n)``); 0 where undefined."""
        rows = q.tolist() if isinstance(q, np.ndarray) else list(q)
        if rows and not isinstance(rows[0], list):
            rows = [rows]
        extra = (float(t),) if self._time else ()
        best = math.inf
        for row in rows:  # plain floats: a call of the compiled scalar costs well under a microsecond
            values = self._values(*row, *extra, *self._params)
            for k in range(0, len(values), 2):
                f, g = abs(values[k]), values[k + 1]
                if not (f >= 0.0 and g >= 0.0):  # NaN: undefined there
                    return 0.0
                best = min(best, f / g if g > 0.0 else (0.0 if f == 0.0 else math.inf))
        return best

    def next_reading(self, distance: float, steps: int) -> int:
        """Steps until the guard is read again, after ``steps`` steps that brought it to ``distance``.

        Every step below ``WATCH_DISTANCE``; otherwise a quarter of the steps the last fall
        rate needs to reach ``WATCH_DISTANCE`` (the distance falls about linearly near a
        pass), at most twice the last interval and ``MAX_GUARD_STEPS``.
        """
        last, self._last = self._last, distance
        if distance < WATCH_DISTANCE:
            return 1
        limit = min(MAX_GUARD_STEPS, 2 * max(steps, GUARD_STEPS // 2))
        if last is None or last <= distance:
            return limit
        per_step = (last - distance) / max(steps, 1)
        return max(1, min(limit, int((distance - WATCH_DISTANCE) / per_step / 4)))

    def message(self, system: str, distance: float, where: str) -> str:
        """The error text: the locus, how near, where (time, step, method) and the remedy."""
        return (
            f"the run of {system!r} came near a coordinate singularity of its coordinates, {self.locus} "
            f"(det W = 0, W = d^2 L/dq_dot^2; distance {distance:.2g} in the units of the coordinates, radians for "
            f"an angle) {where}: the equations of motion divide by det W there, so a fixed step loses its accuracy; "
            f"{REMEDY}"
        )


def never_zero(factor: Any, bounded: list[Any], values: dict[Any, float]) -> bool:
    """Whether ``factor``, a polynomial in the symbols ``bounded`` (sines and cosines, each in
    ``[-1, 1]``) with the parameters of ``values`` set to their values, is never zero there.

    The range of each monomial over the box ``|x_i| <= 1`` lies in ``[0, 1]`` when all its
    exponents are even (the constant in ``[1, 1]``), else in ``[-1, 1]``; the sum of its
    coefficient times that interval over the monomials encloses the range of the factor
    (interval arithmetic: Moore, Kearfott & Cloud, "Introduction to Interval Analysis",
    Sect. 5.1), here in exact rationals (each parameter's double is a rational), so an
    enclosure that excludes 0 proves the factor never vanishes for any real sines and
    cosines, hence at no configuration. ``m1 + m2 - m2 cos(a - b)^2`` of the double pendulum in
    angles is in ``[1, 2]`` for unit masses (by hand: ``1 + sin(a - b)^2``); ``sin(theta)`` of a
    top, ``cos(b) + cos(c) + 2`` (zero at ``b = c = pi``) and the triple pendulum's ``det W``
    (enclosed in ``[-7, 10]``) are kept. A factor with any other symbol (a coordinate outside
    the sines and cosines, the time), or a coefficient that is not rational in the parameters,
    is not decided: False."""
    import sympy

    exact = factor.xreplace({symbol: sympy.Rational(float(value)) for symbol, value in values.items()})
    gens = [x for x in bounded if exact.has(x)]
    if not exact.free_symbols <= set(gens):
        return False
    try:
        terms = sympy.Poly(exact, *gens).terms() if gens else [((), sympy.Rational(exact))]
    except (sympy.PolynomialError, TypeError, ValueError):
        return False
    low = high = sympy.Integer(0)
    for exponents, coefficient in terms:
        if not coefficient.is_Rational:
            return False
        bottom = 1 if not any(exponents) else 0 if all(e % 2 == 0 for e in exponents) else -1
        low += coefficient * bottom if coefficient > 0 else coefficient
        high += coefficient if coefficient > 0 else coefficient * bottom
    return bool(low > 0 or high < 0)


def _locus(det: Any, q: list[Any], factors: Callable[[Any, list[Any]], list[Any]],
           values: dict[Any, float] | None = None) -> tuple[list[Any], bool]:
    """The factors of ``det W`` that can vanish (``factors`` is
    :func:`dirac.analysis.core.divisors.denominator_factors`, applied to ``1 / det W``), and
    whether a factor was left out as never zero at the parameters' ``values``
    (:func:`never_zero`; None: none is).

    ``det W`` in sines and cosines of angles is factored as a polynomial in them: each
    ``sin(u)``, ``cos(u)`` becomes a real symbol ``s_u``, ``c_u``, the polynomial is reduced
    modulo ``s_u^2 + c_u^2 - 1`` (:func:`~dirac.analysis.core.pythagoras.circle_polynomial`:
    Pythagoras, exactly, the same function of the angles; eliminating the squares of the sines
    or of the cosines, whichever leaves fewer terms), factored, and the factors are written back in ``sin`` and ``cos``. Each factor is the
    same function of the angles as a product of them is of ``det W``, so every zero of
    ``det W`` is a zero of a factor kept: no singularity is missed; only factors that cannot
    vanish for real sines and cosines are left out (``1 + c_u^2``). ``sin(psi)^2 +
    cos(psi)^2`` of an asymmetric top becomes 1 this way, and its locus reads
    ``sin(theta) = 0``. The road it replaces, ``trigsimp`` of each factor (which
    ``factors`` still takes for a ``det W`` that is not such a polynomial), cost 0.4 s on
    the triple pendulum's ``det W`` in three angle differences (this road: 0.04 s) and
    decided nothing more.
    """
    from dirac.analysis.core.pythagoras import circle_polynomial

    reduced = circle_polynomial(det, by_angle=False)  # all sines or all cosines: the loci as they were named
    if reduced is None:  # no sines or cosines, or not a polynomial in them: as before
        return factors(1 / det, q), False
    polynomial, sines, cosines, back = reduced.polynomial, reduced.sines, reduced.cosines, reduced.back
    found = factors(1 / polynomial, [*q, *sines, *cosines])
    kept = found if values is None else [f for f in found if not never_zero(f, [*sines, *cosines], values)]
    return [f.xreplace(back) for f in kept], len(kept) < len(found)


def _build(mechanics: Any) -> ChartGuard | None:
    import sympy  # not at import: a run without a guard never needs it

    from dirac.analysis.core.divisors import denominator_factors, too_long_to_search
    from dirac.codegen.scalar_backend import scalar_function

    symbolic = mechanics.symbolic
    W = symbolic.get("mass")
    q = list(symbolic.get("coordinates") or ())
    if W is None or not q or mechanics.constant_mass is not None or W.shape[0] > MAX_GUARD_DIMENSION:
        return None
    W = sympy.Matrix(W)
    det = W.det(method="berkowitz")
    params = list(symbolic.get("parameters") or ())
    time = mechanics.time_symbol
    # a factor that never vanishes at the system's parameters guards nothing: left out, but only
    # for a system without explicit time, whose steps do not depend on how the run is cut into
    # calls (the guard's readings cut it; a time-dependent system's steps start at sums of dt)
    values = dict(zip(params, np.asarray(mechanics.params, dtype=float).tolist())) if time is None else None
    locus, dropped = _locus(det, q, denominator_factors, values)
    text = " and ".join(f"{f} = 0" for f in locus)
    if not locus and dropped:
        return None  # det W never zero at these parameters: nothing to guard
    if not locus and (too_long_to_search(1 / det, q) or too_long_to_search(sympy.expand(det), q)):
        # too long to factor: det W itself guards its own zero set (the same loci, not named factor by factor)
        locus, text = [det], "det W = 0 (det W is too long to factor into named loci)"
    if not locus:
        return None  # det W constant or never zero: nothing to guard
    exprs = []
    for f in locus:  # f and the length of its gradient in q
        exprs += [f, sympy.sqrt(sum(sympy.diff(f, x) ** 2 for x in q))]
    arguments = [*q, *([time] if time is not None else []), *params]
    try:
        compiled = scalar_function(arguments, exprs)
    except Exception:  # an unusual function in W: no guard (the run is as before)  # noqa: BLE001
        return None
    return ChartGuard(compiled, text, time is not None, mechanics.params)


def built_once(mechanics: Any, attribute: str, build: Callable[[Any], Any]) -> Any:
    """``build(mechanics)``, kept on the system as ``attribute`` so that later runs reuse it
    (a guard of one system is built once: its factors are found and compiled then)."""
    missing = object()
    cached = getattr(mechanics, attribute, missing)
    if cached is missing:
        cached = build(mechanics)
        try:
            setattr(mechanics, attribute, cached)
        except AttributeError:  # a frozen system: build again next time
            pass
    return cached


def chart_guard(mechanics: Any) -> ChartGuard | None:
    """The :class:`ChartGuard` of a :class:`~dirac.flows.mechanics.MechanicalSystem` (built once), or ``None``."""
    cached = built_once(mechanics, "_chart_guard", _build)
    return cached if isinstance(cached, ChartGuard) else None
