"""The Legendre map at numeric points: momenta from velocities and velocities from momenta.

For the extended Lagrangian ``L_ext = L(q, q_dot, t) - lambda_a chi_a(q, t)`` (the paper's
(1)) the momenta are

    p_q = dL/dq_dot (q, q_dot, t),     p_lambda = 0,                          (205)

so a user who knows positions and velocities (as ``sympy.physics.mechanics`` users do)
gets the phase-space point from them; the inverse solves ``p_q = dL/dq_dot`` for
``q_dot`` by Newton's method with the Hessian ``W = d^2 L / dq_dot^2`` (one step for a
Lagrangian quadratic in the velocities, ``p = W q_dot + a``, (205), (229)). A singular
``W`` (a gauge system, the rigid body's (228)) leaves some velocities undetermined by
the point: then :func:`velocities` refuses instead of choosing them.

Parameters take their default values (as :meth:`ConstraintAnalysis.surface_point`); the
numbers come from :func:`dirac.codegen.array_function`, generated once per analysis.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np
import sympy

from dirac.errors import InputError
from dirac.model.lagrangian import Lagrangian, velocity_name
from dirac.validate import unknown_name_error, validate_finite

__all__ = ["LegendreMap", "MomentumSymbols"]


def _number(value: object, name: str) -> float:
    """A finite float; sympy numbers (``sympy.Float``, ``sympy.Rational``) are taken as well."""
    if isinstance(value, sympy.Basic) and value.is_number and value.is_real:
        value = float(value)
    return validate_finite(value, name)


class LegendreMap:
    """``p = dL/dq_dot`` and its inverse at numeric points of one analysed Lagrangian.

    Parameters
    ----------
    lagrangian
        The analysed Lagrangian (``analysis.lagrangian``).
    momenta
        The momentum symbols of the analysis, coordinates first then multipliers
        (``analysis.momenta``).
    time
        The time symbol of a time-dependent system (``analysis.time``), else ``None``.
    """

    def __init__(self, lagrangian: Lagrangian, momenta: tuple[sympy.Symbol, ...], time: sympy.Symbol | None) -> None:
        from dirac.codegen import array_function  # on first use: most analyses never need it

        missing = [p.name for p, v in lagrangian.parameters.items() if v is None]
        if missing:
            raise InputError(f"parameters {', '.join(missing)} have no default value: fix them (Lagrangian.fix) first")
        self.coordinates = [q.name for q in lagrangian.coordinates]
        self.momentum_names = [p.name for p in momenta]
        defaults = {p: sympy.Float(v) for p, v in lagrangian.parameters.items()}
        L = lagrangian.expression.subs(defaults)
        v = list(lagrangian.velocities)
        p = [sympy.diff(L, s) for s in v]
        W = sympy.Matrix(len(v), len(v), lambda i, j: sympy.diff(p[i], v[j]))
        t = time if time is not None else sympy.Symbol("_t_unused", real=True)
        self.uses_time = time is not None and any(time in e.free_symbols for e in (*p, *W))
        arguments: list[Any] = [list(lagrangian.coordinates), v, t]
        self._p: Callable[..., np.ndarray] = array_function(arguments, p)
        self._W: Callable[..., np.ndarray] = array_function(arguments, W)

    # ------------------------------------------------------------------ inputs
    def _time(self, t: float | None, what: str) -> float:
        if t is None:
            if self.uses_time:
                raise InputError(f"{what}: the momenta p = dL/dq_dot depend on the time t; give it (t=...)")
            return 0.0
        return _number(t, f"{what}: the time t")

    def _positions(self, q: Mapping[str, float], what: str) -> np.ndarray:
        if not isinstance(q, Mapping):
            raise InputError(f"{what}: give the positions as a mapping name -> value, e.g. {{'x': 1.0}}")
        for name in q:
            if name not in self.coordinates:
                raise unknown_name_error("coordinate", name, self.coordinates, source=what)
        lacking = [name for name in self.coordinates if name not in q]
        if lacking:
            raise InputError(f"{what}: the momenta need every coordinate; give {', '.join(lacking)} as well")
        return np.array([_number(q[name], f"{what}: {name}") for name in self.coordinates])

    def _rates(self, q_dot: Mapping[str, float], what: str) -> np.ndarray:
        """Velocities by coordinate name or velocity name (``x`` or ``x_dot``); missing ones are 0."""
        if not isinstance(q_dot, Mapping):
            raise InputError(f"{what}: give the velocities as a mapping name -> value, e.g. {{'x_dot': 0.5}}")
        by_name = {velocity_name(c): c for c in self.coordinates} | {c: c for c in self.coordinates}
        values: dict[str, float] = {}
        for name, value in q_dot.items():
            if name not in by_name:
                raise unknown_name_error("velocity", name, [velocity_name(c) for c in self.coordinates], source=what,
                                         plural="velocities")
            coordinate = by_name[name]
            if coordinate in values:
                raise InputError(f"{what}: the velocity of {coordinate!r} is given twice")
            values[coordinate] = _number(value, f"{what}: {name}")
        return np.array([values.get(c, 0.0) for c in self.coordinates])

    # ------------------------------------------------------------------ the map
    def momenta(self, q: Mapping[str, float], q_dot: Mapping[str, float], t: float | None = None,
                what: str = "momenta") -> dict[str, float]:
        """``p = dL/dq_dot`` at ``(q, q_dot, t)`` (205); the multipliers' momenta are 0.

        ``q`` maps every coordinate name to its value, ``q_dot`` velocity names (``x_dot``)
        or coordinate names to velocities (missing ones are 0).
        """
        values = np.asarray(self._p(self._positions(q, what), self._rates(q_dot, what), self._time(t, what)),
                            dtype=float).reshape(-1)
        result = {name: 0.0 for name in self.momentum_names}
        result.update({name: float(x) for name, x in zip(self.momentum_names, values)})
        return result

    def velocities(self, point: Mapping[str, float], t: float | None = None, what: str = "velocities",
                   tol: float = 1e-13, max_iter: int = 50) -> dict[str, float]:
        """``q_dot`` with ``dL/dq_dot (q, q_dot, t) = p`` at a phase-space point (Newton's method).

        Raises
        ------
        InputError
            A coordinate or momentum missing from ``point``, or a singular Hessian
            ``d^2 L/dq_dot^2`` there (the point does not determine every velocity).
        """
        if not isinstance(point, Mapping):
            raise InputError(f"{what}: give a point as a mapping name -> value")
        if t is None and "t" in point and self.uses_time:
            t = point["t"]
        q = self._positions({c: point[c] for c in self.coordinates if c in point}, what)
        lacking = [name for name in self.momentum_names[:len(q)] if name not in point]
        if lacking:
            raise InputError(f"{what}: the point lacks the momenta {', '.join(lacking)}")
        p = np.array([_number(point[name], f"{what}: {name}") for name in self.momentum_names[:len(q)]])
        time = self._time(t, what)
        v = np.zeros_like(q)
        for _ in range(max_iter):
            W = np.broadcast_to(np.asarray(self._W(q, v, time), dtype=float).reshape(-1), (len(q) ** 2,))
            W = W.reshape(len(q), len(q))
            rank = np.linalg.matrix_rank(W)
            if rank < len(q):
                raise InputError(
                    f"{what}: d2L/dq_dot2 is singular at this point (rank {rank} of {len(q)}): the momenta do "
                    "not determine every velocity (a gauge freedom or a singular Lagrangian); use "
                    "equations_of_motion(at=point), where the free multipliers are chosen"
                )
            residual = np.asarray(self._p(q, v, time), dtype=float).reshape(-1) - p
            scale = max(1.0, float(np.max(np.abs(p), initial=0.0)))
            if np.max(np.abs(residual), initial=0.0) <= tol * scale:
                break
            v = v - np.linalg.solve(W, residual)
        else:
            raise InputError(f"{what}: no velocities give these momenta (Newton's method did not converge)")
        return {velocity_name(c): float(x) for c, x in zip(self.coordinates, v)}


class MomentumSymbols(tuple):
    """The momentum symbols of an analysis (a tuple, ``analysis.momenta``) that can also be
    called: ``analysis.momenta(q, q_dot, t=None)`` is ``p = dL/dq_dot`` there (205), a dict
    momentum name -> value (the multipliers' momenta 0); see :meth:`LegendreMap.momenta`."""

    _compute: Callable[..., dict[str, float]]

    def __new__(cls, symbols: tuple[sympy.Symbol, ...], compute: Callable[..., dict[str, float]]) -> MomentumSymbols:
        made = super().__new__(cls, symbols)
        made._compute = compute
        return made

    def __call__(self, q: Mapping[str, float], q_dot: Mapping[str, float], t: float | None = None) -> dict[str, float]:
        return self._compute(q, q_dot, t)
