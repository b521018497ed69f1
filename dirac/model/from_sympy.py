"""Lagrangians written as sympy expressions: plain symbols or ``sympy.physics.mechanics.dynamicsymbols``.

:func:`plain_parts` (behind :meth:`dirac.Lagrangian.from_sympy`) turns
``L``, the coordinates and the constraints into the symbols the engine uses
(docs/conventions.md): every coordinate becomes a real symbol ``q`` and its velocity the
real symbol ``q_dot``. A coordinate may be

- a plain :class:`sympy.Symbol` ``q``: ``L`` then writes its velocity as a symbol named
  ``q_dot``;
- a function of time ``q(t)`` (``dynamicsymbols("q")``): ``L`` writes its velocity as the
  time derivative ``q(t).diff(t)``, which becomes ``q_dot``, and ``q(t)`` becomes ``q``.

An explicit time dependence may be written with any symbol named ``t`` (``dirac.TIME``,
``sympy.Symbol("t")``, or ``dynamicsymbols._t``, the time of ``dynamicsymbols``) and with
the time symbol of the coordinates ``q(t)`` whatever its name: each becomes the engine's
time :data:`dirac.TIME` (``sympy.Symbol("t", real=True)``), so ``cos(w*t)`` with sympy's
``t`` is the engine's time and never a parameter. When a coordinate is called ``t`` (the
coordinate time of a relativistic particle) there is no explicit time and ``t`` stays
that coordinate.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence

import sympy
from sympy.core.function import AppliedUndef

from dirac.errors import InputError
from dirac.model.expressions import TIME

__all__ = ["plain_parts", "plain_forces", "Parts"]

#: (coordinates, velocities, L, constraints, parameter -> default), in the engine's symbols
Parts = tuple[
    tuple[sympy.Symbol, ...], tuple[sympy.Symbol, ...], sympy.Expr, tuple[sympy.Expr, ...], dict[sympy.Symbol, float | None]
]


def _time_of(coordinate: sympy.Basic) -> sympy.Symbol | None:
    """The time symbol of a coordinate ``q(t)``, ``None`` for a plain symbol."""
    if isinstance(coordinate, sympy.Symbol):
        return None
    if isinstance(coordinate, AppliedUndef) and len(coordinate.args) == 1 and isinstance(coordinate.args[0], sympy.Symbol):
        return coordinate.args[0]
    raise InputError(
        f"coordinate {coordinate!r} must be a sympy Symbol or a function of time such as "
        "dynamicsymbols('x') (x(t))"
    )


def _name_of(coordinate: sympy.Basic) -> str:
    return coordinate.name if isinstance(coordinate, sympy.Symbol) else type(coordinate).__name__


def _engine_time(coordinates: Sequence[sympy.Basic]) -> Callable[[sympy.Basic], sympy.Basic]:
    """The function that writes every time symbol of an expression as :data:`TIME`.

    The time symbols are the argument of the coordinates ``q(t)`` (``dynamicsymbols._t``,
    a ``t`` without ``real=True``, or any other name) and every symbol named ``t`` (with
    whatever assumptions), unless a coordinate is called ``t`` (then nothing changes).
    Applied to the coordinates as well, it keeps ``q(t)`` and ``d q(t)/dt`` recognisable
    when the user substituted a real ``t`` for sympy's (``x(t)`` then reads ``x(T)``).
    """
    if any(_name_of(c) == TIME.name for c in coordinates):
        return lambda e: e
    times = {_time_of(c) for c in coordinates} - {None}

    def timed(e: sympy.Basic) -> sympy.Basic:
        e = sympy.sympify(e)
        return e.xreplace({s: TIME for s in e.free_symbols
                           if isinstance(s, sympy.Symbol) and (s.name == TIME.name or s in times)})

    return timed


def plain_parts(
    L: sympy.Expr,
    coordinates: Sequence[sympy.Basic],
    constraints: Iterable[sympy.Expr],
    parameters: Mapping[sympy.Symbol | str, float | None] | Iterable[sympy.Symbol | str] | None,
    velocity_name: Callable[[str], str],
    extra: Sequence[sympy.Expr] = (),
) -> Parts:
    """The parts of a :class:`~dirac.model.lagrangian.Lagrangian` from sympy expressions.

    Parameters
    ----------
    L
        The Lagrangian ``L(q, q_dot)``.
    coordinates
        Plain symbols ``q`` (velocities written as symbols named ``q_dot``) or functions
        of one time symbol ``q(t)`` (velocities written as ``q(t).diff(t)``); not mixed
        over different time symbols.
    constraints
        Holonomic constraints ``chi(q)`` (expressions that should be zero).
    parameters
        Parameter -> default value (``None`` for none), or just the parameters; ``None``
        makes every other symbol of ``L`` and the constraints a parameter without default.
    velocity_name
        The name of the velocity of a coordinate (``x`` -> ``x_dot``).
    extra
        Further expressions (generalized forces) converted like ``L``: read them back with
        :func:`plain_forces`, which calls this function.

    Examples
    --------
    >>> import sympy
    >>> from sympy.physics.mechanics import dynamicsymbols
    >>> x = dynamicsymbols("x")
    >>> t, m, k = sympy.symbols("t m k")
    >>> plain_parts(m / 2 * x.diff(t) ** 2 - k / 2 * x**2, [x], (), None, lambda q: q + "_dot")[1]
    (x_dot,)
    """
    if isinstance(coordinates, (str, sympy.Basic)) or not isinstance(coordinates, Sequence):
        raise InputError("coordinates must be a list of sympy symbols or dynamicsymbols, e.g. [x, y]")
    if isinstance(constraints, (str, sympy.Basic)):
        raise InputError("constraints must be a list of sympy expressions, e.g. [x**2 + y**2 - l**2]")
    expr = sympy.sympify(L)
    chis = [sympy.sympify(c) for c in constraints]
    time_names = {t.name for t in (_time_of(c) for c in coordinates) if t is not None}
    if len(time_names) > 1:
        raise InputError(f"the coordinates depend on different time symbols {sorted(time_names)}: use one")
    timed = _engine_time(coordinates)
    coordinates = [timed(c) for c in coordinates]
    times = {_time_of(c) for c in coordinates} - {None}
    labels = [_name_of(c) for c in coordinates]
    duplicates = sorted({label for label in labels if labels.count(label) > 1})
    if duplicates:
        raise InputError(f"coordinate(s) {', '.join(duplicates)} listed twice")
    q = {label: sympy.Symbol(label, real=True) for label in labels}
    v = {label: sympy.Symbol(velocity_name(label), real=True) for label in labels}

    # dynamicsymbols: q(t).diff(t) -> q_dot first, then q(t) -> q
    derivatives = {c.diff(_time_of(c)): v[label] for c, label in zip(coordinates, labels) if _time_of(c) is not None}
    functions = {c: q[label] for c, label in zip(coordinates, labels) if _time_of(c) is not None}

    def plain(e: sympy.Expr) -> sympy.Expr:
        """``e`` in the engine's symbols: its time is :data:`TIME`, ``q(t)`` is ``q``, ``q(t).diff(t)`` is ``q_dot``."""
        e = timed(e)
        return e.subs(derivatives).subs(functions) if derivatives else e

    expr = plain(expr)
    chis = [plain(c) for c in chis]
    extras = [plain(sympy.sympify(e)) for e in extra]
    for e in (expr, *chis, *extras):
        left = sorted(str(d) for d in e.atoms(sympy.Derivative, AppliedUndef))
        if left:
            raise InputError(
                f"{', '.join(left)} is not a coordinate or the first time derivative of one: "
                "list every coordinate, and use velocities only (no accelerations)"
            )

    # every symbol by name -> the engine's real symbol of that name
    own = {s.name: s for s in (*q.values(), *v.values())}
    if parameters is None:
        found = set().union(*(e.free_symbols for e in (expr, *chis, *extras)))
        values: dict[str, float | None] = {
            label: None
            for label in sorted(s.name for s in found if s.name not in own and s not in times and s.name != TIME.name)
        }
    elif isinstance(parameters, Mapping):
        values = {str(p): value for p, value in parameters.items()}
    else:
        values = {str(p): None for p in parameters}
    params = {label: sympy.Symbol(label, real=True) for label in values}
    by_name = {**own, **params}
    renaming = {s: by_name[s.name] for e in (expr, *chis, *extras) for s in e.free_symbols if s.name in by_name}
    expr = expr.xreplace(renaming)
    chis = [c.xreplace(renaming) for c in chis]
    _CONVERTED[:] = [e.xreplace(renaming) for e in extras]
    return (
        tuple(q.values()),
        tuple(v.values()),
        expr,
        tuple(chis),
        {params[label]: value for label, value in values.items()},
    )


#: the extra expressions of the last :func:`plain_parts` call (read by :func:`plain_forces`)
_CONVERTED: list[sympy.Expr] = []


def plain_forces(
    L: sympy.Expr,
    coordinates: Sequence[sympy.Basic],
    constraints: Iterable[sympy.Expr],
    parameters: Mapping[sympy.Symbol | str, float | None] | Iterable[sympy.Symbol | str] | None,
    velocity_name: Callable[[str], str],
    forces: Mapping[object, sympy.Expr],
) -> tuple[Parts, dict[str, sympy.Expr]]:
    """:func:`plain_parts` and the generalized forces ``Q_r`` in the engine's symbols.

    ``forces`` maps a coordinate (the symbol, the ``dynamicsymbols`` function or its name)
    to ``Q_r(q, q_dot, t)`` written like ``L`` (``x(t).diff(t)`` or ``x_dot`` for a
    velocity); the result maps the coordinate's name to the converted expression. Names a
    force uses that are not coordinates, velocities or ``t`` become parameters when
    ``parameters`` is ``None``.
    """
    if not isinstance(forces, Mapping):
        raise InputError("forces must be a mapping coordinate -> expression, e.g. {x: -c*x.diff(t)}")
    names = []
    for key in forces:
        if isinstance(key, str):
            names.append(key)
        elif isinstance(key, sympy.Symbol) or isinstance(key, AppliedUndef):
            names.append(_name_of(key))
        else:
            raise InputError(f"a force is keyed by {key!r}: key forces by a coordinate (symbol or name)")
    parts = plain_parts(L, coordinates, constraints, parameters, velocity_name, extra=tuple(forces.values()))
    converted = list(_CONVERTED)
    return parts, dict(zip(names, converted))
